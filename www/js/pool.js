// A small pool of meshing workers (worker.js). The wasm module is compiled
// once here and posted to each worker, so a worker that cancel() ends is
// replaced at the cost of an instantiation. A job runs on an idle worker
// (queued when none is idle) and resolves to
//   { result: { positions, normals, indices, faceRanges, report }, lines: { borders, open } }
// or rejects with an Error carrying the module's message; cancel() rejects it
// with an Error whose message is "cancelled" and stops the work at once
// (the worker is terminated: wasm cannot be interrupted mid-face otherwise).
//
// A model of several bodies (the solids and parts of an assembly) can be
// split across workers with meshShared(): each worker meshes the bodies of
// its share (the module's `share` option), and the results are merged in face
// order. Bodies share no border, so that is the whole model's mesh. Faces of
// one body are sewn together inside one call and always mesh in one worker.

export class MeshPool {
  /**
   * @param {object} o
   * @param {number} [o.size] workers (default 2: a preview and a full mesh at once)
   * @param {URL|string} [o.wasmUrl] the package's surfmesh_bg.wasm
   * @param {Promise<WebAssembly.Module>} [o.module] the module, already compiling (else from wasmUrl)
   * @param {URL|string} o.workerUrl worker.js
   * @param {{ worker: Worker, early: object[], job?: { id: number, options: object } }[]} [o.workers]
   *   workers already started (and sent the module) by the page, with the messages they posted
   *   before the pool took them over and the job each was already sent (negative ids), if any
   */
  constructor({ size = 2, wasmUrl, module, workerUrl, workers = [] }) {
    this.size = Math.max(1, size, workers.length);
    this.workerUrl = workerUrl;
    this.module = module ?? WebAssembly.compileStreaming(fetch(wasmUrl));
    this.slots = [];
    this.queue = [];
    this.nextId = 1;
    this.version = null;
    this.prestarted = [];
    this.error = null;
    for (const { worker, early, job } of workers) this.slots.push(this.#adopt(worker, early, job));
    while (this.slots.length < this.size) this.slots.push(this.#spawn());
  }

  /**
   * The jobs the page started before the pool existed, as { options, job } with job like
   * mesh() returns; each is handed out once.
   */
  takePrestarted() {
    return this.prestarted.splice(0);
  }

  /** Resolves once every current worker has loaded the module (rejects if one cannot). */
  async ready() {
    for (;;) {
      const slots = [...this.slots];
      await Promise.all(slots.map((s) => s.ready));
      if (slots.every((s, i) => this.slots[i] === s)) return;
      // A worker was replaced (cancel) meanwhile: wait for its successor too.
    }
  }

  /**
   * Meshes `bytes` (ArrayBuffer or typed array; copied to the worker) in `format` with `options`.
   * `onProgress(done, total)` follows the faces. Returns { promise, cancel }.
   */
  mesh(bytes, format, options, onProgress = () => {}) {
    const job = this.#job(this.nextId++, options, onProgress);
    job.bytes = bytes;
    job.format = format;
    this.queue.push(job);
    this.#dispatch();
    return job;
  }

  /**
   * As mesh(), split by bodies over `count` workers (at most the pool's size;
   * quality mode is never split) and merged with mergeShares(). Progress is
   * that of the least advanced share still running.
   */
  meshShared(bytes, format, options, count, onProgress = () => {}) {
    const n = Math.min(count, this.size);
    if (n <= 1 || options.mode === 'quality') return this.mesh(bytes, format, options, onProgress);
    const done = new Array(n).fill(0);
    const running = new Array(n).fill(true);
    let total = 0;
    const report = () => {
      const left = done.filter((_, i) => running[i]);
      if (left.length > 0) onProgress(Math.min(...left), total);
    };
    const parts = Array.from({ length: n }, (_, i) =>
      this.mesh(bytes, format, { ...options, share: [i, n] }, (d, t) => {
        done[i] = d;
        total = t;
        report();
      }),
    );
    parts.forEach((p, i) => p.promise.then(() => ((running[i] = false), report()), () => {}));
    const cancel = () => parts.forEach((p) => p.cancel());
    const promise = Promise.all(parts.map((p) => p.promise)).then(mergeShares, (e) => {
      cancel();
      throw e;
    });
    // The page replaces onProgress after the call, as with mesh().
    return {
      promise,
      cancel,
      get onProgress() {
        return onProgress;
      },
      set onProgress(f) {
        onProgress = f;
      },
    };
  }

  #job(id, options, onProgress) {
    const job = { id, options, onProgress, slot: null, settled: false };
    job.promise = new Promise((resolve, reject) => {
      job.resolve = resolve;
      job.reject = reject;
    });
    job.cancel = () => this.#cancel(job);
    return job;
  }

  /** Cancels every queued and running job. */
  cancelAll() {
    for (const job of [...this.queue, ...this.slots.map((s) => s.job).filter(Boolean)]) this.#cancel(job);
  }

  #spawn() {
    const worker = new Worker(this.workerUrl, { type: 'module' });
    const slot = this.#adopt(worker, []);
    this.module.then(
      (module) => worker.postMessage({ type: 'init', module }),
      (e) => this.#fail(slot, new Error(`cannot compile the wasm module: ${e.message}`)),
    );
    return slot;
  }

