// The login kept in the browser (localStorage, so a phone app keeps it across restarts) until
// it expires or the operator logs out. Only the token and its expiry: never the password.
import type { LoginResponse, User } from '../types';

export interface StoredLogin {
  token: string;
  expiresAtMs: number;
  user: User;
}

const KEY = 'gbdcs.login';

export interface StorageLike {
  getItem(k: string): string | null;
  setItem(k: string, v: string): void;
  removeItem(k: string): void;
}

export function fromLoginResponse(r: LoginResponse, nowMs: number): StoredLogin {
  const parsed = Date.parse(r.expires_at);
  // Trust the shorter of expires_at and expires_in_s (a client clock off by minutes must not
  // keep a dead login).
  const byDuration = nowMs + r.expires_in_s * 1000;
  const expiresAtMs = Number.isFinite(parsed) ? Math.min(parsed, byDuration) : byDuration;
  return { token: r.token, expiresAtMs, user: r.user };
}

export function saveLogin(store: StorageLike, login: StoredLogin): void {
  store.setItem(KEY, JSON.stringify(login));
}

export function clearLogin(store: StorageLike): void {
  store.removeItem(KEY);
}

/** The stored login, or null when absent, unreadable or expired. */
export function loadLogin(store: StorageLike, nowMs: number): StoredLogin | null {
  const raw = store.getItem(KEY);
  if (!raw) return null;
  try {
    const v = JSON.parse(raw) as Partial<StoredLogin>;
    if (typeof v.token !== 'string' || typeof v.expiresAtMs !== 'number' || !v.user) return null;
    if (v.expiresAtMs <= nowMs) return null;
    return v as StoredLogin;
  } catch {
    return null;
  }
}
