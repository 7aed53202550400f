// A Web Worker that meshes the bytes it is sent with progress, as a page
// would to keep its main thread free.
import init, { meshWithProgress } from 'surfmesh/web';

const ready = init();

self.onmessage = async (event) => {
  try {
    await ready;
    let progressCalls = 0;
    const result = meshWithProgress(event.data, 'json', { toleranceRel: 1e-3, flatten: true }, () => {
      progressCalls++;
    });
    self.postMessage({ triangles: result.report.triangles, progressCalls });
  } catch (e) {
    self.postMessage({ error: e.message });
  }
};
