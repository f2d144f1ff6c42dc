import type { Alert, TelemetryFrame, WsServerMessage } from '../src/types';

export function frame(over: Partial<TelemetryFrame> = {}): TelemetryFrame {
  return {
    timestamp: '2026-11-23T10:00:00.000Z',
    altitude_m: 0,
    speed_m_s: 0,
    vx_m_s: 0,
    vy_m_s: 0,
    vz_m_s: 0,
    x_m: 0,
    y_m: 0,
    heading_deg: 0,
    battery_pct: 90,
    flight_state: 'READY',
    link: 'OK',
    ...over,
  };
}

export function alert(over: Partial<Alert> = {}): Alert {
  return {
    severity: 'CRITICAL',
    code: 'LINK_LOSS',
    cause: 'no telemetry for 2.1 s',
    suggestion: 'move closer',
    timestamp: '2026-11-23T10:00:01.000Z',
    id: 7,
    ...over,
  };
}

export const tel = (f: TelemetryFrame, replay = false): WsServerMessage => ({
  type: 'telemetry',
  ts: f.timestamp,
  data: f,
  ...(replay ? { replay } : {}),
});
export const al = (a: Alert): WsServerMessage => ({ type: 'alert', ts: a.timestamp, data: a });
