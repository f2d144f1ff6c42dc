// The latest picture (camera frame, drone view) outside React state: the canvas or image that
// shows it pulls or subscribes to it, so 24-30 FPS of JPEGs never re-render the panels.
import type { WsDroneViewData, WsFrameData, WsPictureData } from '../types';

type Listener<T> = (f: T) => void;

export class LatestBus<T> {
  latest: T | null = null;
  received = 0;
  private listeners = new Set<Listener<T>>();

  push(f: T): void {
    this.latest = f;
    this.received++;
    for (const l of this.listeners) l(f);
  }

  subscribe(l: Listener<T>): () => void {
    this.listeners.add(l);
    return () => this.listeners.delete(l);
  }

  clear(): void {
    this.latest = null;
  }
}

/**
 * The live feed: vision results (hands, at tracking's rate) and, apart, camera pictures (at
 * the camera's rate); the feed draws the newest result's skeleton over the newest picture.
 */
export class FrameBus extends LatestBus<WsFrameData> {
  readonly pictures = new LatestBus<WsPictureData>();

  override clear(): void {
    super.clear();
    this.pictures.clear();
  }
}

/** Pictures of the drone from its adapter (the twin's chase camera). */
export class ViewBus extends LatestBus<WsDroneViewData> {}
