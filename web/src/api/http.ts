// REST client for /api/v1 (docs/API.md). Every HTTP error becomes an ApiFailure carrying the
// server's envelope {error, cause, suggestion, request_id}; a network failure gets an envelope
// of our own that says what to do. A 401 on an authenticated call tells the app the login is
// gone (expired, revoked) so it can go back to the login screen with the reason.
import type {
  ApiError,
  Config,
  ConfigUpdate,
  ControlState,
  LoginResponse,
  ReplayStarted,
  SessionDetail,
  SessionList,
  TelemetryHistory,
  User,
} from '../types';

export class ApiFailure extends Error {
  constructor(
    readonly status: number,
    readonly envelope: ApiError,
    readonly retryAfterS: number | null = null,
  ) {
    super(`${envelope.error}: ${envelope.cause}`);
  }
}

export function isApiError(v: unknown): v is ApiError {
  if (!v || typeof v !== 'object') return false;
  const o = v as Record<string, unknown>;
  return (
    typeof o.error === 'string' && typeof o.cause === 'string' && typeof o.suggestion === 'string'
  );
}

export type FetchLike = (input: string, init?: RequestInit) => Promise<Response>;

export interface ApiOptions {
  base?: string;
  fetch?: FetchLike;
  /** Called when an authenticated request answers 401 (login expired or revoked). */
  onUnauthorized?: (failure: ApiFailure) => void;
}

export class Api {
  private token: string | null = null;
  private readonly base: string;
  private readonly fetchFn: FetchLike;

  constructor(private readonly options: ApiOptions = {}) {
    this.base = options.base ?? '/api/v1';
    this.fetchFn = options.fetch ?? ((i, init) => fetch(i, init));
  }

  setToken(token: string | null): void {
    this.token = token;
  }

  async request<T>(method: string, path: string, body?: unknown, auth = true): Promise<T> {
    const headers: Record<string, string> = { Accept: 'application/json' };
    if (body !== undefined) headers['Content-Type'] = 'application/json';
    if (auth && this.token) headers.Authorization = `Bearer ${this.token}`;
    let res: Response;
    try {
      res = await this.fetchFn(this.base + path, {
        method,
        headers,
        body: body === undefined ? undefined : JSON.stringify(body),
      });
    } catch (e) {
      throw new ApiFailure(0, {
        error: 'network',
        cause: `The server could not be reached (${e instanceof Error ? e.message : String(e)}).`,
        suggestion: 'Check that gbdcs serve is running and this page was opened from its address.',
        request_id: '',
      });
    }
    if (res.status === 204) return undefined as T;
    const text = await res.text();
    let json: unknown = undefined;
    try {
      json = text ? JSON.parse(text) : undefined;
    } catch {
      json = undefined;
    }
    if (!res.ok) {
      const envelope: ApiError = isApiError(json)
        ? json
        : {
            error: `http_${res.status}`,
            cause: `The server answered ${res.status} ${res.statusText} without an error body.`,
            suggestion: 'Retry; if it persists, check the server log.',
            request_id: res.headers.get('X-Request-Id') ?? '',
          };
      const ra = res.headers.get('Retry-After');
      const failure = new ApiFailure(res.status, envelope, ra ? Number(ra) : null);
      if (res.status === 401 && auth && this.token) this.options.onUnauthorized?.(failure);
      throw failure;
    }
    return json as T;
  }

  register(email: string, password: string): Promise<User> {
    return this.request('POST', '/auth/register', { email, password }, false);
  }
  login(email: string, password: string): Promise<LoginResponse> {
    return this.request('POST', '/auth/login', { email, password }, false);
  }
  logout(): Promise<void> {
    return this.request('POST', '/auth/logout');
  }
  getConfig(): Promise<Config> {
    return this.request('GET', '/config');
  }
  putConfig(update: ConfigUpdate): Promise<Config> {
    return this.request('PUT', '/config', update);
  }
  sessions(limit = 50, offset = 0): Promise<SessionList> {
    return this.request('GET', `/sessions?limit=${limit}&offset=${offset}`);
  }
  session(id: number): Promise<SessionDetail> {
    return this.request('GET', `/sessions/${id}`);
  }
  telemetry(id: number): Promise<TelemetryHistory> {
    return this.request('GET', `/sessions/${id}/telemetry`);
  }
  replayOnServer(id: number, speed: number): Promise<ReplayStarted> {
    return this.request('POST', `/sessions/${id}/replay`, { speed });
  }
  emergencyStop(reason: string): Promise<ControlState> {
    return this.request('POST', '/control/emergency-stop', { reason });
  }
  emergencyReset(): Promise<ControlState> {
    return this.request('POST', '/control/emergency-reset');
  }
  ackAlert(id: number): Promise<unknown> {
    return this.request('POST', `/alerts/${id}/ack`);
  }
}
