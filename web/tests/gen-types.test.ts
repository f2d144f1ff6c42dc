import { afterEach, describe, expect, it } from 'vitest';
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
// @ts-expect-error plain ESM script without declarations
import { generate } from '../scripts/gen-types.mjs';

const made: string[] = [];
afterEach(() => {
  for (const dir of made.splice(0)) rmSync(dir, { recursive: true, force: true });
});

function dirWith(files: Record<string, unknown>): string {
  const dir = mkdtempSync(join(tmpdir(), 'gbdcs-schemas-'));
  made.push(dir);
  for (const [name, body] of Object.entries(files))
    writeFileSync(join(dir, name), JSON.stringify(body));
  return dir;
}

describe('gen-types', () => {
  it('turns objects, enums, refs and nullable unions into TypeScript', () => {
    const dir = dirWith({
      'a.schema.json': {
        $id: 'a',
        title: 'Alpha',
        type: 'object',
        required: ['kind', 'b'],
        properties: {
          kind: { enum: ['X', 'Y'] },
          b: { $ref: 'b' },
          maybe: { oneOf: [{ type: 'null' }, { $ref: 'b.schema.json' }] },
          list: { type: 'array', items: { type: 'integer' } },
        },
      },
      'b.schema.json': {
        $id: 'b',
        title: 'Beta',
        type: 'object',
        properties: { n: { type: 'number' } },
      },
    });
    const out: string = generate(dir);
    expect(out).toContain('export type Alpha = {');
    expect(out).toContain('  kind: "X" | "Y";');
    expect(out).toContain('  b: Beta;');
    expect(out).toContain('  maybe?: null | Beta;');
    expect(out).toContain('  list?: number[];');
    expect(out).toContain('export const ALPHA_KIND = ["X","Y"] as const;');
    expect(out).toContain('  n?: number;');
  });

  it('rejects a reference to a schema that does not exist', () => {
    const dir = dirWith({
      'a.schema.json': { title: 'A', type: 'object', properties: { b: { $ref: 'nope' } } },
    });
    expect(() => generate(dir)).toThrow(/unresolved \$ref nope/);
  });

  it('matches the committed generated file (no drift)', async () => {
    const { readFileSync } = await import('node:fs');
    const committed = readFileSync(
      join(__dirname, '..', 'src', 'generated', 'contracts.ts'),
      'utf8',
    );
    expect(generate()).toBe(committed);
  });
});
