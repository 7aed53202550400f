// The three.js viewer: a shaded mesh with one colour per model face (groups
// from surfmesh/three; a model of placed parts as one InstancedMesh per
// distinct part, the part's faces coloured alike in every copy), a wireframe overlay, face borders and open edges as
// line sets, orbit controls and fit-to-view. Renders on demand (after a
// change or a camera move), so an idle page costs nothing.

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { faceOfTriangle, toBufferGeometry } from 'surfmesh/three';

/** Face colours: muted, told apart at a glance, none close to the open-edge orange. */
export const PALETTE = [
  0x6d9dc5, 0xc9a66b, 0x8fbf8a, 0xc98b9f, 0x9b8fcf, 0x6bb8b0, 0xd0c27a, 0xa3a8b0, 0x86a9d8, 0xbf9a84, 0x7fae6e,
  0xb88fc0,
];
const NEUTRAL = 0xaeb4bc;
const HIGHLIGHT = 0xffd24a;

export class Viewer {
  constructor(canvas) {
    // Multisampling when a GPU draws; with software GL (headless browsers,
    // virtual machines) it would cost more than the mesh itself, so there the
    // canvas is replaced by a fresh one with a context without it.
    const attributes = { alpha: true, depth: true, stencil: false, premultipliedAlpha: true };
    let gl = canvas.getContext('webgl2', { ...attributes, antialias: true });
    this.software = gl !== null && isSoftware(gl);
    if (this.software) {
      gl.getExtension('WEBGL_lose_context')?.loseContext();
      const fresh = canvas.cloneNode(false);
      canvas.replaceWith(fresh);
      canvas = fresh;
      gl = canvas.getContext('webgl2', { ...attributes, antialias: false });
    }
    this.canvas = canvas;
    this.renderer = new THREE.WebGLRenderer({ canvas, context: gl ?? undefined, ...attributes });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
    this.renderer.setClearColor(0x000000, 0);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(35, 1, 0.1, 1000);
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(1, -1.4, 1);
    this.scene.add(this.camera);
    this.scene.add(new THREE.HemisphereLight(0xe8eef6, 0x30343a, 1.4));
    const key = new THREE.DirectionalLight(0xffffff, 1.6);
    key.position.set(0.5, 0.8, 1);
    this.camera.add(key); // a head light: the lit side follows the view

    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.addEventListener('change', () => this.requestRender());

    // The palette, then the highlight of a picked face (last index).
    this.faceMaterials = [...PALETTE, HIGHLIGHT].map((color) => this.#shaded(color));
    // A picked face of placed parts: its copy drawn over the instances (which sit a little behind).
    this.pickMaterial = new THREE.MeshPhongMaterial({ color: HIGHLIGHT, side: THREE.DoubleSide });
    const plain = this.#shaded(NEUTRAL);
    this.plainMaterials = [...PALETTE.map(() => plain), this.faceMaterials[PALETTE.length]];
    this.wireMaterial = new THREE.LineBasicMaterial({ color: 0x12161c, transparent: true, opacity: 0.35 });
    this.borderMaterial = new THREE.LineBasicMaterial({ color: 0x0b0d10 });
    this.openMaterial = new THREE.LineBasicMaterial({ color: 0xff7a1a, depthTest: false });

    this.group = new THREE.Group();
    this.scene.add(this.group);
    this.parts = null;
    this.options = { faceColors: true, wireframe: true, borders: true, openEdges: true };
    this.pending = false;
    this.empty = true; // nothing drawn yet: a fresh canvas is already clear
    this.onRendered = null;
    new ResizeObserver(() => this.resize()).observe(canvas.parentElement);
    this.resize();
  }

  /**
   * Draws materials once on degenerate geometry that covers no pixel, so that
   * shader compilation (slow with software GL) happens before a mesh is drawn
   * with them rather than when it is. `faces` (the shaded materials) is done
   * at start; `lines` (wireframe, borders, open edges) once the first picture
   * is up: the coarse preview is drawn without them, so its frame waits for
   * one compilation, not four.
   */
  warmUp(kind = 'faces') {
    const parts =
      kind === 'faces'
        ? [
            new THREE.Mesh(
              toBufferGeometry({
                positions: new Float32Array(9),
                normals: new Float32Array([0, 0, 1, 0, 0, 1, 0, 0, 1]),
                indices: new Uint32Array([0, 1, 2]),
                faceRanges: new Uint32Array([0, 1]),
              }),
              this.faceMaterials,
            ),
          ]
        : [this.wireMaterial, this.borderMaterial, this.openMaterial].map((m) => segments(new Float32Array(6), m));
    for (const part of parts) part.frustumCulled = false;
    this.scene.add(...parts);
    this.renderer.render(this.scene, this.camera);
    this.scene.remove(...parts);
    for (const part of parts) part.geometry.dispose();
    performance.mark(`surfmesh:shaders-compiled-${kind}`);
  }

  #shaded(color) {
    return new THREE.MeshPhongMaterial({
      color,
      specular: 0x2a2a2a,
      shininess: 40,
      side: THREE.DoubleSide,
      polygonOffset: true,
      polygonOffsetFactor: 1,
      polygonOffsetUnits: 1,
    });
  }

