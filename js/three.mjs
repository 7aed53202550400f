// surfmesh/three: a surfmesh result as a three.js BufferGeometry.
//
// The result's typed arrays become the geometry's attributes as they are (no
// copy: the one copy happened when the binding moved the mesh out of wasm
// memory, and a Web Worker can transfer the buffers to the page for free).
// Each model face becomes one draw group, so an array of materials colours
// faces apart and a raycast hit's face index maps back to the model face.

import {
  BufferAttribute,
  BufferGeometry,
  Color,
  FileLoader,
  Group,
  InstancedMesh,
  LineBasicMaterial,
  LineSegments,
  Loader,
  Matrix4,
  Mesh,
  MeshStandardMaterial,
  SRGBColorSpace,
} from 'three';

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
  // Kept for mapping a draw group or a triangle back to its model face.
  geometry.userData.faceRanges = ranges;
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

/**
 * A surfmesh result as a three.js scene graph: one `InstancedMesh` per
 * distinct part (its geometry shared by every placed copy, one draw group and
 * one material per face, coloured as the file colours it), under a `Group`
 * named after the assembly's root. A flattened result (`flatten: true`) is
 * one `Mesh`. With `edges`, each copy also gets the part's B-rep edges as
 * `LineSegments` on one shared geometry. The tree, the units and the report
 * are kept in the group's `userData`.
 */
export function toObject3D(result, { edges = false, color = 0xb0b8c0, edgeColor = 0x202020 } = {}) {
  const root = new Group();
  root.name = result.tree?.name ?? '';
  root.userData = { tree: result.tree, instances: result.instances ?? [], units: result.units, report: result.report };
  const parts = result.meshes ?? [result];
  const lineMaterial = new LineBasicMaterial({ color: edgeColor });
  const placements = parts.map(() => []);
  if (result.meshes) {
    for (const inst of result.instances) placements[inst.part]?.push(new Matrix4().fromArray(inst.matrix));
  } else {
    placements[0] = [new Matrix4()];
  }
  parts.forEach((part, p) => {
    const geometry = toBufferGeometry(part);
    const materials = faceMaterials(part, color);
    const copies = placements[p];
    if (copies.length === 0) return;
    let object;
    if (result.meshes) {
      object = new InstancedMesh(geometry, materials, copies.length);
      copies.forEach((m, i) => object.setMatrixAt(i, m));
      object.instanceMatrix.needsUpdate = true;
      object.computeBoundingBox();
      object.computeBoundingSphere();
    } else {
      object = new Mesh(geometry, materials);
    }
    object.name = part.name ?? '';
    object.userData.part = p;
    root.add(object);
    if (edges && part.edges?.length) {
      const lines = new BufferGeometry();
      lines.setAttribute('position', new BufferAttribute(segments(part.edges, part.edgeRanges), 3));
      for (const m of copies) {
        const l = new LineSegments(lines, lineMaterial);
        l.matrixAutoUpdate = false;
        l.matrix.copy(m);
        l.userData.part = p;
        root.add(l);
      }
    }
  });
  return root;
}

/** One material per face: the file's colour (sRGB, as files give them), else `color`. */
function faceMaterials(part, color) {
  const c = part.faceColors ?? new Float32Array(0);
  const count = (part.faceRanges?.length ?? 0) >> 1;
  const shared = new MeshStandardMaterial({ color, metalness: 0.1, roughness: 0.6 });
  const byKey = new Map();
  const out = [];
  for (let f = 0; f < Math.max(count, 1); f++) {
    const [r, g, b] = [c[3 * f], c[3 * f + 1], c[3 * f + 2]];
    if (!(r >= 0 && g >= 0 && b >= 0)) {
      out.push(shared);
      continue;
    }
    const key = `${r},${g},${b}`;
    if (!byKey.has(key)) byKey.set(key, new MeshStandardMaterial({ color: new Color().setRGB(r, g, b, SRGBColorSpace), metalness: 0.1, roughness: 0.6 }));
    out.push(byKey.get(key));
  }
  return out;
}

