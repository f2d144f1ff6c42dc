import { describe, expect, it } from 'vitest';
import { advance, buildTimeline, durationMs, newPlayer, seek, stateAt } from '../src/logic/replay';
import type { SessionDetail } from '../src/types';
import { frame } from './fixtures';

const T = (s: number) => new Date(Date.UTC(2026, 10, 23, 10, 0, s)).toISOString();

const detail: SessionDetail = {
  session: {
    id: 1,
    user_id: 1,
    drone: 'twin',
    profile: 'default',
    started_at: T(0),
    ended_at: T(10),
    open: false,
    duration_s: 10,
    command_count: 1,
    alert_count: 1,
  },
  gestures: [
    {
      gesture: 'THUMB_UP',
      confidence: 0.9,
      handedness: 'Right',
      frame_id: 3,
      timestamp: T(1),
      repeat: false,
    },
  ],
  commands: [
    { command: { type: 'TAKEOFF', source: 'gesture', id: 1 }, outcome: 'OK', recorded_at: T(1) },
  ],
  alerts: [
    {
      alert: {
        id: 5,
        severity: 'CRITICAL',
        code: 'LINK_LOSS',
        cause: 'c',
        suggestion: 's',
        timestamp: T(4),
      },
      acknowledged_at: T(6),
    },
  ],
};
const frames = [0, 2, 3, 4, 8].map((s) =>
  frame({ timestamp: T(s), flight_state: s >= 2 ? 'FLYING' : 'READY', altitude_m: s / 2, x_m: s }),
);

describe('replay', () => {
  const tl = buildTimeline(detail, frames);

  it('orders every stored event on one timeline spanning the session', () => {
    expect(durationMs(tl)).toBe(10_000);
    expect(tl.events.map((e) => e.msg.type)).toEqual([
      'telemetry',
      'gesture',
      'command',
      'telemetry',
      'telemetry',
      'telemetry',
      'alert',
      'ack_result',
      'telemetry',
    ]);
    expect(tl.events.every((e) => e.msg.replay === true)).toBe(true);
  });

  it('rebuilds the panels at any position', () => {
    const at5 = stateAt(tl, 5000).state;
    expect(at5.gesture?.gesture).toBe('THUMB_UP');
    expect(at5.telemetry?.altitude_m).toBe(2);
    expect(at5.alerts.map((a) => a.alert.code)).toEqual(['LINK_LOSS']);
    expect(at5.path.map((p) => p.x_m)).toEqual([2, 3, 4]);
    expect(stateAt(tl, 7000).state.alerts).toEqual([]); // acknowledged at 6 s
  });

  it('shows "No data" in a gap of the recording', () => {
    expect(stateAt(tl, 4500).state.noData).toBe(false);
    expect(stateAt(tl, 7000).state.noData).toBe(true);
  });

  it('plays at the chosen speed, pauses at the end, and seeks both ways', () => {
    let p = { ...newPlayer(tl), playing: true, speed: 4 };
    p = advance(p, tl, 1000);
    expect(p.positionMs).toBe(4000);
    expect(p.state.telemetry?.x_m).toBe(4);
    p = advance(p, tl, 10_000);
    expect(p.positionMs).toBe(10_000);
    expect(p.playing).toBe(false);
    p = seek(p, tl, 2500);
    expect(p.state.telemetry?.x_m).toBe(2);
    expect(p.state.alerts).toEqual([]);
    p = seek(p, tl, 4000);
    expect(p.state.alerts).toHaveLength(1);
    expect(advance({ ...p, playing: false }, tl, 1000).positionMs).toBe(4000);
  });

  it('copes with an empty session', () => {
    const empty = buildTimeline({ ...detail, gestures: [], commands: [], alerts: [] }, []);
    expect(empty.events).toEqual([]);
    expect(durationMs(empty)).toBe(10_000);
  });
});