  /**
   * Shows a mesh result and its line sets; `fit` re-frames the camera. With
   * `overlays: false` (a preview) the line sets are kept but not drawn.
   */
  show(result, lines, { fit = false, overlays = true } = {}) {
    this.clear();
    const geometry = toBufferGeometry(result, { materialCount: PALETTE.length });
    const shaded = result.instanced ? this.#instanced(result.instanced) : new THREE.Mesh(geometry, this.faceMaterials);
    // The wireframe: the worker's edge list over the same vertex buffer (one line per edge).
    const wireGeometry = new THREE.BufferGeometry();
    wireGeometry.setAttribute('position', geometry.getAttribute('position'));
    wireGeometry.setIndex(new THREE.BufferAttribute(lines.wire, 1));
    const wire = new THREE.LineSegments(wireGeometry, this.wireMaterial);
    const borders = segments(lines.borders, this.borderMaterial);
    const open = segments(lines.open, this.openMaterial);
    open.renderOrder = 2;
    // Over placed parts, the picked face is drawn from the merged mesh (one group, or none).
    const pickGeometry = new THREE.BufferGeometry();
    pickGeometry.setAttribute('position', geometry.getAttribute('position'));
    pickGeometry.setAttribute('normal', geometry.getAttribute('normal'));
    pickGeometry.setIndex(geometry.getIndex());
    const pickedMesh = new THREE.Mesh(pickGeometry, [this.pickMaterial]);
    pickedMesh.visible = false;
    const faceStart = instanceFaceStarts(result);
    this.parts = { geometry, shaded, wire, borders, open, pickedMesh, faceStart, overlays, faceRanges: result.faceRanges, picked: -1 };
    this.group.add(shaded, wire, borders, open, pickedMesh);
    this.apply();
    if (fit) this.fit();
    this.requestRender();
  }

