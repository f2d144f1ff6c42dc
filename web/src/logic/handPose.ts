// Schematic 21-point hand poses for the help page's gesture pictures (MediaPipe landmark
// order), built from which digits are extended and where they point. A stand-in until the
// fixtures' hand renderer (sim, OSMesa) can produce pictures for the dashboard.
import type { MappableGesture } from '../types';

type Pt = [number, number];
interface Digit {
  extended: boolean;
  /** degrees from the hand's up direction, clockwise */
  angle: number;
}
interface Pose {
  thumb: Digit;
  fingers: [Digit, Digit, Digit, Digit]; // index, middle, ring, pinky
  /** whole-hand rotation, degrees clockwise (0 = fingers up) */
  rotation: number;
}

const ext = (angle: number): Digit => ({ extended: true, angle });
const fold: Digit = { extended: false, angle: 0 };

export const POSES: Record<MappableGesture, Pose> = {
  OPEN_PALM: { thumb: ext(-55), fingers: [ext(-12), ext(-2), ext(8), ext(20)], rotation: 0 },
  FIST: { thumb: fold, fingers: [fold, fold, fold, fold], rotation: 0 },
  THUMB_UP: { thumb: ext(0), fingers: [fold, fold, fold, fold], rotation: 0 },
  THUMB_DOWN: { thumb: ext(0), fingers: [fold, fold, fold, fold], rotation: 180 },
  POINT_UP: { thumb: fold, fingers: [ext(0), fold, fold, fold], rotation: 0 },
  POINT_LEFT: { thumb: fold, fingers: [ext(0), fold, fold, fold], rotation: -90 },
  POINT_RIGHT: { thumb: fold, fingers: [ext(0), fold, fold, fold], rotation: 90 },
  VICTORY: { thumb: fold, fingers: [ext(-12), ext(10), fold, fold], rotation: 0 },
  I_LOVE_YOU: { thumb: ext(-60), fingers: [ext(-5), fold, fold, ext(15)], rotation: 0 },
};

const MCP: Pt[] = [
  [-0.09, 0.34],
  [0, 0.36],
  [0.08, 0.34],
  [0.15, 0.3],
];
const LEN: [number, number, number][] = [
  [0.13, 0.08, 0.07],
  [0.14, 0.09, 0.07],
  [0.13, 0.08, 0.06],
  [0.1, 0.06, 0.05],
];

function dir(angleDeg: number): Pt {
  const a = (angleDeg * Math.PI) / 180;
  return [Math.sin(a), Math.cos(a)]; // local frame: x right, y up
}

function chain(start: Pt, angle: number, lens: readonly number[]): Pt[] {
  const d = dir(angle);
  const out: Pt[] = [];
  let p = start;
  for (const l of lens) {
    p = [p[0] + d[0] * l, p[1] + d[1] * l];
    out.push(p);
  }
  return out;
}

/** 21 points in a 0..1 image box (x right, y down). */
export function poseLandmarks(pose: Pose): Pt[] {
  const local: Pt[] = [[0, 0]];
  // thumb: CMC, MCP, IP, TIP
  const cmc: Pt = [-0.1, 0.08];
  if (pose.thumb.extended) {
    local.push(
      cmc,
      ...chain(cmc, pose.thumb.angle === 0 ? -10 : pose.thumb.angle, [0.1, 0.08, 0.07]),
    );
  } else {
    local.push(cmc, [-0.15, 0.17], [-0.07, 0.22], [0.01, 0.21]);
  }
  pose.fingers.forEach((f, i) => {
    const mcp = MCP[i] as Pt;
    const lens = LEN[i] as [number, number, number];
    if (f.extended) local.push(mcp, ...chain(mcp, f.angle, lens));
    else
      local.push(
        mcp,
        [mcp[0], mcp[1] + 0.06],
        [mcp[0] + 0.01, mcp[1] + 0.0],
        [mcp[0] + 0.01, mcp[1] - 0.04],
      );
  });
  // A thumb-up fist: the thumb rises from the folded fingers.
  if (pose.thumb.extended && pose.thumb.angle === 0) {
    local[1] = [-0.12, 0.14];
    local[2] = [-0.15, 0.26];
    local[3] = [-0.15, 0.38];
    local[4] = [-0.15, 0.48];
  }
  const r = (pose.rotation * Math.PI) / 180;
  const c: Pt = [0, 0.28];
  return local.map(([x, y]) => {
    const dx = x - c[0];
    const dy = y - c[1];
    // clockwise rotation in the local (y up) frame
    const rx = dx * Math.cos(r) + dy * Math.sin(r);
    const ry = -dx * Math.sin(r) + dy * Math.cos(r);
    return [0.5 + rx * 1.3, 0.5 - ry * 1.3];
  });
}
