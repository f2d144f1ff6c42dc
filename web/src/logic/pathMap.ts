// Path-map maths: the x/y trajectory since take-off fitted into a view box with equal scale on
// both axes (a metre is a metre), the heading marker, and the altitude strip.
// World frame: x_m forward (north at heading 0), y_m right (east); heading_deg clockwise from
// +x. Screen: up = +x, right = +y, so a heading of 0 points up and 90 points right.
import type { TelemetryFrame } from '../types';

export interface PathPoint {
  x_m: number;
  y_m: number;
  altitude_m: number;
  heading_deg: number;
  t: string;
}

/** Keep the last this many points (at 20 Hz: over 8 minutes). */
export const MAX_PATH_POINTS = 10000;
/** A new point only when the drone moved this far or turned (less clutter, same shape). */
export const MIN_STEP_M = 0.02;

export function appendPathPoint(path: readonly PathPoint[], t: TelemetryFrame): PathPoint[] {
  const p: PathPoint = {
    x_m: t.x_m,
    y_m: t.y_m,
    altitude_m: t.altitude_m,
    heading_deg: t.heading_deg,
    t: t.timestamp,
  };
  const last = path[path.length - 1];
  if (
    last &&
    Math.hypot(p.x_m - last.x_m, p.y_m - last.y_m) < MIN_STEP_M &&
    Math.abs(p.altitude_m - last.altitude_m) < MIN_STEP_M &&
    Math.abs(p.heading_deg - last.heading_deg) < 1
  ) {
    // Same place: update the last point so the marker still shows the latest heading.
    return [...path.slice(0, -1), p];
  }
  const next = [...path, p];
  return next.length > MAX_PATH_POINTS ? next.slice(next.length - MAX_PATH_POINTS) : next;
}

export interface View {
  width: number;
  height: number;
  padding: number;
}

export interface Projection {
  /** metres -> pixels */
  scale: number;
  toScreen(x_m: number, y_m: number): [number, number];
  /** metres covered by the view's shorter side, for the scale bar */
  spanM: number;
}

/** Fits all points (and the origin) in the view, equal scale on both axes, at least minSpanM wide. */
export function fitProjection(points: readonly PathPoint[], view: View, minSpanM = 4): Projection {
  let minX = 0;
  let maxX = 0;
  let minY = 0;
  let maxY = 0;
  for (const p of points) {
    minX = Math.min(minX, p.x_m);
    maxX = Math.max(maxX, p.x_m);
    minY = Math.min(minY, p.y_m);
    maxY = Math.max(maxY, p.y_m);
  }
  const spanX = Math.max(maxX - minX, minSpanM);
  const spanY = Math.max(maxY - minY, minSpanM);
  const w = view.width - 2 * view.padding;
  const h = view.height - 2 * view.padding;
  // screen horizontal = y (east), screen vertical = x (north, up)
  const scale = Math.min(w / spanY, h / spanX);
  const cx = (minX + maxX) / 2;
  const cy = (minY + maxY) / 2;
  return {
    scale,
    spanM: Math.min(w, h) / scale,
    toScreen(x_m, y_m) {
      return [view.width / 2 + (y_m - cy) * scale, view.height / 2 - (x_m - cx) * scale];
    },
  };
}

/** Triangle (3 screen points) at (sx, sy) pointing along heading_deg (0 = up, clockwise). */
export function headingMarker(
  sx: number,
  sy: number,
  heading_deg: number,
  size = 10,
): [number, number][] {
  const a = (heading_deg * Math.PI) / 180;
  const fwd: [number, number] = [Math.sin(a), -Math.cos(a)];
  const right: [number, number] = [Math.cos(a), Math.sin(a)];
  return [
    [sx + fwd[0] * size, sy + fwd[1] * size],
    [
      sx - fwd[0] * size * 0.6 + right[0] * size * 0.6,
      sy - fwd[1] * size * 0.6 + right[1] * size * 0.6,
    ],
    [
      sx - fwd[0] * size * 0.6 - right[0] * size * 0.6,
      sy - fwd[1] * size * 0.6 - right[1] * size * 0.6,
    ],
  ];
}

/** The altitude strip: altitude over sample index mapped to a view (0 m at the bottom). */
export function altitudeStrip(
  points: readonly PathPoint[],
  view: View,
  minTopM = 2,
): {
  polyline: [number, number][];
  topM: number;
} {
  const topM = Math.max(minTopM, ...points.map((p) => p.altitude_m));
  const w = view.width - 2 * view.padding;
  const h = view.height - 2 * view.padding;
  const n = points.length;
  const polyline = points.map((p, i): [number, number] => [
    view.padding + (n > 1 ? (i / (n - 1)) * w : w),
    view.padding + h - (Math.max(0, p.altitude_m) / topM) * h,
  ]);
  return { polyline, topM };
}

/** A round number of metres for the scale bar (1, 2, 5, 10, ...), at most maxM. */
export function niceMetres(maxM: number): number {
  if (!(maxM > 0)) return 1;
  const p = Math.pow(10, Math.floor(Math.log10(maxM)));
  for (const m of [5, 2, 1]) if (m * p <= maxM) return m * p;
  return p;
}
