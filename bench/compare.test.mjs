// Smoke run of the side-by-side benchmark (bench/compare.mjs): one small JSON
// surface, one tolerance, one timed run, debug binaries (the ones `cargo
// test` already built). Checks that every mesher ran and that the yardstick
// measured every mesh; the figures themselves are the benchmark's business.
//
//   node --test bench/compare.test.mjs   (after `node scripts/build-wasm.mjs`)

import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { test } from 'node:test';
import { fileURLToPath } from 'node:url';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');

test('the benchmark meshes, measures and compares one small surface', { timeout: 300_000 }, () => {
  const out = mkdtempSync(join(tmpdir(), 'surfmesh-bench-test-'));
  try {
    const args = ['bench/compare.mjs', '--profile', 'debug', '--no-corpus', '--only', 'cylinder.json'];
    args.push('--tols', '1e-2', '--runs', '1', '--out', out);
    const r = spawnSync('node', args, { cwd: root, encoding: 'utf8', maxBuffer: 1 << 26 });
    assert.equal(r.status, 0, r.stderr);
    const { meta, rows, comparisons } = JSON.parse(readFileSync(join(out, 'latest.json'), 'utf8'));
    assert.deepEqual(meta.tolerances, [1e-2]);
    assert.equal(rows.length, 1);
    const row = rows[0];
    assert.equal(row.file, 'cylinder.json');
    // surfmesh, both builds: the same mesh, within its tolerance, no cracks.
    const sw = row.surfmesh_wasm.measure;
    assert.ok(sw.triangles > 0 && sw.max_deviation > 0 && sw.max_deviation <= row.tolerance, JSON.stringify(sw));
    assert.equal(row.surfmesh_native.run.triangles, sw.triangles);
    assert.equal(sw.free_edges + sw.nonmanifold_edges, 0);
    assert.equal(row.surfmesh_wasm.run.total_ms.length, 1);
    // The wasm module's peak memory, against the mesh it returned.
    const { wasm_peak_bytes: peak, wasm_base_bytes: base, output_bytes: output } = row.surfmesh_wasm.run;
    assert.ok(output > 0 && peak >= base && peak % 65536 === 0, JSON.stringify({ peak, base, output }));
    // Each peer reached surfmesh's measured deviation and was measured by the same yardstick.
    for (const peer of ['verb', 'curvo']) {
      const m = row[peer].measure;
      assert.ok(row[peer].search.reached, `${peer}: ${JSON.stringify(row[peer].search)}`);
      assert.ok(m.triangles > 0 && m.max_deviation <= sw.max_deviation, `${peer}: ${JSON.stringify(m)}`);
    }
    const ratios = comparisons[0];
    assert.deepEqual(
      ratios.map((c) => c.peer),
      ['verb', 'curvo'],
    );
    for (const c of ratios) assert.ok(c.triangles > 0 && Number.isFinite(c.time), JSON.stringify(c));
    const md = readFileSync(join(out, 'latest.md'), 'utf8');
    assert.match(md, /\| verb-nurbs \(JS\) \| 0\.01 \| 1 \|/);
    assert.match(md, /### cylinder\.json at 0\.01/);
    assert.match(md, /\| surfmesh wasm \| rel 0\.01 \|.*× output\) \|/);
  } finally {
    rmSync(out, { recursive: true, force: true });
  }
});

test('the scaling bench meshes a plate and a part of blocks, each within tolerance and sewn', { timeout: 300_000 }, async () => {
  const { scaling } = await import('./scaling.mjs');
  const { rows, markdown } = await scaling({ runs: 1, sizes: [10], occt: false });
  assert.deepEqual(
    rows.map((r) => [r.shape, r.holes, r.faces, r.bodies]),
    [
      ['plate', 10, 16, 1],
      ['bodies', 10, 70, 10],
    ],
  );
  for (const r of rows) assert.ok(r.ok && r.triangles > 0 && r.ms > 0, JSON.stringify(r));
  assert.match(markdown, /\| plate \| 10 \| 16 \| 1 \| \d+ \|/);
});
