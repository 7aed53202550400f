// The meshing worker: loads the wasm module (compiled once and posted here,
// so a respawn after cancel() only instantiates it), meshes one
// model per request with progress events, and posts the arrays back as
// transferred buffers (no copy). It also derives the line sets the viewer
// draws, so the page's thread only uploads buffers:
//   wire:    vertex index pairs, one per mesh edge (the wireframe overlay),
//   borders: segments where a model face ends (edges of one triangle of that face),
//   open:    edges with one triangle after welding coincident vertices across
//            faces — the model's open border plus any crack.
//
// The page's first worker boots itself instead ({ type: 'boot', wasm, sample, id, options }):
// it fetches and compiles the module, posts it back for the other workers, and
// meshes the default sample from its own fetch, so the first mesh never waits
// for the page's thread (busy parsing three.js while this runs).
//
// The full build is imported on the first quality-mode or repair request.
//
// Messages in:  { type: 'init', module } | { type: 'boot', wasm, sample?, id, options }
//               then { type: 'mesh', id, bytes, format, options }; with options.repair
//               (the repair options) the mesh in `bytes` (STL or OBJ) is repaired instead
// Messages out: { type: 'module', module } | { type: 'module', error } (after boot) | { type: 'ready' } | { type: 'fatal', message }
//               { type: 'progress', id, done, total }
//               { type: 'result', id, result, lines: { wire, borders, open } }
//               { type: 'error', id, message }

import init, { meshWithProgress, version } from '../pkg/web/surfmesh.js';
import { flattened } from './instanced.js';

// The package's full build (surfmesh/full), loaded the first time a request
// needs what only it has (quality mode, repair); the viewer build does the rest.
let full = null;
function fullBuild() {
  full ??= import('../pkg/full/web/surfmesh.js').then(async (m) => {
    await m.default();
    return m;
  });
  return full;
}

// Settles when the module is loaded: to null, or to the reason it could not load.
// A request that arrives first waits for it.
let settleLoad;
const loaded = new Promise((resolve) => {
  settleLoad = resolve;
});

/** Instantiates `module` (a promise of it); posts 'ready' or 'fatal'. */
function load(module) {
  module
    .then((m) => init({ module_or_path: m }))
    .then(
      () => {
        self.postMessage({ type: 'ready', version: version() });
        settleLoad(null);
      },
      (e) => {
        const message = `cannot load the wasm module: ${e.message ?? e}`;
        self.postMessage({ type: 'fatal', message });
        settleLoad(message);
      },
    );
}

self.onmessage = async (event) => {
  const msg = event.data;
  if (msg.type === 'init') {
    load(Promise.resolve(msg.module));
    return;
  }
  if (msg.type === 'boot') {
    const module = WebAssembly.compileStreaming(fetch(msg.wasm));
    module.then(
      (m) => self.postMessage({ type: 'module', module: m }),
      (e) => self.postMessage({ type: 'module', error: String(e.message ?? e) }),
    );
    load(module);
    if (!msg.sample) return;
    let bytes;
    try {
      const response = await fetch(msg.sample);
      if (!response.ok) throw new Error(`HTTP ${response.status}`);
      bytes = await response.arrayBuffer();
    } catch (e) {
      self.postMessage({ type: 'error', id: msg.id, message: `cannot fetch ${msg.sample}: ${e.message ?? e}` });
      return;
    }
    run(msg.id, bytes, 'json', msg.options);
    return;
  }
  if (msg.type === 'mesh') run(msg.id, msg.bytes, msg.format, msg.options);
};

/** Meshes one request once the module is loaded; posts its result or error. */
async function run(id, bytes, format, options) {
  const failure = await loaded;
  if (failure) {
    self.postMessage({ type: 'error', id, message: failure });
    return;
  }
  let result;
  try {
    if (options?.repair) {
      // Repair is the full build's: the mesh in `bytes` made closed and free of self-intersections.
      const { repair, version: fullVersion } = await fullBuild();
      result = repaired(repair(new Uint8Array(bytes), format, options.repair), fullVersion());
    } else {
      // Each distinct part meshed once, placed by its instances; quality mode is the full build's.
      const build = options?.mode === 'quality' ? await fullBuild() : { meshWithProgress };
      const out = build.meshWithProgress(new Uint8Array(bytes), format, { ...options, flatten: false }, (done, total) => {
        self.postMessage({ type: 'progress', id, done, total });
      });
      result = flattened(out);
    }
  } catch (e) {
    self.postMessage({ type: 'error', id, message: e instanceof Error ? e.message : String(e) });
    return;
  }
  const lines = edgeLines(result);
  const arrays = [result.positions, result.normals, result.indices, result.faceRanges, lines.wire, lines.borders, lines.open];
  for (const m of result.instanced?.meshes ?? []) arrays.push(m.positions, m.normals, m.indices, m.faceRanges);
  // A buffer is listed once (a single instance's arrays are the part's own).
  self.postMessage({ type: 'result', id, result, lines }, [...new Set(arrays.map((a) => a.buffer))]);
}

