// surfmesh (the Node build in pkg/node) against verb-nurbs on the same
// freeform patch (tests/data/js_freeform.json): surfmesh meshes at a relative
// tolerance of 1e-3; verb's normTol is lowered until verb's mesh is as close
// to the exact surface as surfmesh's. Both meshes are measured by the same
// code here (samples on every triangle projected onto the exact surface by
// Newton's method, using verb's evaluator), so the comparison is equal
// accuracy: triangle count ratio and time ratio (median of several runs).
//
// Run: npm run build && npm run bench:verb   [-- --runs N]

import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, join } from 'node:path';
import { performance } from 'node:perf_hooks';
import { fileURLToPath } from 'node:url';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const require = createRequire(import.meta.url);
globalThis.window = globalThis; // verb's UMD bundle looks for a browser global
const verb = quietly(() => require('verb-nurbs')); // it logs its version on load
const surfmesh = require(join(root, 'pkg', 'node'));

function quietly(f) {
  const log = console.log;
  console.log = () => {};
  try {
    return f();
  } finally {
    console.log = log;
  }
}

const runsArg = process.argv.indexOf('--runs');
const RUNS = Math.max(5, runsArg > 0 ? Number(process.argv[runsArg + 1]) : 7);
const REL_TOL = 1e-3;
const SAMPLE_STEPS = 4; // barycentric grid per triangle, as surfmesh's own measure

const file = join(root, 'tests', 'data', 'js_freeform.json');
const bytes = readFileSync(file);
const face = JSON.parse(bytes.toString('utf8')).faces[0].surface;

// ---- the exact surface, through verb -------------------------------------------------
const [du, dv] = face.degree;
const weights = face.weights ?? face.points.map((row) => row.map(() => 1));
const surface = verb.geom.NurbsSurface.byKnotsControlPointsWeights(du, dv, face.knots[0], face.knots[1], face.points, weights);
const uRange = [face.knots[0][du], face.knots[0][face.knots[0].length - du - 1]];
const vRange = [face.knots[1][dv], face.knots[1][face.knots[1].length - dv - 1]];

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const clamp = (x, [lo, hi]) => Math.min(hi, Math.max(lo, x));

/** Coarse grid of surface points: starting guesses for the projection. */
const GRID = 64;
const grid = [];
for (let i = 0; i <= GRID; i++) {
  for (let j = 0; j <= GRID; j++) {
    const u = uRange[0] + ((uRange[1] - uRange[0]) * i) / GRID;
    const v = vRange[0] + ((vRange[1] - vRange[0]) * j) / GRID;
    grid.push({ uv: [u, v], p: surface.point(u, v) });
  }
}

/** Closest point on the surface to `p` by Newton's method from `uv`; returns [distance, uv]. */
function project(p, uv) {
  let [u, v] = uv;
  let best = Infinity;
  let bestUv = uv;
  for (let it = 0; it < 30; it++) {
    const d = surface.derivatives(u, v, 2);
    const r = sub(d[0][0], p);
    const dist = Math.sqrt(dot(r, r));
    if (dist < best) {
      best = dist;
      bestUv = [u, v];
    }
    const [su, sv, suu, suv, svv] = [d[1][0], d[0][1], d[2][0], d[1][1], d[0][2]];
    const f = [dot(su, r), dot(sv, r)];
    const a = dot(su, su) + dot(suu, r);
    const b = dot(su, sv) + dot(suv, r);
    const c = dot(sv, sv) + dot(svv, r);
    const det = a * c - b * b;
    if (!(Math.abs(det) > 1e-300)) break;
    const nu = clamp(u - (c * f[0] - b * f[1]) / det, uRange);
    const nv = clamp(v - (a * f[1] - b * f[0]) / det, vRange);
    if (Math.abs(nu - u) + Math.abs(nv - v) < 1e-14) break;
    [u, v] = [nu, nv];
  }
  return [best, bestUv];
}

function nearestOnGrid(p) {
  let best = Infinity;
  let uv = grid[0].uv;
  for (const g of grid) {
    const r = sub(g.p, p);
    const d = dot(r, r);
    if (d < best) {
      best = d;
      uv = g.uv;
    }
  }
  return uv;
}