  /** A slot for `worker` (busy with `started` if given), replaying the messages it posted before it had a handler. */
  #adopt(worker, early, started) {
    const slot = { worker, job: null, ready: null };
    if (started) {
      const job = this.#job(started.id, started.options, () => {});
      job.slot = slot;
      slot.job = job;
      this.prestarted.push({ options: started.options, job });
    }
    slot.ready = new Promise((resolve, reject) => {
      slot.onReady = resolve;
      slot.onFatal = reject;
    });
    slot.ready.catch(() => {}); // reported through ready() and the jobs
    worker.onmessage = (event) => this.#receive(slot, event.data);
    worker.onerror = (event) => {
      event.preventDefault?.();
      this.#fail(slot, new Error(`meshing worker failed: ${event.message ?? 'cannot start worker.js'}`));
    };
    for (const msg of early) this.#receive(slot, msg);
    this.module.catch((e) => this.#fail(slot, new Error(`cannot compile the wasm module: ${e.message}`)));
    return slot;
  }

  #receive(slot, msg) {
    if (msg.type === 'ready') {
      this.version = msg.version;
      slot.onReady();
      return;
    }
    if (msg.type === 'fatal') {
      this.#fail(slot, new Error(msg.message));
      return;
    }
    const job = slot.job;
    if (!job || job.id !== msg.id) return;
    if (msg.type === 'progress') {
      job.onProgress(msg.done, msg.total);
      return;
    }
    slot.job = null;
    job.settled = true;
    if (msg.type === 'result') job.resolve({ result: msg.result, lines: msg.lines });
    else job.reject(new Error(msg.message));
    this.#dispatch();
  }

  /** A worker that cannot mesh: its job and the queue fail with `error`, and it gets no more jobs. */
  #fail(slot, error) {
    slot.onFatal(error);
    slot.error = error;
    this.error ??= error; // the first reason a worker could not start
    const job = slot.job;
    slot.job = null;
    if (job && !job.settled) {
      job.settled = true;
      job.reject(error);
    }
    for (const queued of this.queue.splice(0)) {
      queued.settled = true;
      queued.reject(error);
    }
  }

  #dispatch() {
    const broken = this.slots.find((s) => s.error);
    if (broken && this.slots.every((s) => s.error)) {
      for (const queued of this.queue.splice(0)) {
        queued.settled = true;
        queued.reject(broken.error);
      }
    }
    for (const slot of this.slots) {
      if (slot.job || slot.error || this.queue.length === 0) continue;
      const job = this.queue.shift();
      slot.job = job;
      job.slot = slot;
      const bytes = job.bytes instanceof ArrayBuffer ? job.bytes.slice(0) : job.bytes.slice().buffer;
      slot.worker.postMessage({ type: 'mesh', id: job.id, bytes, format: job.format, options: job.options }, [bytes]);
    }
  }

  #cancel(job) {
    if (job.settled) return;
    job.settled = true;
    const queued = this.queue.indexOf(job);
    if (queued >= 0) this.queue.splice(queued, 1);
    const slot = job.slot;
    if (slot && slot.job === job) {
      slot.worker.terminate();
      slot.onReady(); // settles waiters on the old worker; ready() moves on to its successor
      const fresh = this.#spawn();
      this.slots[this.slots.indexOf(slot)] = fresh;
    }
    job.reject(new Error('cancelled'));
    this.#dispatch();
  }
}

/**
 * One result from the results of a model's shares ({ result, lines } each, as
 * a job resolves): every face's triangles and vertices from the share that
 * meshed it, in face order, so faceRanges stay sorted; the line sets joined;
 * the report's counts summed, its extremes the extremes, its mean deviation
 * weighted by triangles (the 1st-percentile angle is the smallest share's).
 */
