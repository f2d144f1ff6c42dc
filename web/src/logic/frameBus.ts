// The latest camera frame, outside React state: the feed canvas pulls it on each animation
// frame, so 24-30 FPS of JPEGs never re-render the panels.
import type { WsFrameData } from '../types';

type Listener = (f: WsFrameData) => void;

export class FrameBus {
  latest: WsFrameData | null = null;
  received = 0;
  private listeners = new Set<Listener>();

  push(f: WsFrameData): void {
    this.latest = f;
    this.received++;
    for (const l of this.listeners) l(f);
  }

  subscribe(l: Listener): () => void {
    this.listeners.add(l);
    return () => this.listeners.delete(l);
  }

  clear(): void {
    this.latest = null;
  }
}
