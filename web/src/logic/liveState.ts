// The flying view's state, built from /ws/live messages by one pure reducer. The live socket
// and the replay player both feed it, so the panels are the same whether live or replayed.
// Camera frames and drone views do not pass through here (they go straight to the feed canvas
// and the drone-view image).
import type {
  Alert,
  GestureEvent,
  TelemetryFrame,
  WsCommandData,
  WsErrorData,
  WsServerMessage,
  WsStateData,
} from '../types';
import { CLEARED_BY } from './alerts';
import { appendPathPoint, type PathPoint } from './pathMap';

/** Telemetry older than this (client clock) shows "No data". The server sends >= 5 Hz. */
export const NO_DATA_AFTER_MS = 2000;
export const MAX_COMMANDS = 50;

export interface AlertEntry {
  /** The server's alert id (what an ack names); a local key when the alert has none. */
  key: string;
  alert: Alert;
  receivedAtMs: number;
  /** Sent an ack, waiting for ack_result. */
  acking: boolean;
  /** INFO alerts of one code share a banner: how many arrived (absent: 1). */
  count?: number;
}

export interface LiveState {
  telemetry: TelemetryFrame | null;
  telemetryAtMs: number | null;
  noData: boolean;
  gesture: GestureEvent | null;
  lastCommand: WsCommandData | null;
  commands: WsCommandData[];
  alerts: AlertEntry[];
  server: WsStateData | null;
  /** Flight path since the last take-off (x/y/altitude/heading). */
  path: PathPoint[];
  idleHovering: boolean;
  lastError: WsErrorData | null;
  replay: boolean;
  replayFinished: boolean;
}

export const initialLiveState: LiveState = {
  telemetry: null,
  telemetryAtMs: null,
  noData: true,
  gesture: null,
  lastCommand: null,
  commands: [],
  alerts: [],
  server: null,
  path: [],
  idleHovering: false,
  lastError: null,
  replay: false,
  replayFinished: false,
};

export type LiveAction =
  | { kind: 'message'; message: WsServerMessage; nowMs: number }
  | { kind: 'tick'; nowMs: number }
  | { kind: 'acking'; key: string }
  | { kind: 'dismiss'; key: string }
  | { kind: 'reset' };

const OPERATOR_SOURCES = new Set(['gesture', 'keyboard', 'api']);

export function alertKey(alert: Alert, fallback: string): string {
  return alert.id !== undefined ? String(alert.id) : `local-${alert.code}-${fallback}`;
}

export function liveReducer(state: LiveState, action: LiveAction): LiveState {
  switch (action.kind) {
    case 'reset':
      return initialLiveState;
    case 'tick': {
      const noData =
        state.telemetryAtMs === null || action.nowMs - state.telemetryAtMs > NO_DATA_AFTER_MS;
      return noData === state.noData ? state : { ...state, noData };
    }
    case 'acking':
      return {
        ...state,
        alerts: state.alerts.map((a) => (a.key === action.key ? { ...a, acking: true } : a)),
      };
    case 'dismiss':
      return { ...state, alerts: state.alerts.filter((a) => a.key !== action.key) };
    case 'message':
      return onMessage(state, action.message, action.nowMs);
  }
}

function onMessage(state: LiveState, msg: WsServerMessage, nowMs: number): LiveState {
  const replay = msg.replay === true;
  const base = replay !== state.replay ? { ...state, replay } : state;
  switch (msg.type) {
    case 'telemetry': {
      const t = msg.data;
      const wasFlying = state.telemetry ? isAirborne(state.telemetry.flight_state) : false;
      const flying = isAirborne(t.flight_state);
      // A take-off starts a new path; on the ground the last flight stays on the map.
      let path = state.path;
      if (flying && !wasFlying) path = [];
      if (flying || (wasFlying && !flying)) path = appendPathPoint(path, t);
      return {
        ...base,
        telemetry: t,
        telemetryAtMs: nowMs,
        noData: false,
        path,
        idleHovering: state.idleHovering && t.flight_state === 'FLYING',
      };
    }
    case 'gesture':
      return { ...base, gesture: msg.data };
    case 'command': {
      const c = msg.data;
      const commands = [c, ...state.commands].slice(0, MAX_COMMANDS);
      const operator = OPERATOR_SOURCES.has(c.command.source);
      return {
        ...base,
        lastCommand: c,
        commands,
        idleHovering: operator ? false : state.idleHovering,
      };
    }
    case 'alert': {
      const alert = msg.data;
      const key = alertKey(alert, `${nowMs}-${state.alerts.length}`);
      const cleared = CLEARED_BY[alert.code] ?? [];
      // An INFO alert replaces the earlier INFO banner of its code (newest wins, counted), so
      // a flapping condition cannot push the flying view off the screen; warnings and critical
      // alerts keep one banner each until acknowledged.
      const same = (a: AlertEntry) =>
        alert.severity === 'INFO' && a.alert.severity === 'INFO' && a.alert.code === alert.code;
      const count = state.alerts.filter(same).reduce((n, a) => n + (a.count ?? 1), 0) + 1;
      let alerts = state.alerts.filter(
        (a) => !cleared.includes(a.alert.code) && a.key !== key && !same(a),
      );
      alerts = [
        ...alerts,
        { key, alert, receivedAtMs: nowMs, acking: false, ...(count > 1 ? { count } : {}) },
      ];
      const idleHovering = alert.code === 'IDLE_HOVER' ? true : state.idleHovering;
      return { ...base, alerts, idleHovering };
    }
    case 'ack_result':
      return {
        ...base,
        alerts: state.alerts.filter((a) => a.key !== String(msg.data.alert_id)),
      };
    case 'state': {
      const s = msg.data;
      const replayFinished = replay && s.replay?.finished === true;
      return { ...base, server: replay ? state.server : s, replayFinished };
    }
    case 'error':
      return { ...base, lastError: msg.data };
    case 'frame':
    case 'picture':
    case 'drone_view':
      return base;
  }
}

export function isAirborne(s: TelemetryFrame['flight_state']): boolean {
  return s === 'FLYING' || s === 'LANDING';
}

/** Alerts most severe first, then newest first. */
export function sortedAlerts(alerts: readonly AlertEntry[]): AlertEntry[] {
  const rank = { CRITICAL: 0, WARNING: 1, INFO: 2 } as const;
  return [...alerts].sort(
    (a, b) => rank[a.alert.severity] - rank[b.alert.severity] || b.receivedAtMs - a.receivedAtMs,
  );
}

/** The command a gesture maps to in the profile in force, as the operator reads it. */
export function describeCommand(c: WsCommandData['command'] | null | undefined): string {
  if (!c) return '—';
  if (c.type !== 'MOVE' || !c.payload) return c.type;
  const p = c.payload;
  const parts: string[] = [];
  if (p.vx_m_s) parts.push(`${p.vx_m_s > 0 ? 'forward' : 'back'} ${Math.abs(p.vx_m_s)} m/s`);
  if (p.vy_m_s) parts.push(`${p.vy_m_s > 0 ? 'right' : 'left'} ${Math.abs(p.vy_m_s)} m/s`);
  if (p.vz_m_s) parts.push(`${p.vz_m_s > 0 ? 'up' : 'down'} ${Math.abs(p.vz_m_s)} m/s`);
  if (p.yaw_rate_deg_s)
    parts.push(`yaw ${p.yaw_rate_deg_s > 0 ? 'right' : 'left'} ${Math.abs(p.yaw_rate_deg_s)}°/s`);
  return parts.length ? `MOVE ${parts.join(', ')}` : 'MOVE';
}
