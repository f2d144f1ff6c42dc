// The 21-point MediaPipe hand skeleton: bones between landmarks and the mapping from
// normalised landmark coordinates to a canvas where the image is drawn letterboxed.

/** Bones as landmark index pairs (MediaPipe Hands order). */
export const HAND_CONNECTIONS: readonly (readonly [number, number])[] = [
  [0, 1],
  [1, 2],
  [2, 3],
  [3, 4], // thumb
  [0, 5],
  [5, 6],
  [6, 7],
  [7, 8], // index
  [5, 9],
  [9, 10],
  [10, 11],
  [11, 12], // middle
  [9, 13],
  [13, 14],
  [14, 15],
  [15, 16], // ring
  [13, 17],
  [0, 17],
  [17, 18],
  [18, 19],
  [19, 20], // pinky and palm
];

export interface Fit {
  x: number;
  y: number;
  width: number;
  height: number;
}

/** Where an image of imgW x imgH goes in a canvas of canW x canH, aspect kept, centred. */
export function containFit(imgW: number, imgH: number, canW: number, canH: number): Fit {
  if (imgW <= 0 || imgH <= 0) return { x: 0, y: 0, width: canW, height: canH };
  const s = Math.min(canW / imgW, canH / imgH);
  const width = imgW * s;
  const height = imgH * s;
  return { x: (canW - width) / 2, y: (canH - height) / 2, width, height };
}

/** Canvas points for 21 normalised landmarks, or null when the hand is not 21 finite points. */
export function projectLandmarks(
  landmarks: readonly (readonly number[])[],
  fit: Fit,
): [number, number][] | null {
  if (landmarks.length !== 21) return null;
  const out: [number, number][] = [];
  for (const p of landmarks) {
    const x = p[0];
    const y = p[1];
    if (x === undefined || y === undefined || !Number.isFinite(x) || !Number.isFinite(y))
      return null;
    out.push([fit.x + x * fit.width, fit.y + y * fit.height]);
  }
  return out;
}
