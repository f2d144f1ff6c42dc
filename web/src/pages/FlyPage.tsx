// The one view to fly from: feed, gesture, telemetry, alerts, controls, path map. Nothing here
// needs scrolling on a laptop screen; keyboard flying works while this view is shown.
import { useEffect, useMemo, useRef, useState, type Dispatch } from 'react';
import { Api, ApiFailure } from '../api/http';
import type { LinkStatus } from '../api/live';
import { AlertBanners, CommandLog, GesturePanel, TelemetryPanel } from '../components/Panels';
import { ErrorBox } from '../components/ErrorBox';
import { DroneView } from '../components/DroneView';
import { Feed } from '../components/Feed';
import { PathMap } from '../components/PathMap';
import type { FrameBus, ViewBus } from '../logic/frameBus';
import { KeyTracker, type KeyOutput } from '../logic/keys';
import type { AlertEntry, LiveAction, LiveState } from '../logic/liveState';
import type { Config, WsClientMessage } from '../types';

interface Props {
  live: LiveState;
  frames: FrameBus;
  views: ViewBus;
  send: (m: WsClientMessage) => boolean;
  api: Api;
  config: Config | null;
  link: { status: LinkStatus; detail?: string };
  dispatch: Dispatch<LiveAction>;
}

export function FlyPage({ live, frames, views, send, api, config, link, dispatch }: Props) {
  const [failure, setFailure] = useState<ApiFailure | null>(null);
  const [notice, setNotice] = useState<string | null>(null);
  const keys = useMemo(() => new KeyTracker(), []);

  const emergencyStop = async () => {
    setNotice('EMERGENCY STOP sent');
    if (send({ type: 'emergency_stop', reason: 'operator: dashboard button or Space' })) return;
    try {
      await api.emergencyStop('operator: dashboard (socket down, sent over REST)');
      setNotice('EMERGENCY STOP sent (over REST: the live connection is down)');
    } catch (e) {
      setNotice('EMERGENCY STOP NOT DELIVERED: the server could not be reached.');
      if (e instanceof ApiFailure) setFailure(e);
    }
  };

  const reset = async () => {
    try {
      await api.emergencyReset();
      setNotice('Emergency stop released: commands are accepted again.');
    } catch (e) {
      if (e instanceof ApiFailure) setFailure(e);
    }
  };

  const tap = (key: string) => {
    if (!send({ type: 'input', key, pressed: true })) {
      setNotice('Not connected to the server: the command was not sent.');
      return;
    }
    send({ type: 'input', key, pressed: false });
  };

  const ack = (a: AlertEntry) => {
    const id = a.alert.id;
    if (id === undefined) return;
    dispatch({ kind: 'acking', key: a.key });
    if (!send({ type: 'ack', alert_id: id })) {
      api
        .ackAlert(id)
        .then(() => dispatch({ kind: 'dismiss', key: a.key }))
        .catch((e: unknown) => e instanceof ApiFailure && setFailure(e));
    }
  };

  const emergencyStopRef = useLatest(emergencyStop);
  useEffect(() => {
    const out = (o: KeyOutput) => {
      if (o.kind === 'input') send({ type: 'input', key: o.key, pressed: o.pressed });
    };
    const down = (e: KeyboardEvent) => {
      const o = keys.down(e);
      if (o.kind === 'none') return;
      e.preventDefault(); // Space must not also click a focused button; arrows must not scroll
      if (o.kind === 'emergency_stop') void emergencyStopRef.current();
      else out(o);
    };
    const up = (e: KeyboardEvent) => {
      const o = keys.up(e);
      if (o.kind !== 'none') {
        e.preventDefault();
        out(o);
      }
    };
    const blur = () => keys.releaseAll().forEach(out);
    window.addEventListener('keydown', down);
    window.addEventListener('keyup', up);
    window.addEventListener('blur', blur);
    return () => {
      window.removeEventListener('keydown', down);
      window.removeEventListener('keyup', up);
      window.removeEventListener('blur', blur);
      keys.releaseAll().forEach(out);
    };
  }, [keys, send, emergencyStopRef]);

  const s = live.server;
  const latched = s?.emergency_latched === true;
  const flying = live.telemetry?.flight_state === 'FLYING';
  const visionBlocked = s !== null && !s.vision.ready;

  return (
    <div className="fly">
      <AlertBanners
        alerts={live.alerts}
        onAck={ack}
        onDismiss={(a) => dispatch({ kind: 'dismiss', key: a.key })}
      />
      {live.replay && (
        <p className="banner-replay" role="status">
          Showing a replay streamed by the server{live.replayFinished ? ' (finished)' : ''}.
        </p>
      )}
      <div className="fly-grid">
        <div className="fly-main">
          <Feed frames={frames} />
          <div className="fly-under">
            <GesturePanel live={live} config={config} />
            <PathMap path={live.path} />
          </div>
        </div>
        <div className="fly-side">
          <section className="panel controls" aria-labelledby="controls-h">
            <h2 id="controls-h">Controls</h2>
            <button
              type="button"
              className="estop"
              onClick={() => void emergencyStop()}
              aria-keyshortcuts="Space"
              data-testid="estop"
            >
              EMERGENCY STOP <span className="kbd">Space</span>
            </button>
            {latched && (
              <div className="latched" role="alert">
                Emergency stop is latched: every command is refused.{' '}
                <button type="button" onClick={() => void reset()}>
                  Release emergency stop
                </button>
              </div>
            )}
            <div className="row">
              <button
                type="button"
                onClick={() => tap('t')}
                disabled={latched || flying}
                aria-keyshortcuts="T"
                data-testid="takeoff"
              >
                Take off <span className="kbd">T</span>
              </button>
              <button
                type="button"
                onClick={() => tap('l')}
                disabled={latched}
                aria-keyshortcuts="L"
              >
                Land <span className="kbd">L</span>
              </button>
              <button
                type="button"
                onClick={() => tap('h')}
                disabled={latched}
                aria-keyshortcuts="H"
              >
                Hover <span className="kbd">H</span>
              </button>
            </div>
            <p className="hint">Fly with W A S D or the arrows, Q E to turn, R F up and down.</p>
            {visionBlocked && (
              <p className="warn" role="status">
                Take-off blocked by vision: {s?.vision.reason || 'not ready'}
              </p>
            )}
            {notice && (
              <p className="muted" role="status">
                {notice}
              </p>
            )}
            {link.status !== 'open' && (
              <p className="warn" role="status">
                Server connection: {link.status}
                {link.detail ? ` (${link.detail})` : ''}
              </p>
            )}
            {live.lastError && (
              <p className="warn" role="status">
                Refused: {live.lastError.cause} {live.lastError.suggestion}
              </p>
            )}
            <ErrorBox failure={failure} />
          </section>
          <TelemetryPanel live={live} />
          <ServerState live={live} />
        </div>
        <div className="fly-bottom">
          <DroneView
            views={views}
            adapter={s?.adapter ?? null}
            available={s?.drone_view === true}
          />
          <CommandLog live={live} />
        </div>
      </div>
    </div>
  );
}

function ServerState({ live }: { live: LiveState }) {
  const s = live.server;
  return (
    <section className="panel server-state" aria-labelledby="server-h">
      <h2 id="server-h">Drone and vision</h2>
      {!s ? (
        <p className="muted">Waiting for the server…</p>
      ) : (
        <dl className="kv">
          <dt>Drone</dt>
          <dd data-testid="adapter">
            {s.adapter} {s.connected ? '(connected)' : '(not connected)'}
          </dd>
          <dt>Session</dt>
          <dd>{s.session_id ?? '—'}</dd>
          <dt>Vision</dt>
          <dd data-testid="vision">
            {s.vision.healthy ? 'healthy' : `unhealthy: ${s.vision.reason}`} ·{' '}
            {s.vision.fps.toFixed(0)} FPS
          </dd>
        </dl>
      )}
    </section>
  );
}

function useLatest<T>(v: T) {
  const r = useRef(v);
  r.current = v;
  return r;
}
