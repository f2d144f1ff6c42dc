import type { PathPoint } from '../logic/pathMap';
import { altitudeStrip, fitProjection, headingMarker, niceMetres } from '../logic/pathMap';

const MAP = { width: 320, height: 240, padding: 16 };
const STRIP = { width: 320, height: 70, padding: 8 };

/** x/y trajectory since take-off (north up), heading marker, and the altitude strip. */
export function PathMap({ path }: { path: readonly PathPoint[] }) {
  const proj = fitProjection(path, MAP);
  const pts = path.map((p) => proj.toScreen(p.x_m, p.y_m));
  const last = path[path.length - 1];
  const lastS = pts[pts.length - 1];
  const origin = proj.toScreen(0, 0);
  const bar = niceMetres(proj.spanM / 3);
  const strip = altitudeStrip(path, STRIP);
  const summary = last
    ? `Path of ${path.length} points; now at x ${last.x_m.toFixed(1)} m, y ${last.y_m.toFixed(1)} m, altitude ${last.altitude_m.toFixed(1)} m, heading ${Math.round(last.heading_deg)} degrees.`
    : 'No flight path yet: it starts at take-off.';
  return (
    <section className="panel path-map" aria-labelledby="path-h">
      <h2 id="path-h">Path since take-off</h2>
      <svg
        viewBox={`0 0 ${MAP.width} ${MAP.height}`}
        role="img"
        aria-label={summary}
        data-testid="path-map"
        data-points={path.length}
      >
        <rect className="map-bg" x="0" y="0" width={MAP.width} height={MAP.height} rx="6" />
        <circle className="map-origin" cx={origin[0]} cy={origin[1]} r="4" />
        {pts.length > 1 && (
          <polyline className="map-path" points={pts.map((p) => p.join(',')).join(' ')} />
        )}
        {last && lastS && (
          <polygon
            className="map-heading"
            points={headingMarker(lastS[0], lastS[1], last.heading_deg)
              .map((p) => p.join(','))
              .join(' ')}
          />
        )}
        <text className="map-north" x={MAP.width - 14} y="16" textAnchor="middle">
          N
        </text>
        <line
          className="map-scale"
          x1="12"
          y1={MAP.height - 12}
          x2={12 + bar * proj.scale}
          y2={MAP.height - 12}
        />
        <text className="map-label" x="12" y={MAP.height - 18}>
          {bar} m
        </text>
      </svg>
      <svg
        viewBox={`0 0 ${STRIP.width} ${STRIP.height}`}
        role="img"
        aria-label={`Altitude over the flight, top of scale ${strip.topM.toFixed(1)} metres`}
        data-testid="altitude-strip"
      >
        <rect className="map-bg" x="0" y="0" width={STRIP.width} height={STRIP.height} rx="6" />
        {strip.polyline.length > 1 && (
          <polyline className="map-alt" points={strip.polyline.map((p) => p.join(',')).join(' ')} />
        )}
        <text className="map-label" x="6" y="14">
          {strip.topM.toFixed(1)} m
        </text>
        <text className="map-label" x="6" y={STRIP.height - 4}>
          0 m
        </text>
      </svg>
    </section>
  );
}