  /**
   * Placed parts as a group of InstancedMesh, one per distinct part: its
   * geometry (a draw group per face) shared by every copy, each copy's matrix
   * the instance's; `userData.instances` maps a copy to its instance.
   */
  #instanced({ meshes, instances }) {
    const group = new THREE.Group();
    const copies = meshes.map(() => []);
    const which = meshes.map(() => []); // per part, the instance index of each copy
    instances.forEach((inst, k) => {
      copies[inst.part]?.push(new THREE.Matrix4().fromArray(inst.matrix));
      which[inst.part]?.push(k);
    });
    meshes.forEach((part, p) => {
      if (copies[p].length === 0) return;
      const mesh = new THREE.InstancedMesh(toBufferGeometry(part, { materialCount: PALETTE.length }), this.faceMaterials, copies[p].length);
      copies[p].forEach((m, i) => mesh.setMatrixAt(i, m));
      mesh.instanceMatrix.needsUpdate = true;
      mesh.computeBoundingBox();
      mesh.computeBoundingSphere();
      mesh.userData.part = p;
      mesh.userData.instances = which[p];
      group.add(mesh);
    });
    return group;
  }

  /** Draw calls of the shaded model: InstancedMesh objects and the copies they place (a plain mesh: 1 and 1). */
  instancing() {
    const shaded = this.parts?.shaded;
    if (!shaded?.isGroup) return { meshes: shaded ? 1 : 0, copies: shaded ? 1 : 0 };
    return { meshes: shaded.children.length, copies: shaded.children.reduce((n, m) => n + m.count, 0) };
  }

  /**
   * The model face under the canvas point (x, y) in CSS pixels, or -1; with
   * `highlight`, that face is drawn in the highlight colour (and the previous one restored).
   */
  pick(x, y, { highlight = true } = {}) {
    if (!this.parts) return -1;
    const rect = this.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(((x - rect.left) / rect.width) * 2 - 1, -((y - rect.top) / rect.height) * 2 + 1);
    const ray = new THREE.Raycaster();
    ray.setFromCamera(ndc, this.camera);
    const hit = ray.intersectObject(this.parts.shaded, true)[0];
    let face = -1;
    if (hit?.instanceId !== undefined) {
      // A copy of a part: the part's face, counted from where that instance's faces start.
      const part = hit.object.geometry.userData.faceRanges;
      const j = faceOfTriangle(part, hit.faceIndex);
      const k = hit.object.userData.instances[hit.instanceId];
      if (j >= 0) face = this.parts.faceStart[k] + j;
    } else if (hit) {
      face = faceOfTriangle(this.parts.faceRanges, hit.faceIndex);
    }
    if (highlight) this.highlight(face);
    return face;
  }

  /** Draws model face `face` in the highlight colour (-1: none). */
  highlight(face) {
    if (!this.parts) return;
    if (this.parts.shaded.isGroup) {
      const g = this.parts.pickedMesh.geometry;
      g.clearGroups();
      const r = this.parts.faceRanges;
      if (face >= 0) g.addGroup(3 * r[2 * face], 3 * r[2 * face + 1], 0);
      this.parts.pickedMesh.visible = face >= 0;
      this.parts.picked = face;
      this.requestRender();
      return;
    }
    const groups = this.parts.geometry.groups;
    const ranges = this.parts.faceRanges;
    for (const g of groups) {
      const f = faceOfTriangle(ranges, g.start / 3);
      g.materialIndex = f === face ? PALETTE.length : f % PALETTE.length;
    }
    this.parts.picked = face;
    this.requestRender();
  }

  /** Removes the shown mesh and frees its GPU buffers. */
  clear() {
    if (!this.parts) return;
    for (const part of [this.parts.shaded, this.parts.wire, this.parts.borders, this.parts.open, this.parts.pickedMesh]) {
      this.group.remove(part);
    }
    if (this.parts.shaded.isGroup) for (const m of this.parts.shaded.children) m.geometry.dispose();
    this.parts.pickedMesh.geometry.dispose();
    this.parts.geometry.dispose();
    this.parts.wire.geometry.dispose();
    this.parts.borders.geometry.dispose();
    this.parts.open.geometry.dispose();
    this.parts = null;
    this.empty = false;
    this.requestRender();
  }

  /** Display toggles: faceColors, wireframe, borders, openEdges (booleans). */
  set(options) {
    Object.assign(this.options, options);
    this.apply();
  }

  apply() {
    if (!this.parts) return;
    const o = this.options;
    const materials = o.faceColors ? this.faceMaterials : this.plainMaterials;
    if (this.parts.shaded.isGroup) for (const m of this.parts.shaded.children) m.material = materials;
    else this.parts.shaded.material = materials;
    const overlays = this.parts.overlays;
    this.parts.wire.visible = overlays && o.wireframe;
    this.parts.borders.visible = overlays && o.borders;
    this.parts.open.visible = overlays && o.openEdges;
    this.requestRender();
  }

  /** Frames the mesh: looks from the front-right-top, close enough that its bounding box just fits. */
  fit() {
    if (!this.parts) return;
    const box = this.parts.geometry.boundingBox;
    const center = box.getCenter(new THREE.Vector3());
    const dir = new THREE.Vector3(0.5, -0.9, 0.65).normalize();
    // Camera axes for that direction (z up).
    const forward = dir.clone().negate();
    const right = new THREE.Vector3().crossVectors(forward, this.camera.up).normalize();
    const up = new THREE.Vector3().crossVectors(right, forward);
    const tanV = Math.tan(THREE.MathUtils.degToRad(this.camera.fov) / 2) * 0.9;
    const tanH = tanV * this.camera.aspect;
    let distance = 0;
    let depth = 0;
    for (let i = 0; i < 8; i++) {
      const corner = new THREE.Vector3(
        i & 1 ? box.max.x : box.min.x,
        i & 2 ? box.max.y : box.min.y,
        i & 4 ? box.max.z : box.min.z,
      ).sub(center);
      const z = corner.dot(forward);
      distance = Math.max(distance, Math.abs(corner.dot(right)) / tanH + z, Math.abs(corner.dot(up)) / tanV + z);
      depth = Math.max(depth, corner.length());
    }
    distance = Math.max(distance, 1e-6);
    this.controls.target.copy(center);
    this.camera.position.copy(center).addScaledVector(dir, distance);
    this.camera.near = Math.max(distance - depth, distance / 1000) / 2;
    this.camera.far = (distance + depth) * 4;
    this.camera.updateProjectionMatrix();
    this.controls.update();
    this.requestRender();
  }

  resize() {
    const box = this.canvas.parentElement.getBoundingClientRect();
    const width = Math.max(1, Math.floor(box.width));
    const height = Math.max(1, Math.floor(box.height));
    this.renderer.setSize(width, height, false);
    this.camera.aspect = width / height;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  /** Draws at the next frame; an empty view is cleared once, then left alone. */
  requestRender() {
    if (this.pending || (!this.parts && this.empty)) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.renderer.render(this.scene, this.camera);
      this.empty = !this.parts;
      if (this.onRendered) this.onRendered();
    });
  }
}

/** Where each instance's faces start in the merged mesh (instance after instance); null without instances. */
function instanceFaceStarts(result) {
  if (!result.instanced) return null;
  const { meshes, instances } = result.instanced;
  const starts = new Uint32Array(instances.length);
  let f = 0;
  instances.forEach((inst, k) => {
    starts[k] = f;
    f += meshes[inst.part].faceRanges.length / 2;
  });
  return starts;
}

/** Whether the context is drawn by a software rasterizer (SwiftShader, llvmpipe, ...). */
function isSoftware(gl) {
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
  return /swiftshader|llvmpipe|softpipe|software|basic render/i.test(name);
}

function segments(array, material) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(array, 3));
  return new THREE.LineSegments(geometry, material);
}
