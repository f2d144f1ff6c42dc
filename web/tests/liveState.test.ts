import { describe, expect, it } from 'vitest';
import {
  NO_DATA_AFTER_MS,
  describeCommand,
  initialLiveState,
  liveReducer,
  sortedAlerts,
  type LiveAction,
  type LiveState,
} from '../src/logic/liveState';
import { al, alert, frame, tel } from './fixtures';

const run = (actions: LiveAction[], s: LiveState = initialLiveState) =>
  actions.reduce(liveReducer, s);

describe('liveReducer', () => {
  it('shows telemetry and "No data" once it stops for longer than the limit', () => {
    let s = run([{ kind: 'message', message: tel(frame({ altitude_m: 1.5 })), nowMs: 1000 }]);
    expect(s.telemetry?.altitude_m).toBe(1.5);
    expect(s.noData).toBe(false);
    s = liveReducer(s, { kind: 'tick', nowMs: 1000 + NO_DATA_AFTER_MS });
    expect(s.noData).toBe(false);
    s = liveReducer(s, { kind: 'tick', nowMs: 1001 + NO_DATA_AFTER_MS });
    expect(s.noData).toBe(true);
    s = liveReducer(s, { kind: 'message', message: tel(frame()), nowMs: 5000 });
    expect(s.noData).toBe(false);
  });

  it('starts with No data before any telemetry', () => {
    expect(liveReducer(initialLiveState, { kind: 'tick', nowMs: 0 }).noData).toBe(true);
  });

  it('keeps an alert until it is acknowledged (ack_result) and never drops it on its own', () => {
    let s = run([{ kind: 'message', message: al(alert({ id: 7 })), nowMs: 0 }]);
    s = run([{ kind: 'tick', nowMs: 600000 }], s);
    expect(s.alerts.map((a) => a.key)).toEqual(['7']);
    s = liveReducer(s, { kind: 'acking', key: '7' });
    expect(s.alerts[0]?.acking).toBe(true);
    s = liveReducer(s, {
      kind: 'message',
      message: { type: 'ack_result', ts: 'x', data: { alert_id: 7, acknowledged_at: 'x' } },
      nowMs: 1,
    });
    expect(s.alerts).toEqual([]);
  });

  it('clears LINK_LOSS when LINK_RESTORED arrives, and shows the restore', () => {
    const s = run([
      { kind: 'message', message: al(alert({ id: 1, code: 'LINK_LOSS' })), nowMs: 0 },
      {
        kind: 'message',
        message: al(alert({ id: 2, code: 'BATTERY_LOW', severity: 'WARNING' })),
        nowMs: 1,
      },
      {
        kind: 'message',
        message: al(alert({ id: 3, code: 'LINK_RESTORED', severity: 'INFO' })),
        nowMs: 2,
      },
    ]);
    expect(s.alerts.map((a) => a.alert.code).sort()).toEqual(['BATTERY_LOW', 'LINK_RESTORED']);
  });

  it('does not duplicate an alert delivered twice', () => {
    const s = run([
      { kind: 'message', message: al(alert({ id: 4 })), nowMs: 0 },
      { kind: 'message', message: al(alert({ id: 4 })), nowMs: 1 },
    ]);
    expect(s.alerts).toHaveLength(1);
  });

  it('keeps one banner per INFO code (newest, counted) but every warning and critical alert', () => {
    const info = (id: number) => ({
      kind: 'message' as const,
      message: al(alert({ id, severity: 'INFO', code: 'VISION_RESTORED' })),
      nowMs: id,
    });
    const s = run([
      info(1),
      info(2),
      {
        kind: 'message',
        message: al(alert({ id: 3, severity: 'WARNING', code: 'BATTERY_LOW' })),
        nowMs: 3,
      },
      {
        kind: 'message',
        message: al(alert({ id: 4, severity: 'WARNING', code: 'BATTERY_LOW' })),
        nowMs: 4,
      },
      info(5),
    ]);
    const restored = s.alerts.filter((a) => a.alert.code === 'VISION_RESTORED');
    expect(restored.map((a) => [a.key, a.count])).toEqual([['5', 3]]);
    expect(s.alerts.filter((a) => a.alert.code === 'BATTERY_LOW')).toHaveLength(2);
  });

  it('orders alerts critical first, then newest', () => {
    const s = run([
      {
        kind: 'message',
        message: al(alert({ id: 1, severity: 'INFO', code: 'IDLE_HOVER' })),
        nowMs: 0,
      },
      { kind: 'message', message: al(alert({ id: 2, severity: 'CRITICAL' })), nowMs: 1 },
      {
        kind: 'message',
        message: al(alert({ id: 3, severity: 'WARNING', code: 'BATTERY_LOW' })),
        nowMs: 2,
      },
    ]);
    expect(sortedAlerts(s.alerts).map((a) => a.key)).toEqual(['2', '3', '1']);
  });

  it('shows "Idle – hovering" from IDLE_HOVER until the operator acts again', () => {
    let s = run([
      { kind: 'message', message: tel(frame({ flight_state: 'FLYING' })), nowMs: 0 },
      {
        kind: 'message',
        message: al(alert({ id: 9, code: 'IDLE_HOVER', severity: 'INFO' })),
        nowMs: 1,
      },
    ]);
    expect(s.idleHovering).toBe(true);
    s = liveReducer(s, {
      kind: 'message',
      message: {
        type: 'command',
        ts: 'x',
        data: { command: { type: 'HOVER', source: 'failsafe' }, outcome: 'OK' },
      },
      nowMs: 2,
    });
    expect(s.idleHovering).toBe(true);
    s = liveReducer(s, {
      kind: 'message',
      message: {
        type: 'command',
        ts: 'x',
        data: {
          command: { type: 'MOVE', source: 'gesture', payload: { vx_m_s: 0.4 } },
          outcome: 'OK',
        },
      },
      nowMs: 3,
    });
    expect(s.idleHovering).toBe(false);
  });

  it('starts a new path at take-off and keeps the last flight after landing', () => {
    let s = run([
      {
        kind: 'message',
        message: tel(frame({ flight_state: 'FLYING', x_m: 5, y_m: 5 })),
        nowMs: 0,
      },
      {
        kind: 'message',
        message: tel(frame({ flight_state: 'FLYING', x_m: 6, y_m: 5 })),
        nowMs: 1,
      },
      { kind: 'message', message: tel(frame({ flight_state: 'READY', x_m: 6, y_m: 5 })), nowMs: 2 },
    ]);
    expect(s.path.map((p) => p.x_m)).toEqual([5, 6]);
    s = run(
      [{ kind: 'message', message: tel(frame({ flight_state: 'READY', x_m: 9 })), nowMs: 3 }],
      s,
    );
    expect(s.path).toHaveLength(2);
    s = run(
      [
        {
          kind: 'message',
          message: tel(frame({ flight_state: 'FLYING', x_m: 0, y_m: 0 })),
          nowMs: 4,
        },
      ],
      s,
    );
    expect(s.path.map((p) => p.x_m)).toEqual([0]);
  });

  it('keeps the last 50 commands, newest first', () => {
    const actions: LiveAction[] = Array.from({ length: 60 }, (_, i) => ({
      kind: 'message',
      message: {
        type: 'command',
        ts: 'x',
        data: { command: { type: 'HOVER', source: 'keyboard', id: i }, outcome: 'OK' },
      },
      nowMs: i,
    }));
    const s = run(actions);
    expect(s.commands).toHaveLength(50);
    expect(s.commands[0]?.command.id).toBe(59);
    expect(s.lastCommand?.command.id).toBe(59);
  });

  it('marks replayed messages and does not let a replay overwrite the live server state', () => {
    const live = {
      adapter: 'twin',
      connected: true,
      session_id: 3,
      flight_state: 'READY' as const,
      emergency_latched: false,
      clients: 1,
      vision: {
        ready: true,
        healthy: true,
        reason: '',
        fps: 30,
        worker_running: true,
        worker_restarts: 0,
      },
    };
    let s = run([{ kind: 'message', message: { type: 'state', ts: 'x', data: live }, nowMs: 0 }]);
    s = liveReducer(s, {
      kind: 'message',
      message: {
        type: 'state',
        ts: 'x',
        replay: true,
        data: {
          ...live,
          session_id: 1,
          replay: { replay_id: '01JD3Z8Q4K7J9ZK3M2V6X1N0AB', session_id: 1, finished: true },
        },
      },
      nowMs: 1,
    });
    expect(s.replay).toBe(true);
    expect(s.replayFinished).toBe(true);
    expect(s.server?.session_id).toBe(3);
  });
});

describe('describeCommand', () => {
  it('says where a MOVE goes in words', () => {
    expect(
      describeCommand({
        type: 'MOVE',
        source: 'gesture',
        payload: { vy_m_s: -0.4, duration_s: 1 },
      }),
    ).toBe('MOVE left 0.4 m/s');
    expect(
      describeCommand({ type: 'MOVE', source: 'gesture', payload: { yaw_rate_deg_s: 45 } }),
    ).toBe('MOVE yaw right 45°/s');
    expect(describeCommand({ type: 'TAKEOFF', source: 'gesture' })).toBe('TAKEOFF');
    expect(describeCommand(null)).toBe('—');
  });
});
