// The live camera feed: the newest picture (`picture` messages, at the camera's rate) drawn on
// a canvas on each animation frame, with the 21-point skeleton of every hand from the newest
// vision result (`frame` messages, at tracking's rate) over it, as long as that result is
// close enough in capture time (logic/feedSync.ts); the page says how far the skeleton lags
// and hides it when tracking falls too far behind. A landmark-only source (no pictures) draws
// each result's skeleton on black. Decoding happens off the React render path; a picture that
// arrives while the previous one decodes replaces it (latest wins).
import { useEffect, useRef, useState } from 'react';
import type { FrameBus } from '../logic/frameBus';
import { FpsMeter } from '../logic/fps';
import {
  PICTURE_TIMEOUT_MS,
  captureMs,
  skeletonVerdict,
  type SkeletonVerdict,
} from '../logic/feedSync';
import { HAND_CONNECTIONS, containFit, projectLandmarks } from '../logic/skeleton';
import type { WsFrameData, WsPictureData } from '../types';

export interface FeedStats {
  /** distinct pictures drawn (or results, for a landmark-only source) */
  drawn: number;
  fps: number;
  /** vision results received */
  results: number;
  skeleton: SkeletonVerdict['state'];
  skeletonLagMs: number | null;
}

function cssVar(name: string, fallback: string): string {
  return getComputedStyle(document.documentElement).getPropertyValue(name).trim() || fallback;
}

