// The scaling bench in Node (issue 35; `cargo bench --bench scaling` is the
// native one): drilled plates of 10, 100, 1000 and 4000 holes and parts of as
// many one-hole blocks, each block its own solid (bench/plate.mjs writes
// both), meshed by the npm package's Node build (pkg/node) at one absolute
// tolerance, and by occt-import-js at the same linear deflection (angular
// 0.5, surfmesh's default angle) for the ratio. Time per face and per output
// triangle, each against the smallest size: flat means linear.
//
// Everything runs in this one process: each mesher's first call (wasm
// compilation included) is reported apart, then the best of RUNS calls.
//
//   node bench/scaling.mjs [--runs 2] [--sizes 10,100,1000,4000] [--shapes plate,bodies]
//                          [--tol 0.02] [--no-occt] [--out DIR]
//
// Prints a markdown table; with --out also writes DIR/scaling.md and
// scaling.json. bench/compare.mjs (`npm run bench`) runs it after the corpus.

import { mkdirSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, join } from 'node:path';
import { performance } from 'node:perf_hooks';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { plateStep } from './plate.mjs';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const require = createRequire(import.meta.url);

/** Holes → grid, as benches/scaling.rs. */
const GRIDS = { 10: [5, 2], 100: [10, 10], 1000: [40, 25], 4000: [80, 50] };

function gridOf(holes) {
  if (GRIDS[holes]) return GRIDS[holes];
  const nx = Math.ceil(Math.sqrt(holes));
  return [nx, Math.ceil(holes / nx)];
}

/** A first call this long is the only one: the size's figure is that call. */
const ONE_CALL_MS = 30_000;

/**
 * `f` once cold, then warm-up calls until V8 has tiered the code up (about
 * two seconds of calls, at most 30), then the best of `runs` calls:
 * {cold, best, result}. A first call over ONE_CALL_MS stands for all.
 */
function timed(f, runs) {
  const w0 = performance.now();
  let result = f();
  const cold = performance.now() - w0;
  if (cold > ONE_CALL_MS) return { cold, best: cold, result, once: true };
  for (let k = 0; k < 30 && performance.now() - w0 < 2000; k++) result = f();
  let best = Infinity;
  for (let k = 0; k < runs; k++) {
    const t0 = performance.now();
    result = f();
    best = Math.min(best, performance.now() - t0);
  }
  return { cold, best, result };
}

/**
 * Runs the scaling bench; returns {rows, markdown}. `say` reports progress.
 * Options: runs, sizes, shapes, tol (mm), occt (bool).
 */
export async function scaling({ runs = 2, sizes = [10, 100, 1000, 4000], shapes = ['plate', 'bodies'], tol = 0.02, occt = true, say = () => {} } = {}) {
  const surfmesh = require(join(root, 'pkg', 'node'));
  let oc = null;
  if (occt) {
    try {
      oc = await require('occt-import-js')({ print() {}, printErr() {} });
    } catch (e) {
      say(`occt-import-js not loaded: ${e.message}`);
    }
  }
  const rows = [];
  for (const shape of shapes) {
    // OCCT's time on the size before: past ONE_CALL_MS the larger sizes are left to it.
    let occtBefore = 0;
    for (const holes of sizes) {
      const [nx, ny] = gridOf(holes);
      const text = plateStep(nx, ny, { bodies: shape === 'bodies' });
      const bytes = new TextEncoder().encode(text);
      say(`scaling: ${shape} ${nx * ny} holes: surfmesh`);
      const row = { shape, holes: nx * ny, bytes: bytes.length };
      try {
        const s = timed(() => surfmesh.mesh(bytes, 'step', { tolerance: tol, flatten: true }), runs);
        const rep = s.result.report;
        Object.assign(row, {
          faces: rep.faces,
          bodies: rep.bodies,
          triangles: rep.triangles,
          ok: rep.max_deviation <= rep.tolerance && rep.free_edges === 0,
          cold_ms: s.cold,
          ms: s.best,
          once: s.once ?? false,
        });
      } catch (e) {
        row.error = String(e?.message ?? e).split('\n')[0];
      }
      if (oc && !row.error && occtBefore > ONE_CALL_MS) row.occt_skipped = `the size before took ${(occtBefore / 1000).toFixed(0)} s`;
      else if (oc && !row.error) {
        say(`scaling: ${shape} ${nx * ny} holes: occt-import-js`);
        const params = { linearUnit: 'millimeter', linearDeflectionType: 'absolute_value', linearDeflection: tol, angularDeflection: 0.5 };
        const o = timed(() => oc.ReadStepFile(bytes, params), runs);
        const triangles = o.result.success ? o.result.meshes.reduce((n, m) => n + m.index.array.length / 3, 0) : 0;
        occtBefore = o.best;
        // A read that fails or meshes nothing (out of memory on the largest part) times nothing.
        if (triangles > 0) Object.assign(row, { occt_ms: o.best, occt_once: o.once ?? false, occt_triangles: triangles });
        else row.occt_skipped = `no triangles after ${(o.best / 1000).toFixed(0)} s`;
      }
      rows.push(row);
    }
  }
  return { rows, markdown: markdown(rows, { runs, tol }) };
}

