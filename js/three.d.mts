import type { BufferGeometry, Group, Loader, LoadingManager } from 'three';
import type { AssemblyNode, MeshOptions, MeshOutput, FlatMeshOutput, PartInstance, Report } from './web/surfmesh.js';

/** The arrays of a surfmesh result (a part mesh or a flattened result) that a geometry needs. */
export interface MeshArrays {
  positions: Float32Array;
  normals?: Float32Array;
  indices: Uint32Array;
  faceRanges?: Uint32Array;
}

/**
 * Wraps a surfmesh result in a BufferGeometry without copying its arrays, with one group per
 * model face; a group's materialIndex is the face index, or face % materialCount when given.
 * `userData.faceRanges` keeps the ranges.
 */
export function toBufferGeometry(result: MeshArrays, options?: { materialCount?: number }): BufferGeometry;

/** The model face that owns `triangle` (e.g. a raycast hit's faceIndex), or -1. */
export function faceOfTriangle(faceRanges: Uint32Array, triangle: number): number;

/** How toObject3D draws a result. */
export interface ObjectOptions {
  /** Also draw each copy's B-rep edges as LineSegments (default false). */
  edges?: boolean;
  /** Colour of faces the file does not colour (default 0xb0b8c0). */
  color?: number;
  /** Colour of the edge lines (default 0x202020). */
  edgeColor?: number;
}

/** What toObject3D keeps in the group's userData. */
export interface SurfmeshUserData {
  tree: AssemblyNode;
  instances: PartInstance[];
  units: string;
  report: Report;
}

/**
 * A result as a Group: one InstancedMesh per distinct part (a Mesh for a flattened result), one
 * draw group and material per face coloured as the file colours it, optional edge lines.
 */
export function toObject3D(result: MeshOutput | FlatMeshOutput, options?: ObjectOptions): Group & { userData: SurfmeshUserData };

/** Meshes `buffer` in a fresh module worker on the package's web build. */
export function meshInWorker(
  buffer: ArrayBuffer | ArrayBufferView,
  format: string,
  options?: MeshOptions,
  onProgress?: (event: { type: 'mesh'; loaded: number; total: number; lengthComputable: true }) => void,
): Promise<MeshOutput | FlatMeshOutput>;

/**
 * Loads JSON, IGES and STEP files as three.js objects, in the manner of STLLoader and GLTFLoader:
 * `load(url, onLoad, onProgress, onError)`, `loadAsync(url, onProgress)`, `parse`. Meshing runs in a
 * Web Worker; onProgress gets download ProgressEvents, then `{ type: 'mesh', loaded, total }` per face.
 */
export class SurfmeshLoader extends Loader<Group & { userData: SurfmeshUserData }> {
  constructor(manager?: LoadingManager);
  options: MeshOptions & ObjectOptions;
  format: string;
  /** The options of `mesh` and of toObject3D. */
  setOptions(options: MeshOptions & ObjectOptions): this;
  /** "json", "iges" or "step" (default: from the URL's extension, else detected from the bytes). */
  setFormat(format: string): this;
  load(
    url: string,
    onLoad: (group: Group & { userData: SurfmeshUserData }) => void,
    onProgress?: (event: ProgressEvent | { type: 'mesh'; loaded: number; total: number }) => void,
    onError?: (error: unknown) => void,
  ): void;
  parseAsync(
    buffer: ArrayBuffer,
    format?: string,
    onProgress?: (event: { type: 'mesh'; loaded: number; total: number }) => void,
  ): Promise<Group & { userData: SurfmeshUserData }>;
  parse(buffer: ArrayBuffer, onLoad: (group: Group & { userData: SurfmeshUserData }) => void, onError?: (error: unknown) => void): void;
}