/**
 * A repair result in the shape of a mesh result: one face, vertex normals
 * (area-weighted means of the triangles'), and the repair report with the
 * full build's version.
 */
function repaired({ positions, indices, report }, version) {
  const normals = new Float32Array(positions.length);
  for (let t = 0; t < indices.length; t += 3) {
    const [a, b, c] = [3 * indices[t], 3 * indices[t + 1], 3 * indices[t + 2]];
    const u = [positions[b] - positions[a], positions[b + 1] - positions[a + 1], positions[b + 2] - positions[a + 2]];
    const v = [positions[c] - positions[a], positions[c + 1] - positions[a + 1], positions[c + 2] - positions[a + 2]];
    const n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    for (const i of [a, b, c]) for (let k = 0; k < 3; k++) normals[i + k] += n[k];
  }
  for (let i = 0; i < normals.length; i += 3) {
    const len = Math.hypot(normals[i], normals[i + 1], normals[i + 2]) || 1;
    for (let k = 0; k < 3; k++) normals[i + k] /= len;
  }
  const faceRanges = new Uint32Array([0, indices.length / 3]);
  return { positions, normals, indices, faceRanges, report: { ...report, build: `full ${version}` } };
}

/** Wireframe index pairs, and face-border and open-edge segments (x, y, z pairs), of a mesh. */
function edgeLines({ positions, indices, faceRanges }) {
  // Weld: one id per distinct position (sewing makes shared borders coincide exactly).
  const weld = new Uint32Array(positions.length / 3);
  const ids = new Map();
  for (let v = 0; v < weld.length; v++) {
    const key = `${positions[3 * v]},${positions[3 * v + 1]},${positions[3 * v + 2]}`;
    let id = ids.get(key);
    if (id === undefined) {
      id = ids.size;
      ids.set(key, id);
    }
    weld[v] = id;
  }
  const n = ids.size;
  const faceOf = new Uint32Array(indices.length / 3);
  for (let f = 0; 2 * f + 1 < faceRanges.length; f++) {
    faceOf.fill(f, faceRanges[2 * f], faceRanges[2 * f] + faceRanges[2 * f + 1]);
  }
  // Per welded edge: how many triangles use it, the first user's face, whether
  // two different faces use it, and one (unwelded) vertex pair to draw.
  const edges = new Map();
  for (let t = 0; t < indices.length / 3; t++) {
    for (let k = 0; k < 3; k++) {
      const a = indices[3 * t + k];
      const b = indices[3 * t + ((k + 1) % 3)];
      const wa = weld[a];
      const wb = weld[b];
      const key = wa < wb ? wa * n + wb : wb * n + wa;
      const e = edges.get(key);
      if (e === undefined) edges.set(key, { uses: 1, face: faceOf[t], faces: 1, a, b });
      else {
        e.uses++;
        if (e.face !== faceOf[t]) e.faces = 2;
      }
    }
  }
  const wire = new Uint32Array(2 * edges.size);
  const borders = [];
  const open = [];
  let w = 0;
  const push = (out, a, b) => {
    out.push(positions[3 * a], positions[3 * a + 1], positions[3 * a + 2]);
    out.push(positions[3 * b], positions[3 * b + 1], positions[3 * b + 2]);
  };
  for (const e of edges.values()) {
    wire[w++] = e.a;
    wire[w++] = e.b;
    if (e.uses === 1) push(open, e.a, e.b);
    if (e.uses === 1 || e.faces > 1) push(borders, e.a, e.b);
  }
  return { wire, borders: new Float32Array(borders), open: new Float32Array(open) };
}
