// Frame-rate meter over a sliding window of frame times (ms).
export class FpsMeter {
  private times: number[] = [];
  constructor(private readonly windowMs = 2000) {}

  frame(nowMs: number): void {
    this.times.push(nowMs);
    const cut = nowMs - this.windowMs;
    while (this.times.length && (this.times[0] ?? 0) < cut) this.times.shift();
  }

  /** Frames per second over the window ending at nowMs. */
  fps(nowMs: number): number {
    const cut = nowMs - this.windowMs;
    const n = this.times.filter((t) => t >= cut).length;
    if (n < 2) return 0;
    const first = this.times.find((t) => t >= cut) ?? nowMs;
    const span = Math.max(nowMs - first, 1);
    return ((n - 1) * 1000) / span;
  }
}
