// Readable contrast in both themes: every text/background pair the dashboard uses meets WCAG
// 2.x AA (4.5:1 for text, 3:1 for large text and UI marks), read from the CSS variables.
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { describe, expect, it } from 'vitest';

const css = readFileSync(join(__dirname, '..', 'src', 'styles.css'), 'utf8');

function theme(selector: string): Record<string, string> {
  const start = css.indexOf(selector);
  const block = css.slice(css.indexOf('{', start) + 1, css.indexOf('}', start));
  const vars: Record<string, string> = {};
  for (const m of block.matchAll(/--([\w-]+):\s*(#[0-9a-fA-F]{6})/g)) vars[m[1]!] = m[2]!;
  return vars;
}

function luminance(hex: string): number {
  const c = [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16) / 255);
  const lin = c.map((v) => (v <= 0.03928 ? v / 12.92 : Math.pow((v + 0.055) / 1.055, 2.4)));
  return 0.2126 * lin[0]! + 0.7152 * lin[1]! + 0.0722 * lin[2]!;
}

export function contrast(a: string, b: string): number {
  const [x, y] = [luminance(a), luminance(b)].sort((p, q) => q - p);
  return (x! + 0.05) / (y! + 0.05);
}

// [foreground, background, minimum]
const PAIRS: [string, string, number][] = [
  ['text', 'bg', 4.5],
  ['text', 'panel', 4.5],
  ['text', 'panel-2', 4.5],
  ['muted', 'panel', 4.5],
  ['muted', 'bg', 4.5],
  ['accent', 'bg', 4.5],
  ['accent', 'panel', 4.5],
  ['accent-text', 'accent', 4.5],
  ['danger-text', 'danger', 4.5],
  ['text', 'crit-bg', 4.5],
  ['text', 'warn-bg', 4.5],
  ['text', 'info-bg', 4.5],
  ['warn', 'panel', 4.5],
  ['ok', 'panel', 4.5],
  ['map-path', 'panel-2', 3],
  ['focus', 'bg', 3],
];

describe.each([
  ['dark', ":root[data-theme='dark']"],
  ['light', ":root[data-theme='light']"],
])('%s theme', (_name, selector) => {
  const vars = theme(selector);
  it.each(PAIRS)('%s on %s is readable', (fg, bg, min) => {
    expect(vars[fg], `--${fg} missing`).toBeDefined();
    expect(vars[bg], `--${bg} missing`).toBeDefined();
    expect(contrast(vars[fg]!, vars[bg]!)).toBeGreaterThanOrEqual(min);
  });
});

describe('contrast maths', () => {
  it('matches the WCAG reference values', () => {
    expect(contrast('#000000', '#ffffff')).toBeCloseTo(21, 5);
    expect(contrast('#777777', '#ffffff')).toBeCloseTo(4.48, 2);
  });
});
