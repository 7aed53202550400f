// Tests of the built npm package (pkg/, from `npm run build`) through the
// real wasm-bindgen glue: every target of both builds loads and meshes, the
// package's export map resolves, a thrown Error carries exactly the command
// line's message, and the declarations are typed.
//
// Run: node --test scripts/pkg.test.mjs   (after `npm run build`)

import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, readFileSync, rmSync, symlinkSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { after, test } from 'node:test';
import { fileURLToPath } from 'node:url';
import { gzipSync } from 'node:zlib';
import { plateStep } from '../bench/plate.mjs';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const pkg = join(root, 'pkg');
const require = createRequire(import.meta.url);
const surfmesh = require(join(pkg, 'node'));
const freeform = readFileSync(join(root, 'tests', 'data', 'js_freeform.json'));
const scratch = mkdtempSync(join(tmpdir(), 'surfmesh-pkg-'));
after(() => rmSync(scratch, { recursive: true, force: true }));

/** A one-patch model with `patch` merged into its surface and `loops` on its face. */
function model(patch = {}, loops = []) {
  const points = [0, 1, 2, 3].map((i) => [0, 1, 2, 3].map((j) => [i, j, i % 3 && j % 3 ? 1 : 0]));
  const surface = { degree: [3, 3], knots: [[0, 0, 0, 0, 1, 1, 1, 1], [0, 0, 0, 0, 1, 1, 1, 1]], points, ...patch };
  return JSON.stringify({ units: 'mm', faces: [{ surface, loops }] });
}

function line(a, b) {
  return { degree: 1, knots: [0, 0, 1, 1], points: [a, b] };
}

const badInputs = {
  'malformed JSON': '{ "faces": [ { "surface": ',
  'knots too short': model({ knots: [[0, 0, 1, 1], [0, 0, 0, 0, 1, 1, 1, 1]] }),
  'decreasing knots': model({ knots: [[0, 0, 0, 0.6, 0.4, 1, 1, 1, 1], [0, 0, 0, 0, 1, 1, 1, 1]] }),
  'zero weight': model({ weights: [[1, 1, 1, 1], [1, 1, 0, 1], [1, 1, 1, 1], [1, 1, 1, 1]] }),
  'open loop': model({}, [
    {
      curves: [
        line([0.2, 0.2], [0.8, 0.2]),
        line([0.8, 0.2], [0.8, 0.8]),
        line([0.8, 0.9], [0.2, 0.8]),
        line([0.2, 0.8], [0.2, 0.2]),
      ],
    },
  ]),
};

/** The command line's one-line error for `text` saved as a .json file, without its "surfmesh: FILE: " prefix. */
function cliError(name, text) {
  const file = join(scratch, `${name.replace(/\W+/g, '_')}.json`);
  writeFileSync(file, text);
  const r = spawnSync('cargo', ['run', '--quiet', '--bin', 'surfmesh', '--', 'mesh', file], { cwd: root, encoding: 'utf8' });
  assert.notEqual(r.status, 0, `the CLI accepted ${name}`);
  const lines = r.stderr.trim().split('\n');
  const last = lines[lines.length - 1];
  const prefix = `surfmesh: ${file}: `;
  assert.ok(last.startsWith(prefix), `unexpected CLI error line: ${last}`);
  return last.slice(prefix.length);
}

test('the Node build meshes the bundled freeform surface within its tolerance', () => {
  const out = surfmesh.mesh(freeform, 'auto', { toleranceRel: 1e-3, flatten: true });
  assert.ok(out.positions instanceof Float32Array);
  assert.ok(out.normals instanceof Float32Array);
  assert.ok(out.indices instanceof Uint32Array);
  assert.ok(out.faceRanges instanceof Uint32Array);
  const { report } = out;
  assert.equal(out.positions.length, 3 * report.vertices);
  assert.equal(out.indices.length, 3 * report.triangles);
  assert.deepEqual([...out.faceRanges], [0, report.triangles]);
  assert.ok(report.max_deviation <= report.tolerance, `${report.max_deviation} > ${report.tolerance}`);
  assert.ok(report.time_ms > 0 && report.parse_ms >= 0, 'the binding fills in the times');
  assert.match(surfmesh.version(), /^\d+\.\d+\.\d+$/);
});

