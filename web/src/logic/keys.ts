// Keyboard flying: which browser keys are sent to the server as `input` messages (ws_input),
// and a tracker that sends each key down once (no auto-repeat flood) and releases every held
// key when the window loses focus (the server hovers when a movement key is released).
// The server's KeyboardInput turns keys into the same commands gestures produce, through the
// same arbiter and failsafes.

export interface KeyBinding {
  /** KeyboardEvent.key values (letters lower-case) */
  keys: readonly string[];
  /** what is sent in ws_input.key */
  send: string;
  label: string;
}

export const KEY_BINDINGS: readonly KeyBinding[] = [
  { keys: ['w', 'ArrowUp'], send: 'w', label: 'Forward' },
  { keys: ['s', 'ArrowDown'], send: 's', label: 'Back' },
  { keys: ['a', 'ArrowLeft'], send: 'a', label: 'Left' },
  { keys: ['d', 'ArrowRight'], send: 'd', label: 'Right' },
  { keys: ['q'], send: 'q', label: 'Yaw left' },
  { keys: ['e'], send: 'e', label: 'Yaw right' },
  { keys: ['r'], send: 'r', label: 'Up' },
  { keys: ['f'], send: 'f', label: 'Down' },
  { keys: ['t'], send: 't', label: 'Take off' },
  { keys: ['l'], send: 'l', label: 'Land' },
  { keys: ['h'], send: 'h', label: 'Hover' },
];

/** Space: emergency stop (sent as an emergency_stop message, not as an input key). */
export const EMERGENCY_KEY = ' ';

const byKey = new Map<string, string>();
for (const b of KEY_BINDINGS) for (const k of b.keys) byKey.set(k, b.send);

/** The ws_input key for a KeyboardEvent.key, or null when the key does not fly. */
export function flyingKey(eventKey: string): string | null {
  const k = eventKey.length === 1 ? eventKey.toLowerCase() : eventKey;
  return byKey.get(k) ?? null;
}

export interface KeyEventLike {
  key: string;
  repeat?: boolean;
  ctrlKey?: boolean;
  altKey?: boolean;
  metaKey?: boolean;
  target?: unknown;
}

/** True when the key is typed into a form field (flying keys must not fire there). */
export function isTypingTarget(target: unknown): boolean {
  if (!target || typeof target !== 'object') return false;
  const el = target as { tagName?: string; isContentEditable?: boolean; type?: string };
  const tag = (el.tagName ?? '').toUpperCase();
  if (el.isContentEditable) return true;
  if (tag === 'TEXTAREA' || tag === 'SELECT') return true;
  if (tag === 'INPUT') {
    const t = (el.type ?? 'text').toLowerCase();
    return !['button', 'checkbox', 'radio', 'range', 'submit', 'reset'].includes(t);
  }
  return false;
}

export type KeyOutput =
  { kind: 'input'; key: string; pressed: boolean } | { kind: 'emergency_stop' } | { kind: 'none' };

/** Tracks held keys; turns key events into what to send. One instance per flying view. */
export class KeyTracker {
  private readonly held = new Set<string>();

  down(e: KeyEventLike): KeyOutput {
    if (e.ctrlKey || e.altKey || e.metaKey || isTypingTarget(e.target)) return { kind: 'none' };
    if (e.key === EMERGENCY_KEY || e.key === 'Spacebar') return { kind: 'emergency_stop' };
    const k = flyingKey(e.key);
    if (!k) return { kind: 'none' };
    if (this.held.has(k)) return { kind: 'none' }; // auto-repeat or the other key of a pair
    this.held.add(k);
    return { kind: 'input', key: k, pressed: true };
  }

  up(e: KeyEventLike): KeyOutput {
    const k = flyingKey(e.key);
    if (!k || !this.held.has(k)) return { kind: 'none' };
    this.held.delete(k);
    return { kind: 'input', key: k, pressed: false };
  }

  /** Window blurred or view left: release everything held. */
  releaseAll(): KeyOutput[] {
    const out: KeyOutput[] = [...this.held].map((key) => ({ kind: 'input', key, pressed: false }));
    this.held.clear();
    return out;
  }

  heldKeys(): string[] {
    return [...this.held];
  }
}
