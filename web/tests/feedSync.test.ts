import { describe, expect, it } from 'vitest';
import {
  SKELETON_CURRENT_MS,
  SKELETON_STALE_MS,
  captureMs,
  skeletonVerdict,
} from '../src/logic/feedSync';
import { FrameBus } from '../src/logic/frameBus';

describe('skeletonVerdict', () => {
  const t = 1_767_225_600_000;

  it('waits for the first result', () => {
    expect(skeletonVerdict(t, null).state).toBe('waiting');
    expect(skeletonVerdict(null, null).state).toBe('waiting');
  });

  it('treats a landmark-only source (no pictures) as current', () => {
    expect(skeletonVerdict(null, t)).toMatchObject({ state: 'current', lagMs: null });
  });

  it('draws a skeleton a few camera frames old as current, with its lag', () => {
    const v = skeletonVerdict(t + 33, t);
    expect(v).toMatchObject({ state: 'current', lagMs: 33 });
    expect(v.label).toContain('33 ms');
    expect(skeletonVerdict(t + SKELETON_CURRENT_MS, t).state).toBe('current');
  });

  it('a result newer than the picture (its picture was skipped) is in step', () => {
    expect(skeletonVerdict(t, t + 40)).toMatchObject({ state: 'current', lagMs: 0 });
  });

  it('says when the skeleton lags, up to the freshness limit', () => {
    const v = skeletonVerdict(t + SKELETON_CURRENT_MS + 1, t);
    expect(v.state).toBe('lagging');
    expect(v.label).toMatch(/lags the picture by 101 ms/);
    expect(skeletonVerdict(t + SKELETON_STALE_MS, t).state).toBe('lagging');
  });

  it('never shows a skeleton older than the freshness limit', () => {
    const v = skeletonVerdict(t + 1250, t);
    expect(v).toMatchObject({ state: 'stale', lagMs: 1250 });
    expect(v.label).toBe('Tracking is 1.3 s behind the picture: skeleton hidden');
  });
});

describe('captureMs', () => {
  it('parses the messages’ UTC times and refuses garbage', () => {
    expect(captureMs('2026-01-01T00:00:00.040Z')).toBe(1_767_225_600_040);
    expect(captureMs('not a time')).toBeNull();
  });
});

describe('FrameBus', () => {
  it('keeps the newest result and, apart, the newest picture; clear() forgets both', () => {
    const bus = new FrameBus();
    const seen: number[] = [];
    bus.pictures.subscribe((p) => seen.push(p.frame_id));
    bus.pictures.push({
      frame_id: 7,
      capture_time: '2026-01-01T00:00:00.000Z',
      width: 4,
      height: 3,
      jpeg: 'AA==',
    });
    bus.push({
      frame_id: 5,
      capture_time: '2026-01-01T00:00:00.000Z',
      width: 640,
      height: 480,
      latency_ms: 12,
      hands: [],
    });
    expect(seen).toEqual([7]);
    expect(bus.pictures.received).toBe(1);
    expect(bus.received).toBe(1);
    expect(bus.latest?.frame_id).toBe(5);
    bus.clear();
    expect(bus.latest).toBeNull();
    expect(bus.pictures.latest).toBeNull();
  });
});
