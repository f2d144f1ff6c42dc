#!/usr/bin/env node
// End-to-end test of the dashboard in a real browser against a real `gbdcs serve`.
//
//   node e2e/run.mjs --gbdcs build/app/gbdcs [--out build/web-e2e] [--chromium /usr/bin/chromium]
//                    [--fps-seconds 60] [--keep]
//
// Starts `gbdcs serve` on a free loopback port with a temporary SQLite database (twin drone,
// the default rendered-hand camera), drives Debian's chromium headless through playwright-core
// (no browser download), and walks an operator's flight: a bad login shows the server's cause
// and suggestion; register and log in; telemetry and the gesture update; the drone takes off
// by gesture; an alert appears (the vision worker is killed) and is acknowledged; the
// emergency stop (Space) brings it down; a stored session is replayed; log out. A screenshot
// of each step goes to --out. With --fps-seconds N it also measures the feed's frame rate
// over N seconds and writes it to --out/feed_fps.json.
//
// Fails (exit 1) when chromium, the gbdcs binary or its `serve` command is missing: never skips.
/* global window, localStorage -- functions passed to page.evaluate run in the page */
import { spawn, execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const repo = resolve(here, '..', '..');

function arg(name, fallback) {
  const i = process.argv.indexOf(`--${name}`);
  return i >= 0 ? process.argv[i + 1] : fallback;
}
const gbdcs = resolve(arg('gbdcs', process.env.GBDCS_BIN ?? join(repo, 'build', 'app', 'gbdcs')));
const out = resolve(arg('out', join(repo, 'build', 'web-e2e')));
const chromiumPath = arg('chromium', process.env.GBDCS_CHROMIUM ?? '/usr/bin/chromium');
const fpsSeconds = Number(arg('fps-seconds', '0'));
const keep = process.argv.includes('--keep');
// Camera: the server's default (the rendered demo hand) unless --source is given, e.g.
// timeline:fixtures/timelines/demo_flight.json (landmarks only: light on a loaded machine).
const source = arg('source', '');
// Generous: a loaded 2-core CI machine renders the hand video and runs the models.
const STEP_MS = Number(process.env.GBDCS_E2E_STEP_MS ?? 90_000);

function fail(msg) {
  console.error(`web e2e: FAIL: ${msg}`);
  process.exitCode = 1;
  throw new Error(msg);
}

const log = (m) => console.log(`web e2e: ${m}`);

async function waitHttp(url, ms, child) {
  const end = Date.now() + ms;
  let last = '';
  while (Date.now() < end) {
    if (child.exitCode !== null) fail(`gbdcs serve exited with ${child.exitCode} before answering`);
    try {
      const r = await fetch(url);
      if (r.ok) return await r.json();
      last = `HTTP ${r.status}`;
    } catch (e) {
      last = e.message;
    }
    await new Promise((r) => setTimeout(r, 250));
  }
  fail(`${url} did not answer within ${ms} ms (${last})`);
}

async function main() {
  if (!existsSync(chromiumPath))
    fail(`chromium not found at ${chromiumPath} (ci/setup installs Debian's chromium)`);
  if (!existsSync(gbdcs)) fail(`gbdcs binary not found at ${gbdcs} (build it: ci/build)`);
  try {
    execFileSync(gbdcs, ['serve', '--help'], { stdio: 'pipe' });
  } catch (e) {
    fail(
      `\`${gbdcs} serve --help\` failed: the server (issue 7) is not built into this binary (${e.message.split('\n')[0]})`,
    );
  }
  if (!existsSync(join(repo, 'web', 'dist', 'index.html')))
    fail('web/dist is not built (ci/setup builds it)');
  let chromium;
  try {
    ({ chromium } = await import('playwright-core'));
  } catch {
    fail('playwright-core is not installed (cd web && npm ci)');
  }

  mkdirSync(out, { recursive: true });
  const tmp = mkdtempSync(join(tmpdir(), 'gbdcs-web-e2e-'));
  const serverLog = join(out, 'serve.log');
  const logFd = [];
  // --port 0: the server picks a free port and prints it.
  const child = spawn(
    gbdcs,
    [
      'serve',
      '--port',
      '0',
      '--bind',
      '127.0.0.1',
      '--db',
      join(tmp, 'gbdcs.db'),
      '--adapter',
      'twin',
      '--web',
      join(repo, 'web', 'dist'),
      ...(source ? ['--source', source] : []),
    ],
    { cwd: repo, env: { ...process.env }, stdio: ['ignore', 'pipe', 'pipe'] },
  );
  let browser;
  let page;
  const shots = [];
  try {
    const base = await new Promise((res, rej) => {
      let seen = '';
      const timer = setTimeout(
        () => rej(new Error(`gbdcs serve did not say where it listens within 120 s:\n${seen}`)),
        120_000,
      );
      child.stdout.on('data', (d) => {
        logFd.push(d);
        seen += d.toString();
        const m = /listening on (http:\/\/[0-9.]+:\d+)/.exec(seen);
        if (m) {
          clearTimeout(timer);
          res(m[1]);
        }
      });
      child.stderr.on('data', (d) => logFd.push(d));
      child.once('exit', (code) =>
        rej(new Error(`gbdcs serve exited with ${code}:\n${Buffer.concat(logFd)}`)),
      );
    });
    log(`gbdcs serve on ${base} (db in ${tmp})`);
    await waitHttp(`${base}/api/v1/healthz`, 120_000, child);

    browser = await chromium.launch({
      executablePath: chromiumPath,
      headless: true,
      args: [
        '--no-sandbox',
        '--disable-dev-shm-usage',
        '--autoplay-policy=no-user-gesture-required',
      ],
    });
    page = await browser.newPage({ viewport: { width: 1366, height: 900 } });
    const errors = [];
    page.on('pageerror', (e) => errors.push(e.message));
    const sockets = [];
    page.on('websocket', (ws) => {
      if (ws.url().includes('/ws/live')) sockets.push(ws);
    });
    let n = 0;
    const shot = async (name) => {
      const file = join(out, `${String(++n).padStart(2, '0')}-${name}.png`);
      await page.screenshot({ path: file });
      shots.push(file);
      log(`step ${n}: ${name} ok (${file})`);
    };
    const text = (testid) => page.getByTestId(testid).innerText();
    const waitText = async (testid, pred, what) => {
      const end = Date.now() + STEP_MS;
      let now = '(absent)';
      while (Date.now() < end) {
        now = await page
          .getByTestId(testid)
          .first()
          .innerText({ timeout: 1000 })
          .catch(() => '(absent)');
        if (now !== '(absent)' && pred(now)) return now;
        await page.waitForTimeout(200);
      }
      fail(`${what}: [${testid}] is "${now}"`);
    };

    const waitAttr = async (testid, name, pred, what) => {
      const end = Date.now() + STEP_MS;
      let now = null;
      while (Date.now() < end) {
        now = await page
          .getByTestId(testid)
          .first()
          .getAttribute(name, { timeout: 1000 })
          .catch(() => null);
        if (now !== null && pred(now)) return now;
        await page.waitForTimeout(200);
      }
      fail(`${what}: [${testid}] ${name}="${now}"`);
    };

    // 1. A bad login shows the server's own cause and suggestion.
    await page.goto(base + '/');
    const email = `pilot-${Date.now()}@example.com`;
    const password = 'correct horse battery';
    const bad = await fetch(`${base}/api/v1/auth/login`, {
      method: 'POST',
      headers: { 'Content-Type': 'application/json' },
      body: JSON.stringify({ email, password: 'wrong password 123' }),
    }).then((r) => r.json());
    await page.getByLabel('E-mail').fill(email);
    await page.getByLabel('Password').fill('wrong password 123');
    await page.getByRole('button', { name: 'Log in', exact: true }).last().click();
    const box = page.getByRole('alert').filter({ hasText: 'Could not log in' });
    await box.waitFor({ timeout: STEP_MS });
    const boxText = await box.innerText();
    if (!boxText.includes(bad.cause) || !boxText.includes(bad.suggestion))
      fail(
        `bad login: the page shows "${boxText}", not the server's cause "${bad.cause}" and suggestion "${bad.suggestion}"`,
      );
    await shot('bad-login-shows-cause-and-suggestion');

    // 2. Register and log in.
    await page.getByRole('tab', { name: 'Register' }).click();
    await page.getByLabel('Password').fill(password);
    await page.getByRole('button', { name: 'Create account' }).click();
    await page.getByRole('navigation', { name: 'Main' }).waitFor({ timeout: STEP_MS });
    await shot('registered-and-logged-in');

    // 3. Telemetry flows and the gesture updates.
    await waitText('altitude', (t) => /m$/.test(t), 'telemetry never arrived');
    await waitText('link', (t) => t === 'OK' || t === 'DEGRADED', 'link not OK');
    await waitText('gesture', (t) => t !== 'No gesture', 'no gesture recognised from the camera');
    const firstGesture = await text('gesture');
    await waitText('gesture', (t) => t !== firstGesture, 'the gesture never changed');
    await waitText('feed-fps', (t) => parseFloat(t) > 0, 'the feed shows no frames');
    await shot('telemetry-and-gesture-live');

    // 4. The drone takes off by gesture. The camera's hand shows the take-off gesture every
    // loop, so the drone may already be in the air from before this browser logged in: then the
    // operator lands it (the Land button) and the next take-off gesture must lift it again. The
    // command log then shows TAKEOFF from a gesture accepted, and the telemetry says FLYING.
    const tookOff = () =>
      page.evaluate(() =>
        window.__gbdcs.live.commands.some(
          (c) =>
            c.command.type === 'TAKEOFF' && c.command.source === 'gesture' && c.outcome === 'OK',
        ),
      );
    if ((await text('flight-state')) === 'FLYING' && !(await tookOff())) {
      log('the drone took off before the login: landing it to see the gesture take off again');
      await page.getByRole('button', { name: /^Land/ }).click();
      await waitText('flight-state', (t) => t === 'READY', 'not back on the ground after Land');
    }
    for (const end = Date.now() + STEP_MS; !(await tookOff()); await page.waitForTimeout(250))
      if (Date.now() > end) fail('no TAKEOFF by gesture was accepted');
    await waitText('flight-state', (t) => t === 'FLYING', 'not FLYING after the take-off gesture');
    // The path map (an SVG: its point count is an attribute) draws the flight since take-off.
    await waitAttr('path-map', 'data-points', (v) => Number(v) > 1, 'the path map stays empty');
    await shot('took-off-by-gesture');

    // 4b. The twin's chase camera: drone_view pictures reach the flying view.
    await waitAttr(
      'drone-view',
      'data-frame-id',
      (v) => Number(v) >= 1,
      'no picture from the twin chase camera',
    );
    await page.getByTestId('drone-view').scrollIntoViewIfNeeded();
    await shot('twin-chase-camera');

    // 5. An alert appears and is acknowledged: kill -9 the vision worker (the server's child).
    const kids = execFileSync('ps', ['-o', 'pid=,args=', '--ppid', String(child.pid)]).toString();
    const worker = kids
      .split('\n')
      .map((l) => l.trim())
      .find((l) => /\bvision\b/.test(l));
    if (!worker) fail(`no vision worker among gbdcs serve's children:\n${kids}`);
    process.kill(Number(worker.split(/\s+/)[0]), 'SIGKILL');
    // The first VISION_WORKER_LOST banner (by its alert id: another one may follow if the
    // restarted worker is slow), acknowledged from the page, then checked in the stored session.
    const lost = page.locator('[data-testid="alert"][data-code="VISION_WORKER_LOST"]').first();
    await lost.waitFor({ timeout: STEP_MS });
    const alertId = await lost.getAttribute('data-alert-id');
    const banner = page.locator(`[data-testid="alert"][data-alert-id="${alertId}"]`);
    const alertText = await banner.innerText();
    await shot('alert-shown');
    await banner.getByRole('button', { name: 'Acknowledge' }).click();
    await banner.waitFor({ state: 'detached', timeout: STEP_MS });
    const token = await page.evaluate(() => JSON.parse(localStorage.getItem('gbdcs.login')).token);
    const auth = { headers: { Authorization: `Bearer ${token}` } };
    const sessions = await fetch(`${base}/api/v1/sessions?limit=1`, auth).then((r) => r.json());
    const sessionId = sessions.sessions[0]?.id;
    const detail = await fetch(`${base}/api/v1/sessions/${sessionId}`, auth).then((r) => r.json());
    const record = detail.alerts.find((r) => String(r.alert.id) === alertId);
    if (!record?.acknowledged_at)
      fail(`alert ${alertId} is not stored as acknowledged: ${JSON.stringify(record)}`);
    log(`alert ${alertId} "${alertText.split('\n')[0]}" acknowledged at ${record.acknowledged_at}`);
    await shot('alert-acknowledged');

    // The worker restarts; fly again if the hover left it airborne, else wait for take-off.
    await waitText('vision', (t) => t.startsWith('healthy'), 'the vision worker did not come back');
    if ((await text('flight-state')) === 'READY') {
      // The twin landed itself while the worker was down (no command for 15 s): the operator's
      // Take off button (input key t) lifts it again, else the next take-off gesture will.
      await page
        .getByTestId('takeoff')
        .click({ timeout: 5000 })
        .catch(() => log('take-off button not clickable; waiting for the gesture'));
    }
    await waitText('flight-state', (t) => t === 'FLYING', 'not flying before the emergency stop');

    // 6. Emergency stop (Space) brings it down.
    await page.locator('body').press('Space');
    await waitText('flight-state', (t) => t !== 'FLYING', 'still FLYING after the emergency stop');
    await page
      .getByRole('alert')
      .filter({ hasText: 'Emergency stop is latched' })
      .waitFor({ timeout: STEP_MS });
    await waitText(
      'altitude',
      (t) => parseFloat(t) < 0.2,
      'the drone is not down after the emergency stop',
    );
    await shot('emergency-stop-landed');
    await page.getByRole('button', { name: 'Release emergency stop' }).click();

    if (fpsSeconds > 0) {
      // Counted in the page (pictures and results received, distinct pictures drawn, the
      // worker's vision FPS sampled from the state messages each second) and at the server
      // (pictures broadcast, vision results received: /metrics).
      const metric = async (name) => {
        const text = await fetch(`${base}/api/v1/metrics`).then((r) => r.text());
        const line = text.split('\n').find((l) => l.startsWith(`${name} `));
        return line ? Number(line.split(' ')[1]) : NaN;
      };
      const counts = () =>
        page.evaluate(() => ({
          drawn: window.__gbdcsFeed.drawn,
          results: window.__gbdcs.frames.received,
          pictures: window.__gbdcs.frames.pictures.received,
        }));
      const c0 = await counts();
      const sent0 = await metric('gbdcs_feed_pictures_total');
      const vision0 = await metric('gbdcs_vision_frames_total');
      const t0 = Date.now();
      const visionFps = [];
      const lags = [];
      const states = {};
      while (Date.now() - t0 < fpsSeconds * 1000) {
        await page.waitForTimeout(1000);
        const v = await page.evaluate(() => ({
          fps: window.__gbdcs.live.server?.vision?.fps ?? null,
          lag: window.__gbdcsFeed.skeletonLagMs,
          state: window.__gbdcsFeed.skeleton,
        }));
        if (v.fps !== null) visionFps.push(v.fps);
        if (v.lag !== null) lags.push(v.lag);
        states[v.state] = (states[v.state] ?? 0) + 1;
      }
      const c1 = await counts();
      const sent1 = await metric('gbdcs_feed_pictures_total');
      const vision1 = await metric('gbdcs_vision_frames_total');
      const s = (Date.now() - t0) / 1000;
      const rate = (n) => Number((n / s).toFixed(2));
      const sorted = [...lags].sort((x, y) => x - y);
      const result = {
        window_s: Number(s.toFixed(1)),
        feed_fps_drawn: rate(c1.drawn - c0.drawn),
        feed_pictures_fps_received: rate(c1.pictures - c0.pictures),
        feed_pictures_fps_sent: rate(sent1 - sent0),
        vision_results_fps_received_by_server: rate(vision1 - vision0),
        vision_results_fps_received: rate(c1.results - c0.results),
        vision_fps_mean_reported: visionFps.length
          ? Number((visionFps.reduce((x, y) => x + y, 0) / visionFps.length).toFixed(2))
          : null,
        skeleton_lag_ms_p50: sorted.length ? sorted[Math.floor(sorted.length / 2)] : null,
        skeleton_lag_ms_max: sorted.length ? sorted[sorted.length - 1] : null,
        skeleton_states_sampled: states,
      };
      writeFileSync(join(out, 'feed_fps.json'), JSON.stringify(result, null, 2) + '\n');
      log(
        `feed over ${result.window_s} s: ${result.feed_fps_drawn} FPS drawn, ${result.feed_pictures_fps_received} pictures/s received (${result.feed_pictures_fps_sent} sent), vision ${result.vision_results_fps_received} results/s`,
      );
    }

    // 7. Replay a stored session.
    await page.getByRole('link', { name: 'Sessions' }).click();
    await page.getByTestId('sessions').waitFor({ timeout: STEP_MS });
    await shot('sessions-list');
    await page
      .getByRole('link', { name: /Replay session/ })
      .first()
      .click();
    await page.getByTestId('replay-play').waitFor({ timeout: STEP_MS });
    await page.getByTestId('replay-speed').selectOption('16');
    await page.getByTestId('replay-play').click();
    await waitText('altitude', (t) => /m$/.test(t), 'the replay shows no telemetry');
    await waitText('replay-clock', (t) => !t.startsWith('0:00 '), 'the replay clock does not move');
    await waitText('gesture', (t) => t !== 'No gesture', 'the replay shows no gesture');
    await shot('replay-playing');

    // 8. Log out: the socket closes, back to the login screen.
    await page.getByRole('button', { name: 'Log out' }).click();
    await page.getByText('You logged out.').waitFor({ timeout: STEP_MS });
    await page.getByRole('button', { name: 'Log in', exact: true }).last().waitFor();
    // Every /ws/live socket the page opened is closed.
    for (const end = Date.now() + STEP_MS; sockets.some((w) => !w.isClosed());) {
      if (Date.now() > end) fail('a /ws/live socket is still open after log-out');
      await new Promise((r) => setTimeout(r, 100));
    }
    if (!sockets.length) fail('the page never opened /ws/live');
    await shot('logged-out');

    if (errors.length) fail(`errors in the page: ${errors.join('; ')}`);
    log(`PASS (${shots.length} screenshots in ${out})`);
  } catch (e) {
    // What the page showed when a step failed.
    await page?.screenshot({ path: join(out, 'failed.png') }).catch(() => {});
    throw e;
  } finally {
    await browser?.close().catch(() => {});
    child.kill('SIGTERM');
    await new Promise((r) => (child.exitCode !== null ? r() : child.once('exit', r)));
    writeFileSync(serverLog, Buffer.concat(logFd));
    if (!keep) rmSync(tmp, { recursive: true, force: true });
  }
}

main().catch((e) => {
  if (!process.exitCode) console.error(`web e2e: FAIL: ${e.stack ?? e}`);
  process.exitCode = 1;
});
