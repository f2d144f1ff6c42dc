import { HAND_CONNECTIONS } from '../logic/skeleton';
import { POSES, poseLandmarks } from '../logic/handPose';
import type { MappableGesture } from '../types';

// Renders of our hand model (web/scripts/render-gesture-pictures.sh), when present.
const RENDERED = import.meta.glob('../assets/gestures/*.png', {
  eager: true,
  query: '?url',
  import: 'default',
}) as Record<string, string>;

export function renderedPicture(gesture: MappableGesture): string | undefined {
  return RENDERED[`../assets/gestures/${gesture}.png`];
}

export const HAVE_RENDERED_PICTURES = Object.keys(RENDERED).length > 0;

export function HandPicture({ gesture, label }: { gesture: MappableGesture; label: string }) {
  const src = renderedPicture(gesture);
  if (src) return <img src={src} alt={label} className="hand-picture" width={240} height={180} />;
  const pts = poseLandmarks(POSES[gesture]).map(([x, y]) => [x * 100, y * 100] as const);
  return (
    <svg viewBox="0 0 100 100" className="hand-picture" role="img" aria-label={label}>
      <rect x="0" y="0" width="100" height="100" rx="8" className="map-bg" />
      {HAND_CONNECTIONS.map(([a, b]) => {
        const pa = pts[a];
        const pb = pts[b];
        return pa && pb ? (
          <line key={`${a}-${b}`} x1={pa[0]} y1={pa[1]} x2={pb[0]} y2={pb[1]} className="bone" />
        ) : null;
      })}
      {pts.map(([x, y], i) => (
        <circle key={i} cx={x} cy={y} r={i % 4 === 0 && i > 0 ? 2.6 : 2} className="joint" />
      ))}
    </svg>
  );
}