test('a part of 1006 faces, two of them with 1000 holes each, meshes closed and within tolerance', (t) => {
  const bytes = new TextEncoder().encode(plateStep(25, 40));
  const before = surfmesh.memoryBytes();
  const out = surfmesh.mesh(bytes, 'step', { toleranceRel: 1e-3, flatten: true });
  const { report } = out;
  assert.equal(report.faces, 1006);
  assert.equal(out.faceRanges.length, 2 * 1006);
  for (let f = 0; f < 1006; f += 1) assert.ok(out.faceRanges[2 * f + 1] > 0, `face ${f} has no triangles`);
  assert.equal(report.faces_skipped, 0);
  assert.equal(report.free_edges, 0, 'cracks');
  assert.equal(report.boundary_edges, 0, 'a closed solid has no border');
  assert.equal(report.nonmanifold_edges, 0);
  assert.equal(report.inverted_triangles, 0);
  assert.ok(report.max_deviation <= report.tolerance, `${report.max_deviation} > ${report.tolerance}`);
  const output = out.positions.byteLength + out.normals.byteLength + out.indices.byteLength;
  t.diagnostic(`${report.triangles} triangles; wasm memory ${surfmesh.memoryBytes()} bytes (before ${before}), output ${output}`);
});

test('a fresh module holds its 256 KiB stack, not the default 1 MiB, before its first call', () => {
  const r = spawnSync(process.execPath, ['-e', `process.stdout.write(String(require(${JSON.stringify(join(pkg, 'node'))}).memoryBytes()))`], {
    encoding: 'utf8',
  });
  assert.equal(r.status, 0, r.stderr);
  const bytes = Number(r.stdout);
  // Stack, static data and the allocator's first pages (wasm-pack.toml stack_size).
  assert.ok(bytes >= 262144 && bytes < 1 << 20, `${bytes} bytes at load`);
});

// Issue 37 wants the viewer module under 400 KB gzip -9; this is a ratchet
// on the way there, set just above the size measured when it last dropped
// (main at e3415cb: 672,275 bytes), so that new code that brings bloat back
// (a dependency, a generic's copies, formatting) shows here. Lower it as
// the module shrinks. Raised from 655,000 when mending gained the joint
// resettling of a sliver's nodes and the inner corner's move for a border
// split, the fit check its borrowed steps, and sewing a bound on halving
// crossing chords: 657,720 bytes, 655,216 once a list-of-lists sort they
// brought went through the shared triple sort. Raised again when the
// edge census learned faces' borders, sewing kept a thin wall's skins
// apart, the trim crossing grid nested crowded cells and rebuilt faces kept
// their grid samples: 663,835 bytes. Raised when wasm's tensor-product
// sums went to SIMD lanes (+2,584 bytes, the sums inlined into each degree's
// evaluation) and the STEP reader kept its trim-fit points and borrowed
// keywords (+1,893): 668,312 bytes.
const VIEWER_GZIP_BUDGET = 670_000;

test('the viewer module stays within its gzip -9 budget', () => {
  const wasm = readFileSync(join(pkg, 'node', 'surfmesh_bg.wasm'));
  const gzipped = gzipSync(wasm, { level: 9 }).length;
  assert.ok(gzipped <= VIEWER_GZIP_BUDGET, `${gzipped} bytes gzipped, budget ${VIEWER_GZIP_BUDGET}`);
});

test('thrown errors are Error objects with exactly the command line message', () => {
  for (const [name, text] of Object.entries(badInputs)) {
    const expected = cliError(name, text);
    assert.throws(
      () => surfmesh.mesh(new TextEncoder().encode(text), 'json', {}),
      (e) => e instanceof Error && e.message === expected,
      `${name}: expected ${JSON.stringify(expected)}`,
    );
  }
  assert.throws(() => surfmesh.mesh(freeform, 'json', { maxEdge: 'long' }), /^Error: option maxEdge: expected a number/);
});

test('the package export map serves the Node build to require and import, and the web build at surfmesh/web', () => {
  const app = join(scratch, 'app');
  mkdirSync(join(app, 'node_modules'), { recursive: true });
  symlinkSync(pkg, join(app, 'node_modules', 'surfmesh'), 'dir');
  const data = JSON.stringify(join(root, 'tests', 'data', 'js_freeform.json'));
  const script = `
    import { readFileSync } from 'node:fs';
    import { createRequire } from 'node:module';
    import { mesh } from 'surfmesh';
    import init, { mesh as webMesh } from 'surfmesh/web';
    const cjs = createRequire(import.meta.url)('surfmesh');
    const bytes = readFileSync(${data});
    await init({ module_or_path: readFileSync(${JSON.stringify(join(pkg, 'web', 'surfmesh_bg.wasm'))}) });
    const counts = [mesh(bytes, 'json').report.triangles, cjs.mesh(bytes, 'json').report.triangles, webMesh(bytes, 'json').report.triangles];
    console.log(JSON.stringify({ same: cjs.mesh === mesh, counts }));
  `;
  writeFileSync(join(app, 'main.mjs'), script);
  const r = spawnSync(process.execPath, [join(app, 'main.mjs')], { cwd: app, encoding: 'utf8' });
  assert.equal(r.status, 0, r.stderr);
  const { same, counts } = JSON.parse(r.stdout);
  assert.ok(same, 'require and import should load the same Node module');
  assert.ok(counts[0] > 0 && counts.every((c) => c === counts[0]), `triangle counts differ: ${counts}`);
});

