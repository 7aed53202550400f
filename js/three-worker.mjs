// The worker of surfmesh/three's SurfmeshLoader: loads the package's web
// build, meshes the one request it is sent with progress events, and posts
// the result back with its typed arrays transferred (no copy).
//
// In:  { bytes: ArrayBuffer, format, options }
// Out: { type: 'progress', done, total } ..., then { type: 'result', result } | { type: 'error', message }

import init, { meshWithProgress } from './web/surfmesh.js';

const ready = init();

self.onmessage = async (event) => {
  const { bytes, format, options } = event.data;
  try {
    await ready;
    const result = meshWithProgress(new Uint8Array(bytes), format ?? '', options, (done, total) => {
      self.postMessage({ type: 'progress', done, total });
    });
    self.postMessage({ type: 'result', result }, transferables(result));
  } catch (e) {
    self.postMessage({ type: 'error', message: e instanceof Error ? e.message : String(e) });
  }
};

/** The buffers of every typed array in the result (each its own buffer). */
function transferables(result) {
  const parts = result.meshes ?? [result];
  const out = new Set();
  for (const p of parts) {
    for (const v of Object.values(p)) if (ArrayBuffer.isView(v)) out.add(v.buffer);
  }
  return [...out];
}