export function mergeShares(parts) {
  const results = parts.map((p) => p.result);
  const first = results[0];
  const { positions, normals, indices, faceRanges, remap, triangles, vertices } = mergeFaces(results);
  const wire = [];
  parts.forEach((p, s) => {
    const w = p.lines.wire;
    for (let k = 0; k + 1 < w.length; k += 2) {
      const [a, c] = [remap[s][w[k]], remap[s][w[k + 1]]];
      if (a >= 0 && c >= 0) wire.push(a, c);
    }
  });
  const join = (key) => {
    const out = new Float32Array(parts.reduce((n, p) => n + p.lines[key].length, 0));
    let at = 0;
    for (const p of parts) {
      out.set(p.lines[key], at);
      at += p.lines[key].length;
    }
    return out;
  };
  const reps = results.map((r) => r.report);
  const sum = (k) => reps.reduce((a, r) => a + (r[k] ?? 0), 0);
  const max = (k) => Math.max(...reps.map((r) => r[k] ?? 0));
  const meshed = reps.filter((r) => r.triangles > 0);
  const min = (k) => (meshed.length ? Math.min(...meshed.map((r) => r[k])) : first.report[k]);
  const report = {
    ...first.report,
    faces_skipped: sum('faces_skipped'),
    faces_tessellated: sum('faces_tessellated'),
    triangles,
    vertices,
    max_deviation: max('max_deviation'),
    mean_deviation: triangles > 0 ? reps.reduce((a, r) => a + r.mean_deviation * r.triangles, 0) / triangles : 0,
    min_angle_deg: min('min_angle_deg'),
    p1_angle_deg: min('p1_angle_deg'),
    free_edges: sum('free_edges'),
    boundary_edges: sum('boundary_edges'),
    nonmanifold_edges: sum('nonmanifold_edges'),
    inverted_triangles: sum('inverted_triangles'),
    max_normal_turn: max('max_normal_turn'),
    time_ms: max('time_ms'),
    parse_ms: max('parse_ms'),
    warnings: [...new Set(reps.flatMap((r) => r.warnings ?? []))],
    reparameterized: reps.flatMap((r) => r.reparameterized ?? []),
    shares: reps.length,
  };
  // The part meshes of an instanced result: each part's faces from the shares that meshed them.
  let instanced = first.instanced;
  if (instanced) {
    const meshes = instanced.meshes.map((m, p) => {
      const { positions: ps, normals: ns, indices: is, faceRanges: fr } = mergeFaces(results.map((r) => r.instanced.meshes[p]));
      return { name: m.name, positions: ps, normals: ns, indices: is, faceRanges: fr };
    });
    instanced = { meshes, instances: instanced.instances };
  }
  return {
    result: { ...first, positions, normals, indices, faceRanges, report, instanced },
    lines: { wire: new Uint32Array(wire), borders: join('borders'), open: join('open') },
  };
}

/**
 * One mesh from several meshes of the same faces, each face taken from the
 * first mesh that has triangles for it (a face is meshed by one share only);
 * `remap[s][v]` is where vertex v of mesh s went (-1: not taken).
 */
function mergeFaces(results) {
  const faces = results[0].faceRanges.length / 2;
  let triangles = 0;
  let vertices = 0;
  const blocks = []; // per face: [share, first triangle, count, lowest vertex, highest vertex]
  for (let f = 0; f < faces; f++) {
    const s = results.findIndex((r) => r.faceRanges[2 * f + 1] > 0);
    if (s < 0) {
      blocks.push(null);
      continue;
    }
    const r = results[s];
    const [t0, n] = [r.faceRanges[2 * f], r.faceRanges[2 * f + 1]];
    let lo = Infinity;
    let hi = -1;
    for (let k = 3 * t0; k < 3 * (t0 + n); k++) {
      lo = Math.min(lo, r.indices[k]);
      hi = Math.max(hi, r.indices[k]);
    }
    blocks.push([s, t0, n, lo, hi]);
    triangles += n;
    vertices += hi - lo + 1;
  }
  const positions = new Float32Array(3 * vertices);
  const normals = new Float32Array(3 * vertices);
  const indices = new Uint32Array(3 * triangles);
  const faceRanges = new Uint32Array(2 * faces);
  const remap = results.map((r) => new Int32Array(r.positions.length / 3).fill(-1));
  let v = 0;
  let t = 0;
  for (let f = 0; f < faces; f++) {
    faceRanges[2 * f] = t;
    const b = blocks[f];
    if (!b) continue;
    const [s, t0, n, lo, hi] = b;
    const r = results[s];
    positions.set(r.positions.subarray(3 * lo, 3 * (hi + 1)), 3 * v);
    normals.set(r.normals.subarray(3 * lo, 3 * (hi + 1)), 3 * v);
    for (let x = lo; x <= hi; x++) remap[s][x] = v + x - lo;
    for (let k = 3 * t0; k < 3 * (t0 + n); k++) indices[3 * t + k - 3 * t0] = remap[s][r.indices[k]];
    faceRanges[2 * f + 1] = n;
    v += hi - lo + 1;
    t += n;
  }
  return { positions, normals, indices, faceRanges, remap, triangles, vertices };
}
