import { describe, expect, it } from 'vitest';
import {
  CLOSE_AUTH,
  LiveConnection,
  parseServerMessage,
  reconnectDelayMs,
  type LiveOptions,
  type SocketLike,
} from '../src/api/live';
import type { WsServerMessage } from '../src/types';

class FakeSocket implements SocketLike {
  readyState = 0;
  sent: string[] = [];
  closedWith: number | null = null;
  onopen: SocketLike['onopen'] = null;
  onclose: SocketLike['onclose'] = null;
  onmessage: SocketLike['onmessage'] = null;
  onerror: SocketLike['onerror'] = null;
  send(d: string) {
    this.sent.push(d);
  }
  close(code?: number) {
    this.closedWith = code ?? 1000;
    this.readyState = 3;
  }
  open() {
    this.readyState = 1;
    this.onopen?.({});
  }
  serverClose(code: number, reason = '') {
    this.readyState = 3;
    this.onclose?.({ code, reason });
  }
}

function harness(over: Partial<LiveOptions> = {}) {
  let now = 1_000_000;
  const timers: { at: number; fn: () => void; id: number }[] = [];
  let nextId = 1;
  const sockets: FakeSocket[] = [];
  const got: WsServerMessage[] = [];
  const statuses: string[] = [];
  const lost: string[] = [];
  const conn = new LiveConnection({
    url: 'ws://x/ws/live?token=t',
    expiresAtMs: now + 60_000,
    onMessage: (m) => got.push(m),
    onStatus: (s) => statuses.push(s),
    onAuthLost: (r) => lost.push(r),
    makeSocket: () => {
      const s = new FakeSocket();
      sockets.push(s);
      return s;
    },
    now: () => now,
    setTimer: (fn, ms) => {
      const id = nextId++;
      timers.push({ at: now + ms, fn, id });
      return id;
    },
    clearTimer: (id) => {
      const i = timers.findIndex((t) => t.id === id);
      if (i >= 0) timers.splice(i, 1);
    },
    ...over,
  });
  const advance = async (ms: number) => {
    now += ms;
    for (;;) {
      const due = timers.filter((t) => t.at <= now).sort((a, b) => a.at - b.at)[0];
      if (!due) break;
      timers.splice(timers.indexOf(due), 1);
      due.fn();
    }
    await Promise.resolve();
  };
  return { conn, sockets, got, statuses, lost, advance, timers };
}

const flush = () => new Promise((r) => setTimeout(r, 0));

describe('reconnect back-off', () => {
  it('doubles from 0.5 s up to 8 s', () => {
    expect([0, 1, 2, 3, 4, 5, 10].map(reconnectDelayMs)).toEqual([
      500, 1000, 2000, 4000, 8000, 8000, 8000,
    ]);
  });
});

describe('parseServerMessage', () => {
  it('accepts the server envelope and rejects anything else', () => {
    expect(parseServerMessage('{"type":"telemetry","ts":"x","data":{}}')?.type).toBe('telemetry');
    expect(
      parseServerMessage(
        '{"type":"drone_view","ts":"x","data":{"frame_id":0,"camera":"chase","width":1,"height":1,"jpeg":"AA=="}}',
      )?.type,
    ).toBe('drone_view');
    expect(parseServerMessage('{"type":"bogus","data":{}}')).toBeNull();
    expect(parseServerMessage('{"type":"alert"}')).toBeNull();
    expect(parseServerMessage('not json')).toBeNull();
    expect(parseServerMessage(42)).toBeNull();
  });
});

describe('LiveConnection', () => {
  it('delivers messages and sends only when open', () => {
    const h = harness();
    h.conn.start();
    const s = h.sockets[0]!;
    expect(h.conn.send({ type: 'emergency_stop' })).toBe(false);
    s.open();
    expect(h.conn.send({ type: 'input', key: 'w', pressed: true })).toBe(true);
    expect(JSON.parse(s.sent[0]!)).toEqual({ type: 'input', key: 'w', pressed: true });
    s.onmessage?.({ data: '{"type":"gesture","ts":"x","data":{"gesture":"FIST"}}' });
    s.onmessage?.({ data: 'garbage' });
    expect(h.got.map((m) => m.type)).toEqual(['gesture']);
  });

  it('reconnects with back-off after a dropped connection', async () => {
    const h = harness();
    h.conn.start();
    h.sockets[0]!.open();
    h.sockets[0]!.serverClose(1006);
    await flush();
    expect(h.sockets).toHaveLength(1);
    await h.advance(499);
    expect(h.sockets).toHaveLength(1);
    await h.advance(1);
    expect(h.sockets).toHaveLength(2);
    h.sockets[1]!.serverClose(1006);
    await flush();
    await h.advance(999);
    expect(h.sockets).toHaveLength(2);
    await h.advance(1);
    expect(h.sockets).toHaveLength(3);
    expect(h.statuses).toContain('reconnecting');
  });

  it('goes back to login with the server reason on close 4001 (logout / revoked), no reconnect', async () => {
    const h = harness();
    h.conn.start();
    h.sockets[0]!.open();
    h.sockets[0]!.serverClose(CLOSE_AUTH, 'token revoked');
    await flush();
    await h.advance(60_000);
    expect(h.lost).toEqual(['token revoked']);
    expect(h.sockets).toHaveLength(1);
  });

  it('tells the user the session expired when the token time is up', async () => {
    const h = harness();
    h.conn.start();
    h.sockets[0]!.open();
    await h.advance(60_000);
    expect(h.lost).toHaveLength(1);
    expect(h.lost[0]).toMatch(/session expired/);
    expect(h.sockets[0]!.closedWith).toBe(1000);
  });

  it('refuses to start with an expired token', () => {
    const h = harness({ expiresAtMs: 0 });
    h.conn.start();
    expect(h.sockets).toHaveLength(0);
    expect(h.lost[0]).toMatch(/expired/);
  });

  it('stops reconnecting when the server says the token is no longer valid', async () => {
    const h = harness({ checkAuth: async () => false });
    h.conn.start();
    h.sockets[0]!.serverClose(1006);
    await flush();
    await h.advance(10_000);
    expect(h.sockets).toHaveLength(1);
  });

  it('stop() closes the socket and cancels the reconnect', async () => {
    const h = harness();
    h.conn.start();
    h.sockets[0]!.serverClose(1006);
    await flush();
    h.conn.stop();
    await h.advance(10_000);
    expect(h.sockets).toHaveLength(1);
    expect(h.statuses.at(-1)).toBe('closed');
  });
});
