// The drone seen by its adapter's camera: the twin's chase camera (drone_view messages, about
// 5 per second). The newest picture goes straight into the <img> (no React render per picture).
import { useEffect, useRef, useState } from 'react';
import type { ViewBus } from '../logic/frameBus';

interface Props {
  views: ViewBus;
  /** the connected drone's adapter name */
  adapter: string | null;
  /** the server says this drone sends pictures (state.drone_view) */
  available: boolean;
}

export function DroneView({ views, adapter, available }: Props) {
  const imgRef = useRef<HTMLImageElement | null>(null);
  const [seen, setSeen] = useState(views.latest !== null);

  useEffect(() => {
    const show = () => {
      const v = views.latest;
      const img = imgRef.current;
      if (!v || !img) return;
      img.src = `data:image/jpeg;base64,${v.jpeg}`;
      img.dataset.frameId = String(v.frame_id);
      img.alt = `The drone seen from its ${v.camera} camera`;
    };
    show();
    return views.subscribe(() => {
      setSeen(true);
      show();
    });
  }, [views, seen]);

  if (!available && adapter !== 'twin') return null;
  const title = adapter === 'twin' ? 'Twin chase camera' : 'Drone camera';
  return (
    <section className="panel twin-view" aria-labelledby="twin-h">
      <h2 id="twin-h">{title}</h2>
      {available || seen ? (
        <img
          ref={imgRef}
          className="drone-view"
          data-testid="drone-view"
          width={320}
          height={240}
          alt="Waiting for the drone's camera"
        />
      ) : (
        <p className="muted">
          This server sends no picture of the drone (it predates drone_view messages, or the view is
          switched off with <code>--drone-view-fps 0</code>); the path map shows where it is.
        </p>
      )}
    </section>
  );
}
