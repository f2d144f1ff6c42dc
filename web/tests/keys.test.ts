import { describe, expect, it } from 'vitest';
import { KeyTracker, flyingKey, isTypingTarget } from '../src/logic/keys';

describe('key mapping', () => {
  it('maps arrows, WASD, Q E, R F and T L H to the server keys', () => {
    expect(flyingKey('ArrowUp')).toBe('w');
    expect(flyingKey('W')).toBe('w');
    expect(flyingKey('ArrowLeft')).toBe('a');
    expect(flyingKey('ArrowRight')).toBe('d');
    expect(flyingKey('ArrowDown')).toBe('s');
    expect(['q', 'e', 'r', 'f', 't', 'l', 'h'].map(flyingKey)).toEqual([
      'q',
      'e',
      'r',
      'f',
      't',
      'l',
      'h',
    ]);
    expect(flyingKey('x')).toBeNull();
    expect(flyingKey('Enter')).toBeNull();
  });

  it('sends a key down once however long it is held, and up once', () => {
    const k = new KeyTracker();
    expect(k.down({ key: 'w' })).toEqual({ kind: 'input', key: 'w', pressed: true });
    expect(k.down({ key: 'w', repeat: true })).toEqual({ kind: 'none' });
    expect(k.down({ key: 'ArrowUp' })).toEqual({ kind: 'none' });
    expect(k.up({ key: 'w' })).toEqual({ kind: 'input', key: 'w', pressed: false });
    expect(k.up({ key: 'w' })).toEqual({ kind: 'none' });
  });

  it('Space is the emergency stop, always', () => {
    const k = new KeyTracker();
    expect(k.down({ key: ' ' })).toEqual({ kind: 'emergency_stop' });
    expect(k.down({ key: ' ', repeat: true })).toEqual({ kind: 'emergency_stop' });
  });

  it('ignores keys typed into fields and with modifiers', () => {
    const k = new KeyTracker();
    expect(k.down({ key: 'w', target: { tagName: 'INPUT', type: 'text' } })).toEqual({
      kind: 'none',
    });
    expect(k.down({ key: 'w', ctrlKey: true })).toEqual({ kind: 'none' });
    expect(isTypingTarget({ tagName: 'INPUT', type: 'checkbox' })).toBe(false);
    expect(isTypingTarget({ tagName: 'TEXTAREA' })).toBe(true);
    expect(isTypingTarget({ tagName: 'BUTTON' })).toBe(false);
  });

  it('releases every held key when focus is lost (the drone hovers)', () => {
    const k = new KeyTracker();
    k.down({ key: 'w' });
    k.down({ key: 'q' });
    expect(k.releaseAll()).toEqual([
      { kind: 'input', key: 'w', pressed: false },
      { kind: 'input', key: 'q', pressed: false },
    ]);
    expect(k.heldKeys()).toEqual([]);
  });
});
