// A short two-tone alarm for critical alerts (Web Audio; no sound files). Browsers only allow
// audio after a user gesture: the login click counts, so it works once the operator is in.
let ctx: AudioContext | null = null;

export function playAlarm(): void {
  try {
    const Ctor =
      window.AudioContext ??
      (window as unknown as { webkitAudioContext?: typeof AudioContext }).webkitAudioContext;
    if (!Ctor) return;
    ctx ??= new Ctor();
    if (ctx.state === 'suspended') void ctx.resume();
    const t0 = ctx.currentTime;
    for (let i = 0; i < 3; i++) {
      const osc = ctx.createOscillator();
      const gain = ctx.createGain();
      osc.type = 'square';
      osc.frequency.value = i % 2 ? 660 : 880;
      gain.gain.setValueAtTime(0.0001, t0 + i * 0.25);
      gain.gain.exponentialRampToValueAtTime(0.2, t0 + i * 0.25 + 0.02);
      gain.gain.exponentialRampToValueAtTime(0.0001, t0 + i * 0.25 + 0.22);
      osc.connect(gain).connect(ctx.destination);
      osc.start(t0 + i * 0.25);
      osc.stop(t0 + i * 0.25 + 0.23);
    }
    alarmCount++;
  } catch {
    // No audio device: the banner is still there.
  }
}

/** How many alarms played (the end-to-end test reads it through window.__gbdcs). */
export let alarmCount = 0;
