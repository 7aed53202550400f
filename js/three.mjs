// surfmesh/three: a surfmesh result as a three.js BufferGeometry.
//
// The result's typed arrays become the geometry's attributes as they are (no
// copy: the one copy happened when the binding moved the mesh out of wasm
// memory, and a Web Worker can transfer the buffers to the page for free).
// Each model face becomes one draw group, so an array of materials colours
// faces apart and a raycast hit's face index maps back to the model face.

import { BufferAttribute, BufferGeometry } from 'three';

/**
 * Wraps `result` ({ positions, normals, indices, faceRanges }) in a BufferGeometry
 * with one group per model face. Group `materialIndex` is the face index, or
 * the face index modulo `materialCount` when that option is given (so a short
 * palette of materials can colour any number of faces).
 */
export function toBufferGeometry(result, { materialCount } = {}) {
  const geometry = new BufferGeometry();
  geometry.setAttribute('position', new BufferAttribute(result.positions, 3));
  if (result.normals && result.normals.length === result.positions.length) {
    geometry.setAttribute('normal', new BufferAttribute(result.normals, 3));
  }
  geometry.setIndex(new BufferAttribute(result.indices, 1));
  const ranges = result.faceRanges ?? new Uint32Array(0);
  for (let face = 0; 2 * face + 1 < ranges.length; face++) {
    const count = ranges[2 * face + 1];
    if (count === 0) continue;
    const material = materialCount > 0 ? face % materialCount : face;
    geometry.addGroup(3 * ranges[2 * face], 3 * count, material);
  }
  geometry.computeBoundingBox();
  geometry.computeBoundingSphere();
  return geometry;
}

/**
 * The model face that owns triangle `triangle` (for example a raycast hit's
 * `faceIndex`), found by binary search in `faceRanges`; -1 when none does.
 */
export function faceOfTriangle(faceRanges, triangle) {
  let lo = 0;
  let hi = (faceRanges.length >> 1) - 1;
  while (lo <= hi) {
    const mid = (lo + hi) >> 1;
    const first = faceRanges[2 * mid];
    if (triangle < first) hi = mid - 1;
    else if (triangle >= first + faceRanges[2 * mid + 1]) lo = mid + 1;
    else return mid;
  }
  return -1;
}
