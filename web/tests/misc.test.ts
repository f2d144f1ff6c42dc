import { describe, expect, it } from 'vitest';
import { Api, ApiFailure } from '../src/api/http';
import { fromLoginResponse, loadLogin, saveLogin, type StorageLike } from '../src/logic/auth';
import { FpsMeter } from '../src/logic/fps';
import { parseRoute, routeHash } from '../src/logic/route';
import { containFit, projectLandmarks } from '../src/logic/skeleton';

class MemStore implements StorageLike {
  m = new Map<string, string>();
  getItem(k: string) {
    return this.m.get(k) ?? null;
  }
  setItem(k: string, v: string) {
    this.m.set(k, v);
  }
  removeItem(k: string) {
    this.m.delete(k);
  }
}

const user = {
  id: 1,
  email: 'a@b.c',
  theme: 'dark' as const,
  created_at: '2026-11-23T10:00:00.000Z',
};

describe('stored login', () => {
  it('keeps the login until it expires, trusting the shorter expiry', () => {
    const now = Date.parse('2026-11-23T10:00:00.000Z');
    const l = fromLoginResponse(
      {
        token: 'x'.repeat(30),
        token_type: 'Bearer',
        expires_at: '2026-11-23T10:30:00.000Z',
        expires_in_s: 600,
        user,
      },
      now,
    );
    expect(l.expiresAtMs).toBe(now + 600_000);
    const store = new MemStore();
    saveLogin(store, l);
    expect(loadLogin(store, now + 599_999)?.token).toBe(l.token);
    expect(loadLogin(store, now + 600_000)).toBeNull();
    store.setItem('gbdcs.login', '{broken');
    expect(loadLogin(store, now)).toBeNull();
  });
});

describe('Api', () => {
  it('turns an error envelope into an ApiFailure and reports a lost login', async () => {
    const lost: ApiFailure[] = [];
    const body = {
      error: 'token_expired',
      cause: 'the token expired at 10:30',
      suggestion: 'log in again',
      request_id: '01JD3Z8Q4K7J9ZK3M2V6X1N0AB',
    };
    const api = new Api({
      fetch: async () => new Response(JSON.stringify(body), { status: 401 }),
      onUnauthorized: (f) => lost.push(f),
    });
    api.setToken('t');
    await expect(api.getConfig()).rejects.toMatchObject({ status: 401, envelope: body });
    expect(lost).toHaveLength(1);
  });

  it('does not treat a failed login as a lost session', async () => {
    const lost: ApiFailure[] = [];
    const api = new Api({
      fetch: async () =>
        new Response(
          JSON.stringify({
            error: 'invalid_credentials',
            cause: 'wrong',
            suggestion: 'retry',
            request_id: '',
          }),
          { status: 401 },
        ),
      onUnauthorized: (f) => lost.push(f),
    });
    await expect(api.login('a@b.c', 'x')).rejects.toBeInstanceOf(ApiFailure);
    expect(lost).toEqual([]);
  });

  it('explains a network failure and a non-envelope error', async () => {
    const down = new Api({ fetch: async () => Promise.reject(new Error('ECONNREFUSED')) });
    await expect(down.getConfig()).rejects.toMatchObject({
      status: 0,
      envelope: { error: 'network' },
    });
    const odd = new Api({
      fetch: async () => new Response('oops', { status: 502, statusText: 'Bad Gateway' }),
    });
    await expect(odd.getConfig()).rejects.toMatchObject({
      status: 502,
      envelope: { error: 'http_502' },
    });
  });

  it('sends the bearer token and JSON body', async () => {
    let seen: RequestInit | undefined;
    const api = new Api({
      fetch: async (_u, init) => {
        seen = init;
        return new Response('{"profile":{}}', { status: 200 });
      },
    });
    api.setToken('tok');
    await api.putConfig({ theme: 'light' });
    expect((seen?.headers as Record<string, string>).Authorization).toBe('Bearer tok');
    expect(seen?.body).toBe('{"theme":"light"}');
  });
});

describe('skeleton projection', () => {
  it('letterboxes the image and maps normalised landmarks onto it', () => {
    const fit = containFit(640, 480, 800, 800);
    expect(fit).toEqual({ x: 0, y: 100, width: 800, height: 600 });
    const pts = projectLandmarks(
      Array.from({ length: 21 }, () => [0.5, 1, 0]),
      fit,
    );
    expect(pts?.[0]).toEqual([400, 700]);
    expect(projectLandmarks([[0, 0, 0]], fit)).toBeNull();
    expect(
      projectLandmarks(
        Array.from({ length: 21 }, () => [NaN, 0, 0]),
        fit,
      ),
    ).toBeNull();
  });
});

describe('fps meter', () => {
  it('measures frames per second over its window', () => {
    const m = new FpsMeter(1000);
    for (let t = 0; t <= 1000; t += 40) m.frame(t);
    expect(m.fps(1000)).toBeCloseTo(25, 0);
    expect(m.fps(5000)).toBe(0);
  });
});

describe('routes', () => {
  it('round-trips every page', () => {
    for (const h of ['#/fly', '#/sessions', '#/sessions/12', '#/settings', '#/help'])
      expect(routeHash(parseRoute(h))).toBe(h);
    expect(parseRoute('')).toEqual({ page: 'fly' });
    expect(parseRoute('#/nope')).toEqual({ page: 'fly' });
  });
});

describe('ViewBus', () => {
  it('keeps the newest drone view, counts them, tells subscribers, and clears', async () => {
    const { ViewBus } = await import('../src/logic/frameBus');
    const bus = new ViewBus();
    const seen: number[] = [];
    const off = bus.subscribe((v) => seen.push(v.frame_id));
    const view = (id: number) => ({
      frame_id: id,
      camera: 'chase',
      width: 2,
      height: 2,
      jpeg: 'x',
    });
    bus.push(view(0));
    bus.push(view(1));
    expect(bus.latest?.frame_id).toBe(1);
    expect(bus.received).toBe(2);
    off();
    bus.push(view(2));
    expect(seen).toEqual([0, 1]);
    bus.clear();
    expect(bus.latest).toBeNull();
  });
});
