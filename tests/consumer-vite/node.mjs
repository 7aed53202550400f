// The Node side of the consumer: imports the package by name (its "node"
// export condition picks the nodejs build) and meshes the same sample as the
// Vite page; prints a JSON summary.
import { readFileSync } from 'node:fs';
import { mesh, meshWithProgress, version } from 'surfmesh';

const bytes = readFileSync(new URL('../../www/samples/grid50.json', import.meta.url));
const result = mesh(bytes, 'json', { toleranceRel: 1e-3, flatten: true });
const seen = [];
const again = meshWithProgress(bytes, 'json', { toleranceRel: 1e-3 }, (done, total) => {
  seen.push([done, total]);
});
let cancelled = null;
try {
  meshWithProgress(bytes, 'json', { toleranceRel: 1e-3 }, (done) => done < 5);
} catch (e) {
  cancelled = { message: e.message };
}
let rethrown = null;
try {
  meshWithProgress(bytes, 'json', {}, () => {
    throw new TypeError('stop here');
  });
} catch (e) {
  rethrown = { name: e.name, message: e.message };
}
console.log(
  JSON.stringify({
    version: version(),
    faces: result.report.faces,
    triangles: result.report.triangles,
    maxDeviation: result.report.max_deviation,
    tolerance: result.report.tolerance,
    progressTriangles: again.report.triangles,
    progress: seen,
    cancelled,
    rethrown,
  }),
);
