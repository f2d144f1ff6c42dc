// The panels the flying view and the replay view share, all fed from a LiveState.
import type { AlertEntry, LiveState } from '../logic/liveState';
import { describeCommand, sortedAlerts } from '../logic/liveState';
import type { Config, MotionPayload, Mapping } from '../types';

const GESTURE_LABEL: Record<string, string> = {
  NONE: 'No gesture',
  OPEN_PALM: 'Open palm',
  FIST: 'Fist',
  THUMB_UP: 'Thumb up',
  THUMB_DOWN: 'Thumb down',
  POINT_LEFT: 'Point left',
  POINT_RIGHT: 'Point right',
  POINT_UP: 'Point up',
  VICTORY: 'Victory',
  I_LOVE_YOU: 'I love you',
};

export function gestureLabel(g: string): string {
  return GESTURE_LABEL[g] ?? g;
}

export function mappingText(m: Mapping | undefined): string {
  if (!m) return 'no command';
  return describeCommand({
    type: m.command,
    source: 'gesture',
    payload: m.payload as MotionPayload,
  });
}

export function GesturePanel({ live, config }: { live: LiveState; config: Config | null }) {
  const g = live.gesture;
  const gesture = g?.gesture ?? 'NONE';
  const mapping =
    gesture !== 'NONE'
      ? config?.profile.mappings[gesture as keyof Config['profile']['mappings']]
      : undefined;
  return (
    <section className="panel gesture-panel" aria-labelledby="gesture-h">
      <h2 id="gesture-h">Gesture</h2>
      <div className="gesture-now" data-testid="gesture" aria-live="polite">
        {gestureLabel(gesture)}
      </div>
      <dl className="kv">
        <dt>Confidence</dt>
        <dd data-testid="confidence">{g ? `${Math.round(g.confidence * 100)} %` : '—'}</dd>
        <dt>Maps to</dt>
        <dd data-testid="mapped-command">{gesture === 'NONE' ? '—' : mappingText(mapping)}</dd>
        <dt>Last command</dt>
        <dd data-testid="last-command">
          {live.lastCommand ? (
            <>
              {describeCommand(live.lastCommand.command)}{' '}
              <span className="muted">
                ({live.lastCommand.command.source}: {live.lastCommand.outcome})
              </span>
            </>
          ) : (
            '—'
          )}
        </dd>
      </dl>
    </section>
  );
}

function fmt(v: number | undefined, digits: number, unit: string): string {
  return v === undefined || !Number.isFinite(v) ? '—' : `${v.toFixed(digits)} ${unit}`;
}

export function TelemetryPanel({ live }: { live: LiveState }) {
  const t = live.telemetry;
  const stale = live.noData;
  return (
    <section className="panel telemetry" aria-labelledby="telemetry-h" data-testid="telemetry">
      <h2 id="telemetry-h">
        Telemetry{' '}
        {stale && (
          <span className="badge badge-critical" data-testid="no-data" role="status">
            No data
          </span>
        )}
        {live.idleHovering && (
          <span className="badge badge-info" data-testid="idle-hovering" role="status">
            Idle – hovering
          </span>
        )}
      </h2>
      <dl className={`kv telemetry-grid${stale ? ' stale' : ''}`}>
        <dt>Altitude</dt>
        <dd data-testid="altitude">{fmt(t?.altitude_m, 2, 'm')}</dd>
        <dt>Speed</dt>
        <dd data-testid="speed">{fmt(t?.speed_m_s, 2, 'm/s')}</dd>
        <dt>Heading</dt>
        <dd data-testid="heading">{fmt(t?.heading_deg, 0, '°')}</dd>
        <dt>Battery</dt>
        <dd data-testid="battery" className={t && t.battery_pct < 30 ? 'warn' : undefined}>
          {fmt(t?.battery_pct, 0, '%')}
        </dd>
        <dt>Flight state</dt>
        <dd data-testid="flight-state" className={`state-${t?.flight_state ?? 'none'}`}>
          {t?.flight_state ?? '—'}
        </dd>
        <dt>Link</dt>
        <dd data-testid="link" className={`link-${t?.link ?? 'none'}`}>
          {stale ? 'No data' : (t?.link ?? '—')}
        </dd>
      </dl>
    </section>
  );
}

interface AlertProps {
  alerts: readonly AlertEntry[];
  onAck?: (a: AlertEntry) => void;
  onDismiss?: (a: AlertEntry) => void;
}

export function AlertBanners({ alerts, onAck, onDismiss }: AlertProps) {
  if (!alerts.length) return null;
  return (
    <section className="alerts" aria-label="Alerts">
      {sortedAlerts(alerts).map((a) => (
        <div
          key={a.key}
          className={`alert alert-${a.alert.severity.toLowerCase()}`}
          role={a.alert.severity === 'INFO' ? 'status' : 'alert'}
          data-testid="alert"
          data-code={a.alert.code}
          data-alert-id={a.alert.id}
        >
          <div className="alert-text">
            <strong>
              {a.alert.severity} · {a.alert.code}
              {a.count && a.count > 1 ? ` (×${a.count})` : ''}
            </strong>
            <span className="cause">{a.alert.cause}</span>
            <span className="suggestion">
              <span className="label">What to do: </span>
              {a.alert.suggestion}
            </span>
          </div>
          <div className="alert-actions">
            {onAck && a.alert.id !== undefined && (
              <button type="button" onClick={() => onAck(a)} disabled={a.acking}>
                {a.acking ? 'Acknowledging…' : 'Acknowledge'}
              </button>
            )}
            {onDismiss && (a.alert.id === undefined || a.alert.severity === 'INFO') && (
              <button
                type="button"
                onClick={() => onDismiss(a)}
                aria-label={`Clear ${a.alert.code}`}
              >
                Clear
              </button>
            )}
          </div>
        </div>
      ))}
    </section>
  );
}

export function CommandLog({ live }: { live: LiveState }) {
  return (
    <section className="panel command-log" aria-labelledby="cmdlog-h" data-testid="command-log">
      <h2 id="cmdlog-h">Commands</h2>
      {live.commands.length === 0 ? (
        <p className="muted">No commands yet.</p>
      ) : (
        <ol>
          {live.commands.slice(0, 12).map((c, i) => (
            <li key={`${c.command.id ?? 'x'}-${i}`}>
              <span className={`cmd cmd-${c.command.type.toLowerCase()}`}>
                {describeCommand(c.command)}
              </span>{' '}
              <span className="muted">
                {c.command.source} · {c.outcome}
              </span>
            </li>
          ))}
        </ol>
      )}
    </section>
  );
}