/**
 * Largest distance from the mesh to the surface: every vertex, and a
 * SAMPLE_STEPS barycentric grid on every triangle started from the
 * interpolated parameters of its corners.
 */
function measure(positions, triangles) {
  const corners = positions.map((p) => project(p, nearestOnGrid(p)));
  const vertexUv = corners.map(([, uv]) => uv);
  let max = corners.reduce((m, [d]) => Math.max(m, d), 0);
  const n = SAMPLE_STEPS;
  for (const [i, j, k] of triangles) {
    const [a, b, c] = [positions[i], positions[j], positions[k]];
    const [ua, ub, uc] = [vertexUv[i], vertexUv[j], vertexUv[k]];
    for (let s = 0; s <= n; s++) {
      for (let t = 0; s + t <= n; t++) {
        if ((s === 0 && t === 0) || s === n || t === n) continue; // corners are measured above
        const [wa, wb, wc] = [(n - s - t) / n, s / n, t / n];
        const p = [0, 1, 2].map((x) => wa * a[x] + wb * b[x] + wc * c[x]);
        const uv = [0, 1].map((x) => wa * ua[x] + wb * ub[x] + wc * uc[x]);
        max = Math.max(max, project(p, uv)[0]);
      }
    }
  }
  return max;
}

function median(xs) {
  const s = [...xs].sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
}

/** Median wall time of `f` over RUNS runs after one warm-up; returns [ms, last result]. */
function timed(f) {
  let result = f();
  const times = [];
  for (let r = 0; r < RUNS; r++) {
    const t0 = performance.now();
    result = f();
    times.push(performance.now() - t0);
  }
  return [median(times), result];
}

// ---- surfmesh ------------------------------------------------------------------------
const [smMs, sm] = timed(() => surfmesh.mesh(bytes, 'json', { toleranceRel: REL_TOL }));
const smPositions = [];
for (let i = 0; i < sm.positions.length; i += 3) smPositions.push([sm.positions[i], sm.positions[i + 1], sm.positions[i + 2]]);
const smTriangles = [];
for (let i = 0; i < sm.indices.length; i += 3) smTriangles.push([sm.indices[i], sm.indices[i + 1], sm.indices[i + 2]]);
const smDev = measure(smPositions, smTriangles);

// ---- verb: lower normTol until its measured deviation is no larger -------------------
const verbMesh = (normTol) => surface.tessellate({ normTol, minDivsU: 1, minDivsV: 1, maxDepth: 12, refine: true });
let normTol = 0.1;
let vm;
let vmDev;
for (let step = 0; step < 60; step++) {
  vm = verbMesh(normTol);
  vmDev = measure(vm.points, vm.faces);
  if (vmDev <= smDev) break;
  normTol *= 0.8;
}
const [vmMs] = timed(() => verbMesh(normTol));

// ---- report --------------------------------------------------------------------------
const fmt = (x, d = 4) => Number(x).toPrecision(d);
const rows = [
  ['setting', `toleranceRel ${REL_TOL}`, `normTol ${fmt(normTol, 3)}`, ''],
  ['triangles', sm.report.triangles, vm.faces.length, fmt(sm.report.triangles / vm.faces.length, 3)],
  ['measured max deviation (mm)', fmt(smDev), fmt(vmDev), fmt(smDev / vmDev, 3)],
  [`time, median of ${RUNS} (ms)`, fmt(smMs), fmt(vmMs), fmt(smMs / vmMs, 3)],
];
console.log(`Freeform patch ${file.slice(root.length + 1)}; surfmesh ${surfmesh.version()} (wasm, Node ${process.versions.node}) vs verb-nurbs ${require('verb-nurbs/package.json').version}`);
console.log(`surfmesh's own report: tolerance ${fmt(sm.report.tolerance)} mm, max_deviation ${fmt(sm.report.max_deviation)} mm\n`);
console.log('| | surfmesh | verb | surfmesh / verb |');
console.log('|---|---:|---:|---:|');
for (const r of rows) console.log(`| ${r.join(' | ')} |`);
if (vmDev > smDev) console.log(`\nverb did not reach surfmesh's deviation (stopped at normTol ${fmt(normTol, 3)})`);