test('the bundler build loads as an ES module that imports its .wasm', () => {
  const script = `
    import { readFileSync } from 'node:fs';
    import { mesh } from ${JSON.stringify(join(pkg, 'bundler', 'surfmesh.js'))};
    console.log(mesh(readFileSync(${JSON.stringify(join(root, 'tests', 'data', 'js_freeform.json'))}), 'json').report.triangles);
  `;
  const file = join(scratch, 'bundler.mjs');
  writeFileSync(file, script);
  const r = spawnSync(process.execPath, ['--experimental-wasm-modules', '--no-warnings', file], { encoding: 'utf8' });
  assert.equal(r.status, 0, r.stderr);
  assert.equal(Number(r.stdout.trim()), surfmesh.mesh(freeform, 'json').report.triangles);
});

test('an assembly meshed in shares of its parts merges into the whole mesh', async () => {
  const { mergeShares } = await import(join(root, 'www', 'js', 'pool.js'));
  const bytes = readFileSync(join(root, 'tests', 'data', 'step_assembly.stp'));
  const options = { toleranceRel: 1e-3, flatten: true };
  const whole = surfmesh.mesh(bytes, 'step', options);
  assert.equal(whole.report.bodies, 2);
  const none = { wire: new Uint32Array(), borders: new Float32Array(), open: new Float32Array() };
  const shares = [0, 1].map((i) => ({ result: surfmesh.mesh(bytes, 'step', { ...options, share: [i, 2] }), lines: none }));
  // The two blocks are one part placed twice: it is meshed in one share, which
  // places both copies; the other share has no part of its own.
  const counts = shares.map(({ result }) => result.report.triangles).sort((a, b) => a - b);
  assert.deepEqual(counts, [0, whole.report.triangles]);
  const { result } = mergeShares(shares);
  // Bodies share no border: each face meshes as in the whole model, and the merge keeps face order.
  assert.deepEqual(result.faceRanges, whole.faceRanges);
  assert.deepEqual(result.indices, whole.indices);
  assert.deepEqual(result.positions, whole.positions);
  assert.deepEqual(result.normals, whole.normals);
  assert.deepEqual(result.faceParts, whole.faceParts);
  for (const key of ['triangles', 'vertices', 'free_edges', 'boundary_edges', 'inverted_triangles', 'max_deviation']) {
    assert.equal(result.report[key], whole.report[key], key);
  }
  assert.ok(Math.abs(result.report.mean_deviation - whole.report.mean_deviation) <= 1e-9 * whole.report.tolerance);
  assert.throws(() => surfmesh.mesh(bytes, 'step', { share: [2, 2] }), /option share: expected \[index, count\]/);
  assert.throws(() => surfmesh.mesh(bytes, 'step', { share: [0, 2], mode: 'quality' }), /option share: meshes fast mode only/);
});

test('the page draws placed parts as instances that match the flattened mesh vertex for vertex', async () => {
  const { flattened } = await import(join(root, 'www', 'js', 'instanced.js'));
  const bytes = readFileSync(join(root, 'tests', 'data', 'step_assembly.stp'));
  const whole = surfmesh.mesh(bytes, 'step', { toleranceRel: 1e-3, flatten: true });
  const page = flattened(surfmesh.mesh(bytes, 'step', { toleranceRel: 1e-3 }));
  // One block placed twice: one part mesh, two instances.
  assert.equal(page.instanced.meshes.length, 1);
  assert.equal(page.instanced.instances.length, 2);
  assert.equal(page.faceRanges.length, whole.faceRanges.length);
  assert.equal(page.indices.length, whole.indices.length);
  // The page's faces go instance after instance; the binding's in the file's
  // order, faceParts naming each face's instance. Face j of instance k is the
  // j-th face of k in the file's order.
  const starts = [0];
  for (const inst of page.instanced.instances) starts.push(starts.at(-1) + page.instanced.meshes[inst.part].faceRanges.length / 2);
  const seen = new Array(page.instanced.instances.length).fill(0);
  const corners = (r, f) => {
    const out = [];
    for (let k = 3 * r.faceRanges[2 * f]; k < 3 * (r.faceRanges[2 * f] + r.faceRanges[2 * f + 1]); k++) {
      const v = r.indices[k];
      out.push([r.positions[3 * v], r.positions[3 * v + 1], r.positions[3 * v + 2]]);
    }
    return out;
  };
  const size = Math.max(...whole.positions.map(Math.abs));
  for (let f = 0; f < whole.faceRanges.length / 2; f++) {
    const k = whole.faceParts[f];
    const g = starts[k] + seen[k]++;
    assert.equal(page.faceParts[g], k);
    const [a, b] = [corners(whole, f), corners(page, g)];
    assert.equal(a.length, b.length, `face ${f}`);
    // The same triangles, each corner the same point to float precision (the
    // binding moves f64 points, the page the f32 ones).
    a.forEach((p, i) => p.forEach((x, c) => assert.ok(Math.abs(x - b[i][c]) <= 1e-6 * size, `face ${f} corner ${i}: ${x} vs ${b[i][c]}`)));
  }
  // A one-instance model is its part's mesh, no copy made and nothing to instance.
  const single = surfmesh.mesh(freeform, 'json', {});
  const flat = flattened(single);
  assert.equal(flat.instanced, null);
  assert.equal(flat.positions, single.meshes[0].positions);
});

