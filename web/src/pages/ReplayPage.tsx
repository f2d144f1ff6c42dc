// Replay of a stored session with the flying view's panels: play, pause, speed and a timeline
// scrubber (keyboard: Space/K play-pause; on the scrubber, arrows seek 1 s, Home/End).
import { useEffect, useRef, useState } from 'react';
import { Api, ApiFailure } from '../api/http';
import { ErrorBox } from '../components/ErrorBox';
import { AlertBanners, CommandLog, GesturePanel, TelemetryPanel } from '../components/Panels';
import { PathMap } from '../components/PathMap';
import {
  SPEEDS,
  advance,
  buildTimeline,
  durationMs,
  formatClock,
  newPlayer,
  seek,
  type Player,
  type Timeline,
} from '../logic/replay';
import type { Config, SessionDetail } from '../types';

export function ReplayPage({
  api,
  sessionId,
  config,
}: {
  api: Api;
  sessionId: number;
  config: Config | null;
}) {
  const [detail, setDetail] = useState<SessionDetail | null>(null);
  const [tl, setTl] = useState<Timeline | null>(null);
  const [player, setPlayer] = useState<Player | null>(null);
  const [failure, setFailure] = useState<ApiFailure | null>(null);
  const [serverNote, setServerNote] = useState<string | null>(null);
  const last = useRef<number | null>(null);

  useEffect(() => {
    let live = true;
    Promise.all([api.session(sessionId), api.telemetry(sessionId)])
      .then(([d, t]) => {
        if (!live) return;
        const timeline = buildTimeline(d, t.frames);
        setDetail(d);
        setTl(timeline);
        setPlayer(newPlayer(timeline));
      })
      .catch((e: unknown) => live && e instanceof ApiFailure && setFailure(e));
    return () => {
      live = false;
    };
  }, [api, sessionId]);

  const playing = player?.playing ?? false;
  useEffect(() => {
    if (!playing || !tl) return;
    let raf = 0;
    const step = (now: number) => {
      const prev = last.current ?? now;
      last.current = now;
      setPlayer((p) => (p ? advance(p, tl, now - prev) : p));
      raf = requestAnimationFrame(step);
    };
    raf = requestAnimationFrame(step);
    return () => {
      cancelAnimationFrame(raf);
      last.current = null;
    };
  }, [playing, tl]);

  if (failure) return <ErrorBox failure={failure} title={`Could not load session ${sessionId}`} />;
  if (!detail || !tl || !player) return <p className="muted">Loading session {sessionId}…</p>;

  const total = durationMs(tl);
  const toggle = () =>
    setPlayer((p) => {
      if (!p) return p;
      const atEnd = p.positionMs >= total;
      const base = atEnd ? seek(p, tl, 0) : p;
      return { ...base, playing: !p.playing || atEnd };
    });
  const seekTo = (ms: number) => setPlayer((p) => (p ? seek(p, tl, ms) : p));

  const onKey = (e: React.KeyboardEvent) => {
    if (
      (e.target as HTMLElement).tagName === 'INPUT' ||
      (e.target as HTMLElement).tagName === 'SELECT'
    )
      return;
    if (e.key === ' ' || e.key === 'k') {
      e.preventDefault();
      toggle();
    }
  };

  const streamOnServer = async () => {
    try {
      const r = await api.replayOnServer(sessionId, player.speed >= 1 ? player.speed : 1);
      setServerNote(
        `The server is streaming session ${r.session_id} to every live screen (${r.messages} messages, ${r.duration_s.toFixed(0)} s).`,
      );
    } catch (e) {
      if (e instanceof ApiFailure) setFailure(e);
    }
  };

  const s = detail.session;
  return (
    // eslint-disable-next-line jsx-a11y/no-static-element-interactions
    <div className="page replay" onKeyDown={onKey}>
      <h1>
        Replay of session {s.id}{' '}
        <span className="muted">
          {s.drone} · {new Date(s.started_at).toLocaleString()}
        </span>
      </h1>
      <div className="player panel" role="group" aria-label="Replay controls">
        <button
          type="button"
          onClick={toggle}
          data-testid="replay-play"
          aria-keyshortcuts="Space K"
        >
          {player.playing ? 'Pause' : 'Play'}
        </button>
        <label>
          Speed{' '}
          <select
            value={player.speed}
            onChange={(e) => setPlayer((p) => (p ? { ...p, speed: Number(e.target.value) } : p))}
            data-testid="replay-speed"
          >
            {SPEEDS.map((v) => (
              <option key={v} value={v}>
                {v}×
              </option>
            ))}
          </select>
        </label>
        <input
          type="range"
          className="scrubber"
          min={0}
          max={Math.max(1, total)}
          step={1000}
          value={player.positionMs}
          onChange={(e) => seekTo(Number(e.target.value))}
          aria-label="Position in the session"
          aria-valuetext={`${formatClock(player.positionMs)} of ${formatClock(total)}`}
          data-testid="replay-scrubber"
        />
        <span data-testid="replay-clock">
          {formatClock(player.positionMs)} / {formatClock(total)}
        </span>
        <button type="button" onClick={() => void streamOnServer()}>
          Stream to live screens
        </button>
      </div>
      {serverNote && <p role="status">{serverNote}</p>}
      <p className="muted">
        {tl.events.length} recorded events · {detail.gestures.length} gestures ·{' '}
        {detail.commands.length} commands · {detail.alerts.length} alerts
      </p>
      <AlertBanners alerts={player.state.alerts} />
      <div className="replay-grid">
        <GesturePanel live={player.state} config={config} />
        <TelemetryPanel live={player.state} />
        <PathMap path={player.state.path} />
        <CommandLog live={player.state} />
      </div>
    </div>
  );
}
