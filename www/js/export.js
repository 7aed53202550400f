// Mesh files from a surfmesh result, written in the page: binary STL, OBJ
// (one group per model face) and binary glTF (one primitive per face, sharing
// one vertex buffer, faces coloured like the viewer).

/** Binary STL: 80-byte header, triangle count, then per triangle a facet normal and three corners. */
export function toStl({ positions, indices }, header = 'surfmesh') {
  const count = indices.length / 3;
  const view = new DataView(new ArrayBuffer(84 + 50 * count));
  const title = new TextEncoder().encode(header.slice(0, 80));
  new Uint8Array(view.buffer, 0, 80).set(title);
  view.setUint32(80, count, true);
  let at = 84;
  const p = (i, k) => positions[3 * i + k];
  for (let t = 0; t < count; t++) {
    const [a, b, c] = [indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]];
    const u = [p(b, 0) - p(a, 0), p(b, 1) - p(a, 1), p(b, 2) - p(a, 2)];
    const v = [p(c, 0) - p(a, 0), p(c, 1) - p(a, 1), p(c, 2) - p(a, 2)];
    let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    const len = Math.hypot(n[0], n[1], n[2]);
    n = len > 0 ? n.map((x) => x / len) : [0, 0, 0];
    for (const x of n) {
      view.setFloat32(at, x, true);
      at += 4;
    }
    for (const i of [a, b, c]) {
      for (let k = 0; k < 3; k++) {
        view.setFloat32(at, p(i, k), true);
        at += 4;
      }
    }
    at += 2; // attribute byte count: 0
  }
  return new Blob([view.buffer], { type: 'model/stl' });
}

/** Wavefront OBJ with vertex normals and one `g face_N` group per model face. */
export function toObj({ positions, normals, indices, faceRanges }, comment = 'surfmesh') {
  const lines = [`# ${comment}`];
  const fmt = (x) => (Number.isInteger(x) ? String(x) : x.toPrecision(7).replace(/\.?0+$/, ''));
  for (let i = 0; i < positions.length; i += 3) {
    lines.push(`v ${fmt(positions[i])} ${fmt(positions[i + 1])} ${fmt(positions[i + 2])}`);
  }
  for (let i = 0; i < normals.length; i += 3) {
    lines.push(`vn ${fmt(normals[i])} ${fmt(normals[i + 1])} ${fmt(normals[i + 2])}`);
  }
  for (let f = 0; 2 * f + 1 < faceRanges.length; f++) {
    lines.push(`g face_${f}`);
    const first = faceRanges[2 * f];
    for (let t = first; t < first + faceRanges[2 * f + 1]; t++) {
      const [a, b, c] = [indices[3 * t] + 1, indices[3 * t + 1] + 1, indices[3 * t + 2] + 1];
      lines.push(`f ${a}//${a} ${b}//${b} ${c}//${c}`);
    }
  }
  lines.push('');
  return new Blob([lines.join('\n')], { type: 'model/obj' });
}

/**
 * Binary glTF 2.0: one buffer (positions, normals, indices), one mesh whose
 * primitives are the model faces, materials from `palette` (sRGB hex numbers).
 */
export function toGlb({ positions, normals, indices, faceRanges }, palette = [0xb0b4ba]) {
  const min = [Infinity, Infinity, Infinity];
  const max = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < positions.length; i++) {
    min[i % 3] = Math.min(min[i % 3], positions[i]);
    max[i % 3] = Math.max(max[i % 3], positions[i]);
  }
  const vertexCount = positions.length / 3;
  const posBytes = positions.byteLength;
  const nrmBytes = normals.byteLength;
  const binLength = posBytes + nrmBytes + indices.byteLength;
  const bin = new Uint8Array(binLength);
  bin.set(new Uint8Array(positions.buffer, positions.byteOffset, posBytes), 0);
  bin.set(new Uint8Array(normals.buffer, normals.byteOffset, nrmBytes), posBytes);
  bin.set(new Uint8Array(indices.buffer, indices.byteOffset, indices.byteLength), posBytes + nrmBytes);

  const accessors = [
    { bufferView: 0, componentType: 5126, count: vertexCount, type: 'VEC3', min, max },
    { bufferView: 1, componentType: 5126, count: vertexCount, type: 'VEC3' },
  ];
  const primitives = [];
  const linear = (c) => {
    const s = c / 255;
    return s <= 0.04045 ? s / 12.92 : ((s + 0.055) / 1.055) ** 2.4;
  };
  const materials = palette.map((hex) => ({
    pbrMetallicRoughness: {
      baseColorFactor: [linear((hex >> 16) & 255), linear((hex >> 8) & 255), linear(hex & 255), 1],
      metallicFactor: 0,
      roughnessFactor: 0.6,
    },
    doubleSided: true,
  }));
  for (let f = 0; 2 * f + 1 < faceRanges.length; f++) {
    const count = faceRanges[2 * f + 1];
    if (count === 0) continue;
    accessors.push({
      bufferView: 2,
      byteOffset: 12 * faceRanges[2 * f],
      componentType: 5125,
      count: 3 * count,
      type: 'SCALAR',
    });
    primitives.push({
      attributes: { POSITION: 0, NORMAL: 1 },
      indices: accessors.length - 1,
      material: f % materials.length,
    });
  }
  const gltf = {
    asset: { version: '2.0', generator: 'surfmesh page' },
    scene: 0,
    scenes: [{ nodes: [0] }],
    nodes: [{ mesh: 0 }],
    meshes: [{ primitives }],
    materials,
    accessors,
    bufferViews: [
      { buffer: 0, byteOffset: 0, byteLength: posBytes, target: 34962 },
      { buffer: 0, byteOffset: posBytes, byteLength: nrmBytes, target: 34962 },
      { buffer: 0, byteOffset: posBytes + nrmBytes, byteLength: indices.byteLength, target: 34963 },
    ],
    buffers: [{ byteLength: binLength }],
  };
  const json = new TextEncoder().encode(JSON.stringify(gltf));
  const jsonPadded = (json.length + 3) & ~3;
  const binPadded = (binLength + 3) & ~3;
  const total = 12 + 8 + jsonPadded + 8 + binPadded;
  const out = new Uint8Array(total);
  const view = new DataView(out.buffer);
  view.setUint32(0, 0x46546c67, true); // "glTF"
  view.setUint32(4, 2, true);
  view.setUint32(8, total, true);
  view.setUint32(12, jsonPadded, true);
  view.setUint32(16, 0x4e4f534a, true); // "JSON"
  out.set(json, 20);
  out.fill(0x20, 20 + json.length, 20 + jsonPadded);
  view.setUint32(20 + jsonPadded, binPadded, true);
  view.setUint32(24 + jsonPadded, 0x004e4942, true); // "BIN\0"
  out.set(bin, 28 + jsonPadded);
  return new Blob([out], { type: 'model/gltf-binary' });
}
