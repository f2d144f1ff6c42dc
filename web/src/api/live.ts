// The /ws/live connection: parses server messages, sends client messages (ws_client_message),
// reconnects with back-off after a dropped connection, and stops for good when the login is
// gone (logout or revocation: close code 4001; expiry: the token's time is up), telling the
// app why so it can show the login screen with that reason.
import type { WsClientMessage, WsServerMessage } from '../types';

export const CLOSE_AUTH = 4001;
const SERVER_TYPES = new Set([
  'gesture',
  'telemetry',
  'alert',
  'command',
  'state',
  'frame',
  'picture',
  'drone_view',
  'ack_result',
  'error',
]);

export type LinkStatus = 'connecting' | 'open' | 'reconnecting' | 'closed';

export interface SocketLike {
  readyState: number;
  send(data: string): void;
  close(code?: number, reason?: string): void;
  onopen: ((ev: unknown) => void) | null;
  onclose: ((ev: { code: number; reason: string }) => void) | null;
  onmessage: ((ev: { data: unknown }) => void) | null;
  onerror: ((ev: unknown) => void) | null;
}

export interface LiveOptions {
  url: string;
  /** ms since epoch when the token expires */
  expiresAtMs: number;
  onMessage(msg: WsServerMessage): void;
  onStatus(status: LinkStatus, detail?: string): void;
  /** The login is gone: do not reconnect; go back to the login screen with this reason. */
  onAuthLost(reason: string): void;
  /** A close we cannot explain from here: ask the server (REST) whether the token still works. */
  checkAuth?: () => Promise<boolean>;
  makeSocket?: (url: string) => SocketLike;
  now?: () => number;
  setTimer?: (fn: () => void, ms: number) => unknown;
  clearTimer?: (t: unknown) => void;
}

/** Back-off before reconnect attempt n (0-based): 0.5 s doubling to 8 s. */
export function reconnectDelayMs(attempt: number): number {
  return Math.min(8000, 500 * Math.pow(2, Math.max(0, attempt)));
}

/** Parses one text message; null when it is not a server message we know. */
export function parseServerMessage(data: unknown): WsServerMessage | null {
  if (typeof data !== 'string') return null;
  let v: unknown;
  try {
    v = JSON.parse(data);
  } catch {
    return null;
  }
  if (!v || typeof v !== 'object') return null;
  const o = v as Record<string, unknown>;
  if (typeof o.type !== 'string' || !SERVER_TYPES.has(o.type)) return null;
  if (!o.data || typeof o.data !== 'object') return null;
  return v as WsServerMessage;
}

export function expiryMessage(expiresAtMs: number): string {
  const at = new Date(expiresAtMs).toLocaleTimeString();
  return `Your session expired at ${at}: logins last at most 30 minutes. Log in again to keep flying.`;
}

export class LiveConnection {
  private socket: SocketLike | null = null;
  private attempt = 0;
  private timer: unknown = null;
  private expiryTimer: unknown = null;
  private stopped = false;
  private readonly now: () => number;
  private readonly setTimer: (fn: () => void, ms: number) => unknown;
  private readonly clearTimer: (t: unknown) => void;

  constructor(private readonly o: LiveOptions) {
    this.now = o.now ?? (() => Date.now());
    this.setTimer = o.setTimer ?? ((fn, ms) => setTimeout(fn, ms));
    this.clearTimer = o.clearTimer ?? ((t) => clearTimeout(t as ReturnType<typeof setTimeout>));
  }

  start(): void {
    this.stopped = false;
    const left = this.o.expiresAtMs - this.now();
    if (left <= 0) {
      this.authLost(expiryMessage(this.o.expiresAtMs));
      return;
    }
    // The server closes the socket at expiry too; the timer makes sure the user is told even
    // when the close is lost.
    this.expiryTimer = this.setTimer(() => this.authLost(expiryMessage(this.o.expiresAtMs)), left);
    this.open('connecting');
  }

  /** Close for good (log out, leaving the view). */
  stop(): void {
    this.stopped = true;
    if (this.timer !== null) this.clearTimer(this.timer);
    if (this.expiryTimer !== null) this.clearTimer(this.expiryTimer);
    this.timer = this.expiryTimer = null;
    const s = this.socket;
    this.socket = null;
    if (s) {
      s.onclose = s.onmessage = s.onerror = s.onopen = null;
      s.close(1000, 'client closed');
    }
    this.o.onStatus('closed');
  }

  /** Sends when open; false when not connected (the caller can fall back to REST). */
  send(msg: WsClientMessage): boolean {
    if (!this.socket || this.socket.readyState !== 1) return false;
    this.socket.send(JSON.stringify(msg));
    return true;
  }

  isOpen(): boolean {
    return this.socket !== null && this.socket.readyState === 1;
  }

  private open(status: LinkStatus): void {
    if (this.stopped) return;
    this.o.onStatus(status);
    const make =
      this.o.makeSocket ?? ((url: string) => new WebSocket(url) as unknown as SocketLike);
    const s = make(this.o.url);
    this.socket = s;
    s.onopen = () => {
      this.attempt = 0;
      this.o.onStatus('open');
    };
    s.onmessage = (ev) => {
      const msg = parseServerMessage(ev.data);
      if (msg) this.o.onMessage(msg);
    };
    s.onerror = () => {};
    s.onclose = (ev) => void this.closed(ev.code, ev.reason);
  }

  private async closed(code: number, reason: string): Promise<void> {
    this.socket = null;
    if (this.stopped) return;
    if (this.now() >= this.o.expiresAtMs) {
      this.authLost(expiryMessage(this.o.expiresAtMs));
      return;
    }
    if (code === CLOSE_AUTH) {
      this.authLost(reason || 'You were logged out (the login was revoked). Log in again.');
      return;
    }
    // A refused handshake (401) looks like 1006 to a browser: ask the server.
    if (this.o.checkAuth) {
      let ok = true;
      try {
        ok = await this.o.checkAuth();
      } catch {
        ok = true; // server unreachable: keep trying to reconnect
      }
      if (this.stopped) return;
      if (!ok) return; // checkAuth's 401 already told the app why (onUnauthorized)
    }
    const delay = reconnectDelayMs(this.attempt++);
    this.o.onStatus(
      'reconnecting',
      `connection lost (code ${code}); retrying in ${delay / 1000} s`,
    );
    this.timer = this.setTimer(() => {
      this.timer = null;
      this.open('reconnecting');
    }, delay);
  }

  private authLost(reason: string): void {
    if (this.stopped) return;
    this.stop();
    this.o.onAuthLost(reason);
  }
}

export function liveUrl(
  token: string,
  loc: { protocol: string; host: string } = window.location,
): string {
  const scheme = loc.protocol === 'https:' ? 'wss:' : 'ws:';
  return `${scheme}//${loc.host}/ws/live?token=${encodeURIComponent(token)}`;
}
