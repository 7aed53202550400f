import type { BufferGeometry } from 'three';

/** The arrays of a surfmesh result that a geometry needs. */
export interface MeshArrays {
  positions: Float32Array;
  normals?: Float32Array;
  indices: Uint32Array;
  faceRanges?: Uint32Array;
}

/**
 * Wraps a surfmesh result in a BufferGeometry without copying its arrays, with one group per
 * model face; a group's materialIndex is the face index, or face % materialCount when given.
 */
export function toBufferGeometry(result: MeshArrays, options?: { materialCount?: number }): BufferGeometry;

/** The model face that owns `triangle` (e.g. a raycast hit's faceIndex), or -1. */
export function faceOfTriangle(faceRanges: Uint32Array, triangle: number): number;
