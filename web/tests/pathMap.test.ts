import { describe, expect, it } from 'vitest';
import {
  MAX_PATH_POINTS,
  altitudeStrip,
  appendPathPoint,
  fitProjection,
  headingMarker,
  niceMetres,
  type PathPoint,
} from '../src/logic/pathMap';
import { frame } from './fixtures';

const pt = (x_m: number, y_m: number, altitude_m = 1, heading_deg = 0): PathPoint => ({
  x_m,
  y_m,
  altitude_m,
  heading_deg,
  t: '',
});
const view = { width: 200, height: 100, padding: 10 };

describe('path map maths', () => {
  it('puts north (+x) up and east (+y) right, with equal scale on both axes', () => {
    const p = fitProjection([pt(0, 0), pt(10, 0), pt(0, 10)], view);
    const [ox, oy] = p.toScreen(0, 0);
    const [nx, ny] = p.toScreen(10, 0);
    const [ex, ey] = p.toScreen(0, 10);
    expect(ny).toBeLessThan(oy);
    expect(nx).toBeCloseTo(ox);
    expect(ex).toBeGreaterThan(ox);
    expect(ey).toBeCloseTo(oy);
    expect(oy - ny).toBeCloseTo(ex - ox); // a metre is a metre both ways
  });

  it('keeps every point inside the padded view', () => {
    const pts = [pt(-3, 7), pt(12, -4), pt(5, 20)];
    const p = fitProjection(pts, view);
    for (const q of pts) {
      const [x, y] = p.toScreen(q.x_m, q.y_m);
      expect(x).toBeGreaterThanOrEqual(view.padding - 1e-9);
      expect(x).toBeLessThanOrEqual(view.width - view.padding + 1e-9);
      expect(y).toBeGreaterThanOrEqual(view.padding - 1e-9);
      expect(y).toBeLessThanOrEqual(view.height - view.padding + 1e-9);
    }
  });

  it('shows at least the minimum span around a drone that has not moved', () => {
    const p = fitProjection([], view, 4);
    expect(p.scale).toBeCloseTo(80 / 4);
    expect(p.toScreen(0, 0)).toEqual([100, 50]);
  });

  it('points the heading marker along the heading (0 up, 90 right)', () => {
    const [tipUp] = headingMarker(50, 50, 0, 10);
    expect(tipUp![0]).toBeCloseTo(50);
    expect(tipUp![1]).toBeCloseTo(40);
    const [tipRight] = headingMarker(50, 50, 90, 10);
    expect(tipRight![0]).toBeCloseTo(60);
    expect(tipRight![1]).toBeCloseTo(50);
  });

  it('draws altitude with 0 m at the bottom and the highest point at the top', () => {
    const s = altitudeStrip([pt(0, 0, 0), pt(0, 0, 5)], view, 2);
    expect(s.topM).toBe(5);
    expect(s.polyline[0]![1]).toBeCloseTo(view.height - view.padding);
    expect(s.polyline[1]![1]).toBeCloseTo(view.padding);
    expect(s.polyline[1]![0]).toBeCloseTo(view.width - view.padding);
  });

  it('adds a point only when the drone moved, and caps the length', () => {
    let path = appendPathPoint([], frame({ x_m: 0 }));
    path = appendPathPoint(path, frame({ x_m: 0.001, heading_deg: 0 }));
    expect(path).toHaveLength(1);
    expect(path[0]!.x_m).toBe(0.001);
    path = appendPathPoint(path, frame({ x_m: 1 }));
    expect(path).toHaveLength(2);
    let long: PathPoint[] = [];
    for (let i = 0; i < MAX_PATH_POINTS + 5; i++) long = appendPathPoint(long, frame({ x_m: i }));
    expect(long).toHaveLength(MAX_PATH_POINTS);
    expect(long[long.length - 1]!.x_m).toBe(MAX_PATH_POINTS + 4);
  });

  it('picks round scale-bar lengths', () => {
    expect([0.7, 1, 3, 7.5, 12, 260].map(niceMetres)).toEqual([0.5, 1, 2, 5, 10, 200]);
  });
});
