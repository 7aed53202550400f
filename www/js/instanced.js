// The page's view of an instanced mesh result: the whole model as one mesh
// (for the line overlays, picking and export) beside the part meshes and
// their placements (drawn as three.js InstancedMesh). Used by worker.js;
// plain functions, so Node tests import them too.

/**
 * The page's result from an instanced one ({ meshes, instances, tree, units,
 * report }): the whole model as one mesh, instance after instance (each its
 * part's faces in the part's order, moved by its matrix), for the line
 * overlays, picking and export; `faceParts` names each face's instance and
 * `parts` each instance's part name. With more than one instance the part
 * meshes and instances ride along as `instanced`, which the viewer draws as
 * one three.js InstancedMesh per part.
 */
export function flattened({ meshes, instances, tree, units, report }) {
  const parts = instances.map((inst) => meshes[inst.part]?.name ?? '');
  const identity = (m) => m.every((x, i) => x === (i % 5 === 0 ? 1 : 0));
  if (instances.length === 1 && identity(instances[0].matrix)) {
    const m = meshes[instances[0].part];
    const faceParts = new Uint32Array(m.faceRanges.length / 2);
    return { positions: m.positions, normals: m.normals, indices: m.indices, faceRanges: m.faceRanges, faceParts, parts, tree, units, report, instanced: null };
  }
  let vertices = 0;
  let triangles = 0;
  let faces = 0;
  for (const inst of instances) {
    const m = meshes[inst.part];
    vertices += m.positions.length / 3;
    triangles += m.indices.length / 3;
    faces += m.faceRanges.length / 2;
  }
  const positions = new Float32Array(3 * vertices);
  const normals = new Float32Array(3 * vertices);
  const indices = new Uint32Array(3 * triangles);
  const faceRanges = new Uint32Array(2 * faces);
  const faceParts = new Uint32Array(faces);
  let [v, t, f] = [0, 0, 0];
  instances.forEach((inst, k) => {
    const m = meshes[inst.part];
    const a = inst.matrix; // column-major 4 x 4
    const p = m.positions;
    const n = m.normals;
    for (let i = 0; i < p.length; i += 3) {
      const [x, y, z] = [p[i], p[i + 1], p[i + 2]];
      const o = 3 * v + i;
      positions[o] = a[0] * x + a[4] * y + a[8] * z + a[12];
      positions[o + 1] = a[1] * x + a[5] * y + a[9] * z + a[13];
      positions[o + 2] = a[2] * x + a[6] * y + a[10] * z + a[14];
      // Rigid placements: the normals turn with the rotation part.
      const [u, w, s] = [n[i], n[i + 1], n[i + 2]];
      normals[o] = a[0] * u + a[4] * w + a[8] * s;
      normals[o + 1] = a[1] * u + a[5] * w + a[9] * s;
      normals[o + 2] = a[2] * u + a[6] * w + a[10] * s;
    }
    for (let i = 0; i < m.indices.length; i++) indices[3 * t + i] = m.indices[i] + v;
    for (let j = 0; j < m.faceRanges.length; j += 2) {
      faceRanges[2 * f] = m.faceRanges[j] + t;
      faceRanges[2 * f + 1] = m.faceRanges[j + 1];
      faceParts[f++] = k;
    }
    v += p.length / 3;
    t += m.indices.length / 3;
  });
  const instanced =
    instances.length > 1
      ? {
          meshes: meshes.map((m) => ({ name: m.name, positions: m.positions, normals: m.normals, indices: m.indices, faceRanges: m.faceRanges })),
          instances: instances.map((inst) => ({ part: inst.part, matrix: inst.matrix })),
        }
      : null;
  return { positions, normals, indices, faceRanges, faceParts, parts, tree, units, report, instanced };
}