/** Polylines (points and (first, count) ranges) as line-segment pairs. */
function segments(points, ranges) {
  let n = 0;
  for (let i = 1; i < ranges.length; i += 2) n += Math.max(ranges[i] - 1, 0);
  const out = new Float32Array(6 * n);
  let o = 0;
  for (let i = 0; i + 1 < ranges.length; i += 2) {
    const [first, count] = [ranges[i], ranges[i + 1]];
    for (let k = first; k + 1 < first + count; k++) {
      out.set(points.subarray(3 * k, 3 * k + 6), o);
      o += 6;
    }
  }
  return out;
}

/** The format name the binding takes, from a file name's extension ("" to detect it). */
function formatOf(url) {
  const ext = /\.([a-z]+)(?:[?#].*)?$/i.exec(String(url))?.[1]?.toLowerCase() ?? '';
  return { json: 'json', igs: 'iges', iges: 'iges', stp: 'step', step: 'step' }[ext] ?? '';
}

/**
 * Loads JSON, IGES and STEP files as three.js objects, the way three.js's
 * own loaders do (`load(url, onLoad, onProgress, onError)`, `loadAsync`,
 * `parse`). Meshing runs in a Web Worker on the package's web build;
 * onProgress receives `{ loaded, total }` in bytes while downloading, then
 * `{ type: 'mesh', loaded: facesDone, total: facesTotal }` while meshing.
 */
export class SurfmeshLoader extends Loader {
  constructor(manager) {
    super(manager);
    /** The `mesh` options (MeshOptions), plus `edges` for toObject3D. */
    this.options = {};
    this.format = '';
  }

  /** Sets the options passed to `mesh` (and `edges`, `color` for the objects); returns this. */
  setOptions(options) {
    this.options = { ...options };
    return this;
  }

  /** Sets the file format ("json", "iges", "step"; default: from the URL, else detected). */
  setFormat(format) {
    this.format = format;
    return this;
  }

  load(url, onLoad, onProgress, onError) {
    const loader = new FileLoader(this.manager);
    loader.setPath(this.path);
    loader.setResponseType('arraybuffer');
    loader.setRequestHeader(this.requestHeader);
    loader.setWithCredentials(this.withCredentials);
    const fail = (e) => {
      if (onError) onError(e);
      else console.error(e);
      this.manager.itemError(url);
    };
    loader.load(
      url,
      (buffer) => {
        this.parseAsync(buffer, this.format || formatOf(url), onProgress).then(onLoad, fail);
      },
      onProgress,
      fail,
    );
  }

  /** Meshes `buffer` in a worker; resolves to the Group of toObject3D. */
  parseAsync(buffer, format = this.format, onProgress) {
    const { edges, color, edgeColor, ...meshOptions } = this.options;
    return meshInWorker(buffer, format, meshOptions, onProgress).then((result) => toObject3D(result, { edges, color, edgeColor }));
  }

  /** As parseAsync, with callbacks (GLTFLoader's form). */
  parse(buffer, onLoad, onError) {
    this.parseAsync(buffer).then(onLoad, onError);
  }
}

/** Meshes in a fresh module worker, which ends with the request. */
export function meshInWorker(buffer, format, options, onProgress) {
  const worker = new Worker(new URL('./three-worker.mjs', import.meta.url), { type: 'module' });
  const bytes = buffer instanceof ArrayBuffer ? buffer : buffer.buffer.slice(buffer.byteOffset, buffer.byteOffset + buffer.byteLength);
  return new Promise((resolve, reject) => {
    worker.onmessage = (e) => {
      const m = e.data;
      if (m.type === 'progress') {
        onProgress?.({ type: 'mesh', loaded: m.done, total: m.total, lengthComputable: true });
        return;
      }
      worker.terminate();
      if (m.type === 'result') resolve(m.result);
      else reject(new Error(m.message));
    };
    worker.onerror = (e) => {
      worker.terminate();
      reject(new Error(e.message ?? 'the meshing worker failed to load'));
    };
    worker.postMessage({ bytes, format, options }, [bytes]);
  });
}