export function Feed({ frames }: { frames: FrameBus }) {
  const canvasRef = useRef<HTMLCanvasElement | null>(null);
  const [fps, setFps] = useState(0);
  const [trackFps, setTrackFps] = useState(0);
  const [verdict, setVerdict] = useState<SkeletonVerdict | null>(null);
  const [hasFrame, setHasFrame] = useState(frames.latest !== null);

  useEffect(() => {
    const canvas = canvasRef.current;
    const ctx = canvas?.getContext('2d');
    if (!canvas || !ctx) return;
    const meter = new FpsMeter(2000);
    const trackMeter = new FpsMeter(2000);
    const stats: FeedStats = {
      drawn: 0,
      fps: 0,
      results: 0,
      skeleton: 'waiting',
      skeletonLagMs: null,
    };
    (window as unknown as { __gbdcsFeed?: FeedStats }).__gbdcsFeed = stats;
    let pending: WsPictureData | null = null;
    let decoding = false;
    let image: HTMLImageElement | null = null;
    let picture: WsPictureData | null = null; // the one `image` shows
    let pictureAt = -Infinity; // performance.now() when it arrived
    let result: WsFrameData | null = frames.latest;
    let lastDrawnKey = '';
    let lastWithPicture = false;
    let dirty = true;
    let raf = 0;
    let alive = true;
    let current: SkeletonVerdict = skeletonVerdict(null, null);

    const decode = (p: WsPictureData) => {
      decoding = true;
      const img = new Image();
      img.onload = () => {
        decoding = false;
        if (!alive) return;
        image = img;
        picture = p;
        pictureAt = performance.now();
        dirty = true;
        if (pending) {
          const next = pending;
          pending = null;
          decode(next);
        }
      };
      img.onerror = () => {
        decoding = false;
      };
      img.src = `data:image/jpeg;base64,${p.jpeg}`;
    };

    const offPictures = frames.pictures.subscribe((p) => {
      if (decoding) pending = p;
      else decode(p);
    });
    const offResults = frames.subscribe((f) => {
      result = f;
      stats.results++;
      trackMeter.frame(performance.now());
      dirty = true;
    });
    if (frames.pictures.latest) decode(frames.pictures.latest);

    const drawSkeleton = (
      f: WsFrameData,
      fit: ReturnType<typeof containFit>,
      dpr: number,
      lagging: boolean,
    ) => {
      ctx.lineWidth = Math.max(2, 3 * dpr);
      ctx.setLineDash(lagging ? [6 * dpr, 5 * dpr] : []);
      ctx.globalAlpha = lagging ? 0.7 : 1;
      for (const hand of f.hands) {
        const pts = projectLandmarks(hand.landmarks, fit);
        if (!pts) continue;
        ctx.strokeStyle = cssVar('--skeleton', '#22d3ee');
        ctx.beginPath();
        for (const [a, b] of HAND_CONNECTIONS) {
          const pa = pts[a];
          const pb = pts[b];
          if (!pa || !pb) continue;
          ctx.moveTo(pa[0], pa[1]);
          ctx.lineTo(pb[0], pb[1]);
        }
        ctx.stroke();
        ctx.fillStyle = cssVar('--joint', '#f97316');
        for (const [x, y] of pts) {
          ctx.beginPath();
          ctx.arc(x, y, 3.5 * dpr, 0, Math.PI * 2);
          ctx.fill();
        }
      }
      ctx.setLineDash([]);
      ctx.globalAlpha = 1;
    };

    const draw = () => {
      raf = requestAnimationFrame(draw);
      const now = performance.now();
      const rect = canvas.getBoundingClientRect();
      const dpr = window.devicePixelRatio || 1;
      const w = Math.max(1, Math.round(rect.width * dpr));
      const h = Math.max(1, Math.round(rect.height * dpr));
      if (canvas.width !== w || canvas.height !== h) {
        canvas.width = w;
        canvas.height = h;
        dirty = true;
      }
      // Pictures stop (a landmark-only source, or the worker is gone): the skeleton on black.
      const withPicture =
        image !== null && picture !== null && now - pictureAt < PICTURE_TIMEOUT_MS;
      if (withPicture !== lastWithPicture) {
        lastWithPicture = withPicture;
        dirty = true;
      }
      if (!dirty) return;
      dirty = false;
      const base = withPicture ? picture : result;
      if (!base) return;
      current = skeletonVerdict(
        withPicture && picture ? captureMs(picture.capture_time) : null,
        result ? captureMs(result.capture_time) : null,
      );
      ctx.fillStyle = '#000';
      ctx.fillRect(0, 0, w, h);
      const fit = containFit(base.width, base.height, w, h);
      if (withPicture && image) ctx.drawImage(image, fit.x, fit.y, fit.width, fit.height);
      if (result && (current.state === 'current' || current.state === 'lagging')) {
        drawSkeleton(result, fit, dpr, current.state === 'lagging');
      }
      stats.skeleton = current.state;
      stats.skeletonLagMs = current.lagMs;
      const key =
        withPicture && picture
          ? `p${picture.capture_time}#${picture.frame_id}`
          : `r${result?.capture_time}#${result?.frame_id}`;
      if (key !== lastDrawnKey) {
        lastDrawnKey = key;
        meter.frame(now);
        stats.drawn++;
        stats.fps = meter.fps(now);
      }
    };
    raf = requestAnimationFrame(draw);
    const fpsTimer = setInterval(() => {
      const now = performance.now();
      setFps(meter.fps(now));
      setTrackFps(trackMeter.fps(now));
      setVerdict(current);
      setHasFrame(lastDrawnKey !== '');
    }, 500);
    return () => {
      alive = false;
      offPictures();
      offResults();
      cancelAnimationFrame(raf);
      clearInterval(fpsTimer);
    };
  }, [frames]);

  const warn = verdict?.state === 'lagging' || verdict?.state === 'stale';
  return (
    <section className="panel feed" aria-labelledby="feed-h">
      <h2 id="feed-h">
        Camera{' '}
        <span className="muted" data-testid="feed-fps">
          {fps.toFixed(0)} FPS
        </span>{' '}
        <span className="muted" data-testid="tracking-fps">
          · tracking {trackFps.toFixed(0)} FPS
        </span>
      </h2>
      <div className="feed-box">
        <canvas
          ref={canvasRef}
          data-testid="feed"
          role="img"
          aria-label="Live camera feed with the detected hand skeleton drawn over it"
        />
        {!hasFrame && <p className="feed-empty">Waiting for the camera…</p>}
        {hasFrame && verdict && (
          <p
            className={warn ? 'feed-skeleton warn' : 'feed-skeleton'}
            data-testid="skeleton-status"
            role="status"
          >
            {verdict.label}
          </p>
        )}
      </div>
    </section>
  );
}
