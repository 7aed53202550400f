// One mesher on one file, in a Node process of its own (so that its peak
// memory is its own): surfmesh (the Node build in pkg/node), occt-import-js
// or verb-nurbs. Called by bench/compare.mjs; prints one JSON object.
//
//   node bench/run_one.mjs surfmesh FILE --rel R [--runs N] [--out MESH.json]
//   node bench/run_one.mjs occt FILE --tol T --angle A [--unit millimeter] [--runs N] [--out MESH.json]
//   node bench/run_one.mjs verb FILE --norm-tol X [--runs N] [--out MESH.json]
//   node bench/run_one.mjs verb FILE --match DEV --tol T --measure BIN
//
// Times are the median-ready lists of every run after one warm-up run; parse
// and mesh apart where the mesher allows (occt-import-js reads and meshes in
// one call). Memory: the process's peak resident set, and the same at start
// (bare Node), in KB; for surfmesh also its wasm memory after the first call
// (its peak) against the bytes of the mesh it returns. The last mesh is written as JSON
// {positions, indices, faceRanges} for the yardstick (examples/measure.rs).

import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { tmpdir } from 'node:os';
import { dirname, extname, join } from 'node:path';
import { performance } from 'node:perf_hooks';
import { fileURLToPath } from 'node:url';

const baseRssKb = process.resourceUsage().maxRSS;
const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const require = createRequire(import.meta.url);

const [peer, file, ...rest] = process.argv.slice(2);
const arg = (name, fallback) => {
  const i = rest.indexOf(name);
  return i >= 0 ? rest[i + 1] : fallback;
};
const RUNS = Math.max(1, Number(arg('--runs', 5)));
const out = arg('--out');

/**
 * Runs `f` once cold (compilation included: what a page meshing once sees),
 * then warms up until V8 has tiered the code up (its wasm and JS tiers
 * switch hot functions to optimized code after a while: the first ten runs of
 * a small model can take twice as long as the later ones): at least two more
 * runs and, within 30 runs, about two seconds; then RUNS timed runs. `f`
 * returns {parse, mesh, result}.
 */
function timed(f) {
  const w0 = performance.now();
  f();
  const cold = performance.now() - w0;
  for (let k = 0; k < 2 || (k < 30 && performance.now() - w0 < 2000); k++) f();
  const runs = [];
  let last;
  for (let r = 0; r < RUNS; r++) {
    const t0 = performance.now();
    last = f();
    runs.push({ total: performance.now() - t0, parse: last.parse, mesh: last.mesh });
  }
  return {
    cold_ms: cold,
    total_ms: runs.map((r) => r.total),
    parse_ms: runs.map((r) => r.parse),
    mesh_ms: runs.map((r) => r.mesh),
    result: last.result,
  };
}

function writeMesh(path, positions, indices, faceRanges) {
  if (!path) return;
  const json = `{"positions":[${Array.from(positions).join(',')}],"indices":[${Array.from(indices).join(',')}],"faceRanges":[${faceRanges.join(',')}]}`;
  writeFileSync(path, json);
}

function finish(extra) {
  const peak = process.resourceUsage().maxRSS;
  console.log(JSON.stringify({ peer, rss_kb: peak, base_rss_kb: baseRssKb, ...extra }));
}

// ---- surfmesh (wasm, the shipping Node build) ----------------------------------------
function runSurfmesh() {
  const surfmesh = require(join(root, 'pkg', 'node'));
  const bytes = readFileSync(file);
  const rel = Number(arg('--rel'));
  const format = extname(file).slice(1).toLowerCase(); // as the CLI: the format from the extension
  // Wasm memory only grows: its size after the first call is that call's peak.
  const wasmBase = surfmesh.memoryBytes?.() ?? null;
  let wasmPeak = null;
  const t = timed(() => {
    const m = surfmesh.mesh(bytes, format, { toleranceRel: rel, flatten: true });
    wasmPeak ??= surfmesh.memoryBytes?.() ?? null;
    return { parse: m.report.parse_ms, mesh: m.report.time_ms, result: m };
  });
  const m = t.result;
  writeMesh(out, m.positions, m.indices, Array.from(m.faceRanges));
  delete t.result;
  const { warnings, ...report } = m.report;
  // The mesh as the JS caller holds it: every typed array of the result.
  const outputBytes = [m.positions, m.normals, m.indices, m.faceRanges, m.faceParts, m.faceColors].reduce((n, a) => n + (a?.byteLength ?? 0), 0);
  finish({ ...t, triangles: m.indices.length / 3, report, warnings: warnings.slice(0, 5), version: surfmesh.version(), wasm_base_bytes: wasmBase, wasm_peak_bytes: wasmPeak, output_bytes: outputBytes });
}

// ---- occt-import-js (OCCT's BRepMesh in wasm) -----------------------------------------
async function runOcct() {
  // Its reader prints entity counts on stdout; keep stdout for the result.
  const occt = await require('occt-import-js')({ print() {}, printErr() {} });
  const bytes = new Uint8Array(readFileSync(file));
  const params = {
    linearUnit: arg('--unit', 'millimeter'),
    linearDeflectionType: 'absolute_value',
    linearDeflection: Number(arg('--tol')),
    angularDeflection: Number(arg('--angle', 0.5)),
  };
  const ext = extname(file).toLowerCase();
  const read = ext === '.igs' || ext === '.iges' ? occt.ReadIgesFile : ext === '.brep' ? occt.ReadBrepFile : occt.ReadStepFile;
  const t = timed(() => ({ parse: null, mesh: null, result: read(bytes, params) }));
  const res = t.result;
  delete t.result;
  if (!res.success) {
    finish({ error: 'occt-import-js: success = false' });
    return;
  }
  let vertexCount = 0;
  let triangleCount = 0;
  const positions = [];
  const indices = [];
  const faceRanges = [];
  for (const m of res.meshes) {
    for (const x of m.attributes.position.array) positions.push(x);
    for (const i of m.index.array) indices.push(i + vertexCount);
    for (const f of m.brep_faces ?? []) faceRanges.push(triangleCount + f.first, f.last - f.first + 1);
    vertexCount += m.attributes.position.array.length / 3;
    triangleCount += m.index.array.length / 3;
  }
  writeMesh(out, positions, indices, faceRanges);
  finish({ ...t, triangles: triangleCount, meshes: res.meshes.length, heap_bytes: occt.HEAP8.length });
}

