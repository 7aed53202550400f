// The baseline comparison of `surfmesh check` sweeps (scripts/check-baseline.mjs):
// each way a file can get worse fails, improvements are told apart, and the
// command's exit status follows.
//
//   node --test scripts/check-baseline.test.mjs

import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { test } from 'node:test';
import { fileURLToPath } from 'node:url';

import { compareRows, regenerateCommand } from './check-baseline.mjs';

const script = join(dirname(fileURLToPath(import.meta.url)), 'check-baseline.mjs');

const row = (over = {}) => ({
  file: 'a.stp',
  ok: true,
  error: null,
  faces_in_file: 10,
  faces_meshed: 10,
  cracks: 0,
  nonmanifold_edges: 0,
  inverted_triangles: 0,
  deviation_ratio: 0.8,
  time_ms: 1000,
  ...over,
});

test('each way a file gets worse is found', () => {
  const cases = [
    [{ ok: false, error: 'STEP line 3: bad' }, /fails where it meshed before: STEP line 3/],
    [{ faces_meshed: 9 }, /faces meshed 10 -> 9/],
    [{ cracks: 2 }, /cracks 0 -> 2/],
    [{ nonmanifold_edges: 1 }, /non-manifold edges 0 -> 1/],
    [{ inverted_triangles: 3 }, /inverted triangles 0 -> 3/],
    [{ deviation_ratio: 1.2 }, /deviation 1.20 x tolerance/],
    [{ time_ms: 12_000 }, /took 12.0 s \(was 1.0 s\)/],
  ];
  for (const [change, message] of cases) {
    const { worse, better } = compareRows(row(), row(change));
    assert.equal(worse.length, 1, JSON.stringify({ change, worse }));
    assert.match(worse[0], message);
    assert.deepEqual(better, []);
  }
  assert.deepEqual(compareRows(row(), row()), { worse: [], better: [] });
});

test('improvements are told, and what was already bad is judged against itself', () => {
  const { worse, better } = compareRows(row({ ok: false, error: 'x' }), row());
  assert.deepEqual(worse, []);
  assert.match(better[0], /meshes where it failed before/);
  const fixed = compareRows(row({ cracks: 4, deviation_ratio: 1.5 }), row({ cracks: 1 }));
  assert.deepEqual(fixed.worse, []);
  assert.equal(fixed.better.length, 2);
  // Already over the tolerance or slow: worse only when further.
  assert.deepEqual(compareRows(row({ deviation_ratio: 1.5 }), row({ deviation_ratio: 1.4 })).worse, []);
  assert.equal(compareRows(row({ deviation_ratio: 1.5 }), row({ deviation_ratio: 1.6 })).worse.length, 1);
  assert.deepEqual(compareRows(row({ time_ms: 20_000 }), row({ time_ms: 25_000 })).worse, []);
  assert.equal(compareRows(row({ time_ms: 20_000 }), row({ time_ms: 31_000 })).worse.length, 1);
});

test('the command fails on a worse file or a missing one, and passes otherwise', () => {
  const dir = mkdtempSync(join(tmpdir(), 'surfmesh-baseline-'));
  try {
    const sweep = (files) => ({ dir: 'x', tolerance: 'relative 0.01', units: 'file', files });
    const write = (name, files) => {
      const path = join(dir, name);
      writeFileSync(path, JSON.stringify(sweep(files)));
      return path;
    };
    const base = write('base.json', [row(), row({ file: 'b.igs', cracks: 3 })]);
    const run = (now) => spawnSync('node', [script, base, now], { encoding: 'utf8' });
    const same = run(write('same.json', [row(), row({ file: 'b.igs', cracks: 1 }), row({ file: 'new.stp' })]));
    assert.equal(same.status, 0, same.stdout + same.stderr);
    assert.match(same.stdout, /improved \(1\):\n {2}b\.igs: cracks 3 -> 1/);
    assert.match(same.stdout, /not in the baseline \(1\):\n {2}new\.stp: meshes/);
    // How to take them: the baseline's own folder, tolerance and path.
    assert.ok(same.stdout.includes(`surfmesh check x --tol-rel 0.01 --timeout 60 --json ${base}`), same.stdout);
    const worse = run(write('worse.json', [row({ cracks: 5 })]));
    assert.equal(worse.status, 1);
    assert.match(worse.stdout, /WORSE \(2\):\n {2}a\.stp: cracks 0 -> 5\n {2}b\.igs: in the baseline, not in the sweep/);
    const other = join(dir, 'other.json');
    writeFileSync(other, JSON.stringify({ ...sweep([row()]), tolerance: 'relative 0.001' }));
    assert.equal(run(other).status, 2);
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
});

test('the command to regenerate a baseline names its own folder, tolerance and file', () => {
  const rel = regenerateCommand('tests/baseline/corpus-3e-3.json', {
    dir: '../shared/corpus',
    tolerance: 'relative 0.003',
    units: 'file',
  });
  assert.match(rel, / check \.\.\/shared\/corpus --tol-rel 0\.003 --timeout 60 --json tests\/baseline\/corpus-3e-3\.json$/);
  const abs = regenerateCommand('b.json', { dir: 'parts', tolerance: 'absolute 0.5', units: 'mm' });
  assert.match(abs, / check parts --tol 0\.5 --units mm --timeout 60 --json b\.json$/);
});
