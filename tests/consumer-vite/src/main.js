// Meshes the page's 50-face sample twice: on this thread with the package's
// web build, and in a Web Worker (the same build, imported by the worker),
// then wraps the result in a three.js geometry with surfmesh/three.
import init, { mesh, version } from 'surfmesh/web';
import { toBufferGeometry } from 'surfmesh/three';
import sampleUrl from '../../../www/samples/grid50.json?url';

const out = document.getElementById('result');

function inWorker(bytes) {
  const worker = new Worker(new URL('./worker.js', import.meta.url), { type: 'module' });
  return new Promise((resolve, reject) => {
    worker.onmessage = (e) => {
      worker.terminate();
      if (e.data.error) reject(new Error(e.data.error));
      else resolve(e.data);
    };
    worker.onerror = (e) => reject(new Error(e.message));
    worker.postMessage(bytes);
  });
}

try {
  await init();
  const bytes = new Uint8Array(await (await fetch(sampleUrl)).arrayBuffer());
  const result = mesh(bytes, 'json', { toleranceRel: 1e-3 });
  const geometry = toBufferGeometry(result);
  const worker = await inWorker(bytes);
  const summary = {
    version: version(),
    faces: result.report.faces,
    triangles: result.report.triangles,
    groups: geometry.groups.length,
    sharesArrays: geometry.index.array === result.indices && geometry.attributes.position.array === result.positions,
    workerTriangles: worker.triangles,
    workerProgressCalls: worker.progressCalls,
  };
  out.textContent = JSON.stringify(summary, null, 2);
  out.dataset.state = 'done';
} catch (e) {
  out.textContent = `error: ${e.message}`;
  out.dataset.state = 'error';
}
