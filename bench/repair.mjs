// Mesh repair (paper 002) in wasm: the package's `repair` (Node build in
// pkg/node, from `node scripts/build-wasm.mjs`) on the self-intersecting
// offset meshes of benches/repair.rs: a wavy torus grid of 15k and 250k
// triangles, offset inward by 1.5 with the package's `offset`. Prints one
// JSON line per case and bucketing: triangles in/out, segments, the report's
// stage times of the fastest run, and every run's wall time.
//
//   node bench/repair.mjs [--runs N] [--sizes 15k,250k]

import { createRequire } from 'node:module';
import { dirname, join } from 'node:path';
import { performance } from 'node:perf_hooks';
import { fileURLToPath } from 'node:url';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const require = createRequire(import.meta.url);
const surfmesh = require(join(root, 'pkg', 'node'));

const args = process.argv.slice(2);
const arg = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 ? args[i + 1] : fallback;
};
const RUNS = Math.max(1, Number(arg('--runs', 3)));
const SIZES = { '15k': [122, 62], '250k': [500, 250] };
const wanted = arg('--sizes', '15k,250k').split(',');

/** The wavy torus of benches/repair.rs as OBJ text: nu × nv quads, two triangles each. */
function wavyTorusObj(nu, nv) {
  const lines = [];
  for (let i = 0; i < nu; i++) {
    const u = (2 * Math.PI * i) / nu;
    const ripple = 1 + 0.15 * Math.sin(5 * u);
    for (let j = 0; j < nv; j++) {
      const v = (2 * Math.PI * j) / nv;
      const r = 20 + 5 * ripple * Math.cos(v);
      lines.push(`v ${r * Math.cos(u)} ${r * Math.sin(u)} ${2 * ripple * Math.sin(v)}`);
    }
  }
  const id = (i, j) => (i % nu) * nv + (j % nv) + 1;
  for (let i = 0; i < nu; i++) {
    for (let j = 0; j < nv; j++) {
      const [a, b, c, d] = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
      lines.push(`f ${a} ${b} ${c}`, `f ${a} ${c} ${d}`);
    }
  }
  return new TextEncoder().encode(lines.join('\n') + '\n');
}

/** Binary STL of positions (Float32Array, xyz) and indices (Uint32Array). */
function stl(positions, indices) {
  const n = indices.length / 3;
  const buf = new ArrayBuffer(84 + 50 * n);
  const view = new DataView(buf);
  view.setUint32(80, n, true);
  let o = 84;
  for (let t = 0; t < n; t++) {
    o += 12; // facet normal: left zero, readers ignore it
    for (let k = 0; k < 3; k++) {
      const v = indices[3 * t + k];
      for (let c = 0; c < 3; c++, o += 4) view.setFloat32(o, positions[3 * v + c], true);
    }
    o += 2;
  }
  return new Uint8Array(buf);
}

for (const size of wanted) {
  const [nu, nv] = SIZES[size];
  const off = surfmesh.offset(wavyTorusObj(nu, nv), 'obj', -1.5);
  const input = stl(off.positions, off.indices);
  for (const bucketing of ['kd', 'bvh']) {
    const times = [];
    let best = null;
    for (let r = 0; r < RUNS + 1; r++) {
      const t0 = performance.now();
      const out = surfmesh.repair(input, 'stl', { bucketing });
      const ms = performance.now() - t0;
      if (r === 0) continue; // warm-up: compilation and first-touch memory
      times.push(ms);
      if (!best || ms < best.ms) best = { ms, report: out.report };
    }
    const rep = best.report;
    console.log(
      JSON.stringify({
        size,
        bucketing,
        triangles_in: rep.triangles_in,
        triangles_out: rep.triangles_out,
        segments: rep.segments,
        regions: rep.regions,
        census_out: rep.census_out,
        time_ms: rep.time_ms,
        parse_ms: rep.parse_ms,
        wall_ms: times.map((t) => Math.round(t)),
      }),
    );
  }
}