// ---- verb-nurbs (JavaScript; untrimmed surfaces only) --------------------------------
function loadVerb() {
  globalThis.window = globalThis; // verb's UMD bundle looks for a browser global
  const log = console.log;
  console.log = () => {}; // it logs its version on load
  try {
    return require('verb-nurbs');
  } finally {
    console.log = log;
  }
}

function verbMesher(verb, bytes) {
  const parse = () =>
    JSON.parse(bytes.toString('utf8')).faces.map((f) => {
      const s = f.surface;
      const weights = s.weights ?? s.points.map((row) => row.map(() => 1));
      return verb.geom.NurbsSurface.byKnotsControlPointsWeights(s.degree[0], s.degree[1], s.knots[0], s.knots[1], s.points, weights);
    });
  const tessellate = (surfaces, normTol) =>
    surfaces.map((s) => s.tessellate({ normTol, minDivsU: 1, minDivsV: 1, maxDepth: 12, refine: true }));
  return { parse, tessellate };
}

function flatten(meshes) {
  const positions = [];
  const indices = [];
  const faceRanges = [];
  let triangles = 0;
  for (const m of meshes) {
    const base = positions.length / 3;
    for (const p of m.points) positions.push(p[0], p[1], p[2]);
    for (const f of m.faces) indices.push(f[0] + base, f[1] + base, f[2] + base);
    faceRanges.push(triangles, m.faces.length);
    triangles += m.faces.length;
  }
  return { positions, indices, faceRanges, triangles };
}

function runVerb() {
  const verb = loadVerb();
  const bytes = readFileSync(file);
  const { parse, tessellate } = verbMesher(verb, bytes);
  const match = arg('--match');
  if (match !== undefined) {
    finish(searchVerb(parse(), tessellate, Number(match)));
    return;
  }
  const normTol = Number(arg('--norm-tol'));
  const t = timed(() => {
    const t0 = performance.now();
    const surfaces = parse();
    const t1 = performance.now();
    const meshes = tessellate(surfaces, normTol);
    return { parse: t1 - t0, mesh: performance.now() - t1, result: meshes };
  });
  const flat = flatten(t.result);
  delete t.result;
  writeMesh(out, flat.positions, flat.indices, flat.faceRanges);
  finish({ ...t, triangles: flat.triangles, norm_tolerance: normTol, version: require('verb-nurbs/package.json').version });
}

/** The search gives up past this many triangles or this long (the mesh would not compare). */
const SEARCH_MAX_TRIANGLES = 150_000;
const SEARCH_MAX_MS = 25_000;

/**
 * Largest normTol (within ~10%) whose mesh the yardstick measures within
 * `target`: down by factors of 4 until it passes, then bisection in log scale.
 */
function searchVerb(surfaces, tessellate, target) {
  const dir = mkdtempSync(join(tmpdir(), 'verb-search-'));
  const measureBin = arg('--measure');
  const tried = [];
  const measure = (normTol) => {
    const flat = flatten(tessellate(surfaces, normTol));
    const path = join(dir, 'mesh.json');
    writeMesh(path, flat.positions, flat.indices, flat.faceRanges);
    const r = spawnSync(measureBin, [file, path, '--tol', arg('--tol'), '--coverage-samples', '1000'], { encoding: 'utf8' });
    if (r.status !== 0) throw new Error(`measure: ${r.stderr}`);
    const dev = JSON.parse(r.stdout).max_deviation ?? Infinity;
    tried.push({ norm_tolerance: normTol, triangles: flat.triangles, max_deviation: dev });
    return { dev, triangles: flat.triangles };
  };
  try {
    let pass = null;
    let fail = null;
    let nt = 0.5;
    const t0 = performance.now();
    const over = (m) => m.triangles > SEARCH_MAX_TRIANGLES || performance.now() - t0 > SEARCH_MAX_MS;
    for (let k = 0; k < 12 && !pass; k++) {
      const m = measure(nt);
      if (m.dev <= target) pass = { nt, ...m };
      else if (over(m)) break;
      else {
        fail = nt;
        nt *= 0.25;
      }
    }
    if (pass && fail !== null) {
      while (fail / pass.nt > 1.1 && performance.now() - t0 < SEARCH_MAX_MS) {
        const mid = Math.sqrt(pass.nt * fail);
        const m = measure(mid);
        if (m.dev <= target) pass = { nt: mid, ...m };
        else fail = mid;
      }
    }
    return pass
      ? { norm_tolerance: pass.nt, max_deviation: pass.dev, triangles: pass.triangles, reached: true, tried }
      : { norm_tolerance: nt, reached: false, tried, gave_up: `no normTol reached it within ${SEARCH_MAX_TRIANGLES} triangles and ${SEARCH_MAX_MS / 1000} s` };
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
}

try {
  if (peer === 'surfmesh') runSurfmesh();
  else if (peer === 'occt') await runOcct();
  else if (peer === 'verb') runVerb();
  else throw new Error(`unknown mesher ${peer}`);
} catch (e) {
  finish({ error: String(e?.message ?? e).split('\n')[0] });
}
