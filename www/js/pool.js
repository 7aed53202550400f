// A small pool of meshing workers (worker.js). The wasm module is compiled
// once here and posted to each worker, so a worker that cancel() ends is
// replaced at the cost of an instantiation. A job runs on an idle worker
// (queued when none is idle) and resolves to
//   { result: { positions, normals, indices, faceRanges, report }, lines: { borders, open } }
// or rejects with an Error carrying the module's message; cancel() rejects it
// with an Error whose message is "cancelled" and stops the work at once
// (the worker is terminated: wasm cannot be interrupted mid-face otherwise).
//
// One model is never split by faces across workers: faces are sewn into one
// watertight mesh after all of them are meshed, inside one call, so the pool
// runs whole jobs (the page's coarse preview and the requested mesh side by side).

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
