#!/usr/bin/env node
/* global document, localStorage, getComputedStyle -- page.evaluate bodies run in the page */
// Browser smoke test of the built dashboard (web/dist) in Debian's chromium, without a server:
// the bundle loads without errors, the manifest and its icons are served and valid, the login
// form works with the keyboard alone and explains an unreachable API with a cause and a
// suggestion, the flying view shows "No data" while nothing arrives, Space does not crash it,
// both themes apply, and the help page shows every gesture. Screenshots go to --out.
//
//   node e2e/smoke.mjs [--out build/web-smoke] [--chromium /usr/bin/chromium]
//
// Fails (never skips) when chromium or web/dist is missing. The full flight against a real
// `gbdcs serve` is e2e/run.mjs.
import { createServer } from 'node:http';
import { existsSync, mkdirSync, readFileSync, statSync } from 'node:fs';
import { extname, join, normalize, resolve, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const web = resolve(here, '..');
const dist = join(web, 'dist');
const arg = (n, d) => {
  const i = process.argv.indexOf(`--${n}`);
  return i >= 0 ? process.argv[i + 1] : d;
};
const out = resolve(arg('out', join(web, '..', 'build', 'web-smoke')));
const chromiumPath = arg('chromium', process.env.GBDCS_CHROMIUM ?? '/usr/bin/chromium');

const fail = (m) => {
  throw new Error(m);
};
const log = (m) => console.log(`web smoke: ${m}`);

const TYPES = {
  '.html': 'text/html',
  '.js': 'text/javascript',
  '.css': 'text/css',
  '.svg': 'image/svg+xml',
  '.png': 'image/png',
  '.webmanifest': 'application/manifest+json',
  '.json': 'application/json',
  '.map': 'application/json',
};

function serveDist() {
  const server = createServer((req, res) => {
    const path = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    if (path.startsWith('/api/') || path.startsWith('/ws/')) {
      res.writeHead(503, { 'Content-Type': 'text/plain' });
      res.end('no server in the smoke test');
      return;
    }
    let file = normalize(join(dist, path));
    if (!file.startsWith(dist)) {
      res.writeHead(404);
      res.end();
      return;
    }
    if (!existsSync(file) || statSync(file).isDirectory()) file = join(dist, 'index.html');
    res.writeHead(200, { 'Content-Type': TYPES[extname(file)] ?? 'application/octet-stream' });
    res.end(readFileSync(file));
  });
  return new Promise((r) => server.listen(0, '127.0.0.1', () => r(server)));
}

async function main() {
  if (!existsSync(chromiumPath))
    fail(`chromium not found at ${chromiumPath} (ci/setup installs it)`);
  if (!existsSync(join(dist, 'index.html'))) fail('web/dist is not built (ci/setup builds it)');
  const { chromium } = await import('playwright-core');
  mkdirSync(out, { recursive: true });
  const server = await serveDist();
  const base = `http://127.0.0.1:${server.address().port}`;
  const browser = await chromium.launch({
    executablePath: chromiumPath,
    headless: true,
    args: ['--no-sandbox', '--disable-dev-shm-usage'],
  });
  try {
    const page = await browser.newPage({ viewport: { width: 1366, height: 768 } });
    const errors = [];
    page.on('pageerror', (e) => errors.push(e.message));
    let n = 0;
    const shot = async (name) => {
      await page.screenshot({ path: join(out, `${String(++n).padStart(2, '0')}-${name}.png`) });
      log(`${name} ok`);
    };

    await page.goto(base + '/');
    if (!(await page.title()).includes('GBDCS')) fail('no GBDCS title');

    // Manifest and icons.
    const href = await page.getAttribute('link[rel="manifest"]', 'href');
    const manifest = await (await fetch(new URL(href, base))).json();
    if (manifest.display !== 'standalone' || !manifest.start_url || !manifest.name)
      fail(`manifest incomplete: ${JSON.stringify(manifest)}`);
    for (const icon of manifest.icons) {
      const r = await fetch(new URL(icon.src, base));
      if (!r.ok || !(r.headers.get('content-type') ?? '').startsWith('image/'))
        fail(`manifest icon ${icon.src} not served as an image`);
    }
    if (!manifest.icons.some((i) => i.sizes === '512x512')) fail('no 512x512 icon');

    // Keyboard only: Tab to the fields and the button, Enter submits.
    await page.keyboard.press('Tab'); // Log in tab
    await page.keyboard.press('Tab'); // Register tab
    await page.keyboard.press('Tab');
    const focused1 = await page.evaluate(() => document.activeElement?.getAttribute('name'));
    if (focused1 !== 'email') fail(`Tab order: expected the e-mail field, got ${focused1}`);
    await page.keyboard.type('pilot@example.com');
    await page.keyboard.press('Tab');
    await page.keyboard.type('a long password 1');
    await page.keyboard.press('Enter');
    const box = page.getByRole('alert');
    await box.waitFor({ timeout: 20000 });
    const t = await box.innerText();
    if (!/Could not log in/.test(t) || !/What to do:/.test(t)) fail(`login error box: "${t}"`);
    await shot('login-error-explained');

    // The flying view with a stored login and no server: "No data", reconnecting, no crash.
    await page.evaluate(() =>
      localStorage.setItem(
        'gbdcs.login',
        JSON.stringify({
          token: 'smoke-token',
          expiresAtMs: Date.now() + 600000,
          user: {
            id: 1,
            email: 'pilot@example.com',
            theme: 'dark',
            created_at: '2026-01-01T00:00:00.000Z',
          },
        }),
      ),
    );
    await page.reload();
    await page.getByTestId('no-data').waitFor({ timeout: 20000 });
    await page.getByTestId('estop').waitFor();
    await page.keyboard.press('Space');
    await page.getByText(/EMERGENCY STOP (sent|NOT DELIVERED)/).waitFor({ timeout: 20000 });
    const estopBox = await page.getByTestId('estop').boundingBox();
    if (!estopBox || estopBox.y + estopBox.height > 768)
      fail('the emergency stop is not visible without scrolling');
    for (const id of [
      'gesture',
      'confidence',
      'mapped-command',
      'altitude',
      'flight-state',
      'battery',
    ]) {
      const b = await page.getByTestId(id).boundingBox();
      if (!b || b.y + b.height > 768) fail(`[${id}] is not visible without scrolling at 1366x768`);
    }
    await shot('fly-view-no-data');

    // Themes.
    const bg = () => page.evaluate(() => getComputedStyle(document.body).backgroundColor);
    const dark = await bg();
    await page.evaluate(() => (document.documentElement.dataset.theme = 'light'));
    const light = await bg();
    if (dark === light) fail('the light theme does not change the background');
    await shot('fly-view-light-theme');

    await page.goto(base + '/#/help');
    await page.reload();
    const pictures = await page.locator('.gesture-cards .hand-picture').count();
    if (pictures !== 9) fail(`help shows ${pictures} gesture pictures, expected 9`);
    await shot('help');

    if (errors.length) fail(`errors in the page: ${errors.join('; ')}`);
    log(`PASS (screenshots in ${out})`);
  } finally {
    await browser.close();
    server.close();
  }
}

main().catch((e) => {
  console.error(`web smoke: FAIL: ${e.message}`);
  process.exitCode = 1;
});
