// Meshes the page's 50-face sample twice: on this thread with the package's
// web build, and in a Web Worker (the same build, imported by the worker),
// then wraps the result in a three.js geometry with surfmesh/three. Then
// loads a STEP assembly with surfmesh/three's SurfmeshLoader (its own
// worker) and checks its InstancedMesh copies against the flattened mesh.
import init, { mesh, version } from 'surfmesh/web';
import { SurfmeshLoader, toBufferGeometry } from 'surfmesh/three';
import { Matrix4, Vector3 } from 'three';
import sampleUrl from '../../../www/samples/grid50.json?url';
import assemblyUrl from '../../data/step_assembly.stp?url';

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

/**
 * The loader's object for the assembly against the flattened mesh of the
 * same file: every instance's triangles, under its matrix, are the flat
 * mesh's triangles of that part instance, in order (largest distance).
 */
function compareInstances(group, flat) {
  let worst = 0;
  let compared = 0;
  const v = new Vector3();
  const meshes = group.children.filter((c) => c.isInstancedMesh);
  // Flat faces of each instance, in face order; instances numbered as the result's.
  const facesOf = new Map();
  flat.faceParts.forEach((k, f) => facesOf.set(k, [...(facesOf.get(k) ?? []), f]));
  const m = new Matrix4();
  let k = 0;
  for (const { part, matrix } of group.userData.instances) {
    const object = meshes.find((o) => o.userData.part === part);
    const copy = group.userData.instances.slice(0, k).filter((i) => i.part === part).length;
    object.getMatrixAt(copy, m);
    const pos = object.geometry.attributes.position.array;
    const idx = object.geometry.index.array;
    const ranges = object.geometry.userData.faceRanges;
    (facesOf.get(k) ?? []).forEach((f, j) => {
      const [a, n] = [ranges[2 * j], ranges[2 * j + 1]];
      const [fa, fn] = [flat.faceRanges[2 * f], flat.faceRanges[2 * f + 1]];
      if (n !== fn) worst = Infinity;
      for (let t = 0; t < 3 * Math.min(n, fn); t++) {
        const i = idx[3 * a + t];
        v.set(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]).applyMatrix4(m);
        const q = flat.indices[3 * fa + t];
        worst = Math.max(worst, Math.hypot(v.x - flat.positions[3 * q], v.y - flat.positions[3 * q + 1], v.z - flat.positions[3 * q + 2]));
        compared++;
      }
    });
    k++;
  }
  return { worst, compared, flatCorners: flat.indices.length };
}

try {
  await init();
  const bytes = new Uint8Array(await (await fetch(sampleUrl)).arrayBuffer());
  const result = mesh(bytes, 'json', { toleranceRel: 1e-3 });
  const part = result.meshes[0];
  const geometry = toBufferGeometry(part);
  const worker = await inWorker(bytes);

  const loader = new SurfmeshLoader().setOptions({ toleranceRel: 1e-3, edges: true });
  const progress = [];
  const group = await loader.loadAsync(assemblyUrl, (e) => progress.push(e.type ?? 'download'));
  const stepBytes = new Uint8Array(await (await fetch(assemblyUrl)).arrayBuffer());
  const flat = mesh(stepBytes, 'step', { toleranceRel: 1e-3, flatten: true });
  const instanced = group.children.filter((c) => c.isInstancedMesh);
  const summary = {
    version: version(),
    faces: result.report.faces,
    triangles: result.report.triangles,
    groups: geometry.groups.length,
    sharesArrays: geometry.index.array === part.indices && geometry.attributes.position.array === part.positions,
    workerTriangles: worker.triangles,
    workerProgressCalls: worker.progressCalls,
    loader: {
      name: group.name,
      children: group.userData.tree.children.map((c) => [c.name, c.occurrence]),
      instancedMeshes: instanced.length,
      copies: instanced.map((o) => o.count),
      groupsPerPart: instanced.map((o) => o.geometry.groups.length),
      materials: instanced.map((o) => o.material.map((m) => m.color.getHexString())),
      lines: group.children.filter((c) => c.isLineSegments).length,
      meshProgress: progress.filter((p) => p === 'mesh').length,
      triangles: group.userData.report.triangles,
      flatTriangles: flat.report.triangles,
      ...compareInstances(group, flat),
    },
  };
  out.textContent = JSON.stringify(summary, null, 2);
  out.dataset.state = 'done';
} catch (e) {
  out.textContent = `error: ${e.message}\n${e.stack}`;
  out.dataset.state = 'error';
}
