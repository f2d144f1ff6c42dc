// The live camera feed: the latest JPEG from the FrameBus drawn on a canvas on each animation
// frame, with the 21-point skeleton of every hand over it. Decoding happens off the React
// render path; a frame that arrives while the previous one decodes replaces it (latest wins).
import { useEffect, useRef, useState } from 'react';
import type { FrameBus } from '../logic/frameBus';
import { FpsMeter } from '../logic/fps';
import { HAND_CONNECTIONS, containFit, projectLandmarks } from '../logic/skeleton';
import type { WsFrameData } from '../types';

export interface FeedStats {
  drawn: number;
  fps: number;
}

function cssVar(name: string, fallback: string): string {
  return getComputedStyle(document.documentElement).getPropertyValue(name).trim() || fallback;
}

export function Feed({ frames }: { frames: FrameBus }) {
  const canvasRef = useRef<HTMLCanvasElement | null>(null);
  const [fps, setFps] = useState(0);
  const [hasFrame, setHasFrame] = useState(frames.latest !== null);

  useEffect(() => {
    const canvas = canvasRef.current;
    const ctx = canvas?.getContext('2d');
    if (!canvas || !ctx) return;
    const meter = new FpsMeter(2000);
    const stats: FeedStats = { drawn: 0, fps: 0 };
    (window as unknown as { __gbdcsFeed?: FeedStats }).__gbdcsFeed = stats;
    let pending: WsFrameData | null = null;
    let decoding = false;
    let image: HTMLImageElement | ImageBitmap | null = null;
    let drawnFrame: WsFrameData | null = null;
    let dirty = false;
    let raf = 0;
    let alive = true;

    const decode = (f: WsFrameData) => {
      if (!f.jpeg) {
        image = null;
        drawnFrame = f;
        dirty = true;
        return;
      }
      decoding = true;
      const img = new Image();
      img.onload = () => {
        decoding = false;
        if (!alive) return;
        image = img;
        drawnFrame = f;
        dirty = true;
        if (pending) {
          const p = pending;
          pending = null;
          decode(p);
        }
      };
      img.onerror = () => {
        decoding = false;
      };
      img.src = `data:image/jpeg;base64,${f.jpeg}`;
    };

    const unsubscribe = frames.subscribe((f) => {
      if (decoding) pending = f;
      else decode(f);
    });
    if (frames.latest) decode(frames.latest);

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
      if (!dirty || !drawnFrame) return;
      dirty = false;
      const f = drawnFrame;
      ctx.fillStyle = '#000';
      ctx.fillRect(0, 0, w, h);
      const fit = containFit(f.width, f.height, w, h);
      if (image) ctx.drawImage(image, fit.x, fit.y, fit.width, fit.height);
      ctx.lineWidth = Math.max(2, 3 * dpr);
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
      meter.frame(now);
      stats.drawn++;
      stats.fps = meter.fps(now);
    };
    raf = requestAnimationFrame(draw);
    const fpsTimer = setInterval(() => {
      setFps(meter.fps(performance.now()));
      setHasFrame(drawnFrame !== null);
    }, 500);
    return () => {
      alive = false;
      unsubscribe();
      cancelAnimationFrame(raf);
      clearInterval(fpsTimer);
    };
  }, [frames]);

  return (
    <section className="panel feed" aria-labelledby="feed-h">
      <h2 id="feed-h">
        Camera{' '}
        <span className="muted" data-testid="feed-fps">
          {fps.toFixed(0)} FPS
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
      </div>
    </section>
  );
}