const f1 = (x) => (x == null || !Number.isFinite(x) ? '–' : x.toFixed(1));
const f2 = (x) => (x == null || !Number.isFinite(x) ? '–' : x.toFixed(2));

function markdown(rows, { runs, tol }) {
  const out = [];
  out.push(`## Scaling (wasm in Node, absolute tolerance ${tol} mm, best of ${runs} after a first call)`);
  out.push('');
  out.push(`Per face and per triangle: surfmesh's parse + mesh time over its faces and output triangles; × is against the smallest size of the shape. OCCT: occt-import-js at the same linear deflection and angular deflection 0.5, read + mesh; ratio = surfmesh / OCCT. A first call over ${ONE_CALL_MS / 1000} s is the only one (marked *), and OCCT is not run on the sizes after one that took that long.`);
  out.push('');
  out.push('| shape | holes | faces | bodies | triangles | first call ms | ms | µs / face | × | µs / triangle | × | triangles / s | OCCT ms | OCCT triangles | ratio | within tolerance, no cracks |');
  out.push('|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|');
  const first = {};
  for (const r of rows) {
    if (r.error) {
      out.push(`| ${r.shape} | ${r.holes} | failed: ${r.error} ||||||||||||||`);
      continue;
    }
    const perFace = (1e3 * r.ms) / r.faces;
    const perTri = (1e3 * r.ms) / r.triangles;
    first[r.shape] ??= { perFace, perTri };
    const f = first[r.shape];
    out.push(`| ${r.shape} | ${r.holes} | ${r.faces} | ${r.bodies} | ${r.triangles} | ${f1(r.cold_ms)} | ${f1(r.ms)}${r.once ? '*' : ''} | ${f1(perFace)} | ${f2(perFace / f.perFace)} | ${f2(perTri)} | ${f2(perTri / f.perTri)} | ${Math.round((1e3 * r.triangles) / r.ms)} | ${r.occt_skipped ? `failed or not run: ${r.occt_skipped}` : `${f1(r.occt_ms)}${r.occt_once ? '*' : ''}`} | ${r.occt_triangles ?? '–'} | ${f2(r.ms / r.occt_ms)} | ${r.ok ? 'yes' : 'NO'} |`);
  }
  return out.join('\n');
}

if (process.argv[1] && import.meta.url === pathToFileURL(process.argv[1]).href) {
  const argv = process.argv.slice(2);
  const opt = (name, fallback) => {
    const i = argv.indexOf(name);
    return i >= 0 ? argv[i + 1] : fallback;
  };
  const list = (s) => s.split(',').filter(Boolean);
  const { rows, markdown: md } = await scaling({
    runs: Math.max(1, Number(opt('--runs', 2))),
    sizes: list(opt('--sizes', '10,100,1000,4000')).map(Number),
    shapes: list(opt('--shapes', 'plate,bodies')),
    tol: Number(opt('--tol', 0.02)),
    occt: !argv.includes('--no-occt'),
    say: (m) => console.error(m),
  });
  const dir = opt('--out');
  if (dir) {
    mkdirSync(dir, { recursive: true });
    writeFileSync(join(dir, 'scaling.md'), `${md}\n`);
    writeFileSync(join(dir, 'scaling.json'), `${JSON.stringify(rows, null, 1)}\n`);
  }
  console.log(md);
}
