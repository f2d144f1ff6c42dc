// Replay of a stored session in the browser: the session's gestures, commands, alerts and
// telemetry (GET /sessions/{id} and /telemetry) become one timeline of /ws/live messages
// marked replay, folded through the same reducer as the live view. Play, pause, speed and
// seeking are pure functions of the position on the timeline.
import type { SessionDetail, TelemetryFrame, WsServerMessage } from '../types';
import { initialLiveState, liveReducer, type LiveState } from './liveState';

export interface TimedMessage {
  tMs: number;
  msg: WsServerMessage;
}

export interface Timeline {
  startMs: number;
  endMs: number;
  events: TimedMessage[];
}

function t(iso: string): number {
  const v = Date.parse(iso);
  return Number.isFinite(v) ? v : NaN;
}

export function buildTimeline(detail: SessionDetail, frames: readonly TelemetryFrame[]): Timeline {
  const events: TimedMessage[] = [];
  const push = (iso: string, msg: WsServerMessage) => {
    const tMs = t(iso);
    if (Number.isFinite(tMs)) events.push({ tMs, msg });
  };
  for (const f of frames)
    push(f.timestamp, { type: 'telemetry', ts: f.timestamp, replay: true, data: f });
  for (const g of detail.gestures)
    push(g.timestamp, { type: 'gesture', ts: g.timestamp, replay: true, data: g });
  for (const c of detail.commands)
    push(c.recorded_at, {
      type: 'command',
      ts: c.recorded_at,
      replay: true,
      data: { command: c.command, outcome: c.outcome },
    });
  for (const a of detail.alerts) {
    push(a.alert.timestamp, { type: 'alert', ts: a.alert.timestamp, replay: true, data: a.alert });
    if (a.acknowledged_at && a.alert.id !== undefined)
      push(a.acknowledged_at, {
        type: 'ack_result',
        ts: a.acknowledged_at,
        replay: true,
        data: { alert_id: a.alert.id, acknowledged_at: a.acknowledged_at },
      });
  }
  // Stable: equal times keep insertion order (telemetry before the gesture of the same instant).
  events.sort((a, b) => a.tMs - b.tMs);
  const sessionStart = t(detail.session.started_at);
  const startMs = Math.min(
    Number.isFinite(sessionStart) ? sessionStart : Infinity,
    events[0]?.tMs ?? Infinity,
  );
  const ended = detail.session.ended_at ? t(detail.session.ended_at) : NaN;
  const lastEvent = events[events.length - 1]?.tMs ?? startMs;
  const endMs = Math.max(Number.isFinite(ended) ? ended : lastEvent, lastEvent);
  return Number.isFinite(startMs)
    ? { startMs, endMs, events }
    : { startMs: 0, endMs: 0, events: [] };
}

/** Index of the first event after position positionMs (ms from the timeline's start). */
export function eventIndexAfter(tl: Timeline, positionMs: number): number {
  const target = tl.startMs + positionMs;
  let lo = 0;
  let hi = tl.events.length;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if ((tl.events[mid]?.tMs ?? Infinity) <= target) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

/** Applies events [from, to) and a tick at the position. */
export function applyEvents(
  state: LiveState,
  tl: Timeline,
  from: number,
  to: number,
  positionMs: number,
): LiveState {
  let s = state;
  for (let i = from; i < to; i++) {
    const e = tl.events[i];
    if (e) s = liveReducer(s, { kind: 'message', message: e.msg, nowMs: e.tMs });
  }
  return liveReducer(s, { kind: 'tick', nowMs: tl.startMs + positionMs });
}

/** The panels' state at a position (for seeking): everything up to it, replayed. */
export function stateAt(tl: Timeline, positionMs: number): { state: LiveState; next: number } {
  const next = eventIndexAfter(tl, positionMs);
  return { state: applyEvents(initialLiveState, tl, 0, next, positionMs), next };
}

export interface Player {
  positionMs: number;
  playing: boolean;
  speed: number;
  next: number;
  state: LiveState;
}

export const SPEEDS = [0.5, 1, 2, 4, 8, 16] as const;

export function newPlayer(tl: Timeline): Player {
  return { positionMs: 0, playing: false, speed: 1, ...stateAt(tl, 0) };
}

export function durationMs(tl: Timeline): number {
  return Math.max(0, tl.endMs - tl.startMs);
}

/** Advances a playing player by wallMs of real time (times its speed); pauses at the end. */
export function advance(p: Player, tl: Timeline, wallMs: number): Player {
  if (!p.playing) return p;
  const end = durationMs(tl);
  const positionMs = Math.min(end, p.positionMs + wallMs * p.speed);
  const next = eventIndexAfter(tl, positionMs);
  const state = applyEvents(p.state, tl, p.next, next, positionMs);
  return { ...p, positionMs, next, state, playing: positionMs < end };
}

export function seek(p: Player, tl: Timeline, positionMs: number): Player {
  const pos = Math.max(0, Math.min(durationMs(tl), positionMs));
  if (pos >= p.positionMs) {
    const next = eventIndexAfter(tl, pos);
    return { ...p, positionMs: pos, next, state: applyEvents(p.state, tl, p.next, next, pos) };
  }
  return { ...p, positionMs: pos, ...stateAt(tl, pos) };
}

export function formatClock(ms: number): string {
  const s = Math.max(0, Math.floor(ms / 1000));
  const m = Math.floor(s / 60);
  return `${m}:${String(s % 60).padStart(2, '0')}`;
}
