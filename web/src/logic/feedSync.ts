// The live feed's two streams and how they fit together: pictures arrive at the camera's rate
// (`picture` messages), the skeleton from the newest vision result (`frame` messages), which
// may be slower. The skeleton is drawn over the newest picture only while it is close enough
// in capture time to be honest about where the hand is:
//   current  lag <= SKELETON_CURRENT_MS (a few camera frames): drawn as is
//   lagging  lag <= SKELETON_STALE_MS: drawn dashed, and the page says by how much it lags
//   stale    older: not drawn; the page says tracking is behind (never a stale skeleton as current)
// SKELETON_STALE_MS is the server's vision_stale_s: with no result for that long vision counts
// as unhealthy and the failsafe hovers.

export const SKELETON_CURRENT_MS = 100;
export const SKELETON_STALE_MS = 500;
/** Without a picture for this long the feed is a landmark-only source (skeleton on black). */
export const PICTURE_TIMEOUT_MS = 2000;

export type SkeletonState = 'current' | 'lagging' | 'stale' | 'waiting';

export interface SkeletonVerdict {
  state: SkeletonState;
  /** capture time of the picture minus that of the result, ms (>= 0); null without both */
  lagMs: number | null;
  /** what the page says about it */
  label: string;
}

/** ms since the epoch of an ISO 8601 UTC time, or null when it does not parse. */
export function captureMs(iso: string): number | null {
  const t = Date.parse(iso);
  return Number.isFinite(t) ? t : null;
}

/**
 * How to show the newest result's skeleton over the newest picture. `pictureMs` null: there
 * is no picture (a landmark-only source), the result is the frame itself and is current.
 */
export function skeletonVerdict(
  pictureMs: number | null,
  resultMs: number | null,
): SkeletonVerdict {
  if (resultMs === null) {
    return { state: 'waiting', lagMs: null, label: 'Tracking: waiting for the first result' };
  }
  if (pictureMs === null) return { state: 'current', lagMs: null, label: 'Skeleton from tracking' };
  const lag = Math.max(0, Math.round(pictureMs - resultMs));
  if (lag <= SKELETON_CURRENT_MS) {
    return { state: 'current', lagMs: lag, label: `Skeleton ${lag} ms behind the picture` };
  }
  if (lag <= SKELETON_STALE_MS) {
    return {
      state: 'lagging',
      lagMs: lag,
      label: `Skeleton lags the picture by ${lag} ms (tracking is slower than the camera)`,
    };
  }
  return {
    state: 'stale',
    lagMs: lag,
    label: `Tracking is ${(lag / 1000).toFixed(1)} s behind the picture: skeleton hidden`,
  };
}