test('the viewer build meshes; repair, fit and quality mode are the full build\'s, at surfmesh/full', () => {
  assert.equal(surfmesh.repair, undefined);
  assert.equal(surfmesh.fit, undefined);
  assert.throws(() => surfmesh.mesh(freeform, 'json', { mode: 'quality' }), /quality/);
  const full = require(join(pkg, 'full', 'node'));
  const q = full.mesh(freeform, 'json', { mode: 'quality', flatten: true });
  assert.ok(q.report.quality.good_angle_fraction > 0.9);
  const stl = `solid t
facet normal 0 0 1
outer loop
vertex 0 0 0
vertex 1 0 0
vertex 0 1 0
endloop
endfacet
endsolid t
`;
  assert.throws(() => full.repair(new TextEncoder().encode(stl), 'stl', { bucketing: 'grid' }), /^Error: option bucketing: expected "kd" or "bvh"$/);
  // The same mesh from both builds.
  assert.equal(full.mesh(freeform, 'json').report.triangles, surfmesh.mesh(freeform, 'json').report.triangles);
  const manifest = JSON.parse(readFileSync(join(pkg, 'package.json'), 'utf8'));
  for (const sub of ['.', './web', './full', './full/web', './three']) assert.ok(manifest.exports[sub], `exports ${sub}`);
});

test('the default result: each distinct part once, its copies as instances, the tree, edges beside the meshes', () => {
  const bytes = readFileSync(join(root, 'tests', 'data', 'step_assembly.stp'));
  const out = surfmesh.mesh(bytes, 'step', { toleranceRel: 1e-3 });
  assert.equal(out.meshes.length, 1);
  assert.deepEqual(out.instances.map((i) => i.part), [0, 0]);
  assert.equal(out.tree.name, 'Assembly');
  assert.deepEqual(out.tree.children.map((c) => c.occurrence), ['Block instance 1', 'Block instance 2']);
  const [part] = out.meshes;
  assert.ok(part.edges instanceof Float32Array && part.edgeRanges instanceof Uint32Array);
  // Every edge point is a vertex of the part's mesh.
  const vertices = new Set();
  for (let v = 0; v < part.positions.length; v += 3) vertices.add(`${part.positions[v]},${part.positions[v + 1]},${part.positions[v + 2]}`);
  for (let p = 0; p < part.edges.length; p += 3) assert.ok(vertices.has(`${part.edges[p]},${part.edges[p + 1]},${part.edges[p + 2]}`));
  // The report counts both copies, as the flattened mesh does.
  assert.equal(out.report.triangles, 2 * part.indices.length / 3);
});

test('the declarations are typed: options and results are interfaces, not any', () => {
  for (const dir of ['web', 'node', 'bundler', join('full', 'web')]) {
    const dts = readFileSync(join(pkg, dir, 'surfmesh.d.ts'), 'utf8');
    for (const name of ['MeshOptions', 'Report', 'MeshOutput', 'FlatMeshOutput', 'AssemblyNode', 'PartInstance']) {
      assert.match(dts, new RegExp(`export interface ${name} `), `${dir}: interface ${name}`);
    }
    assert.match(dts, /export function mesh\(bytes: Uint8Array, format: string, options\?: MeshOptions\): MeshOutput;/);
    assert.doesNotMatch(dts, /export function (mesh|meshWithProgress|repair|fit)\([^)]*\bany\b/, `${dir}: an export takes any`);
    assert.equal(/export function repair\(/.test(dts), dir.startsWith('full'), `${dir}: repair only in the full build`);
  }
});
