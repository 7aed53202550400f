// Writes a STEP (AP214) plate drilled with a grid of through holes: one
// closed shell of 6 + holes faces, its top and bottom each with one inner
// loop per hole. The stress part for the memory and speed figures (a part
// of 1000+ faces, faces with 80+ holes) without keeping a large file in the
// repository. With `bodies`, the same grid as one block per hole instead:
// a part of many independent solids (the scaling bench's other shape).
//
//   node bench/plate.mjs NX NY [--bodies] > plate.stp
//
// Holes sit on a 10 mm pitch, radius 3 mm, plate 5 mm thick; a block of the
// bodies variant is 8 mm square, 2 mm from its neighbours. Each hole is a
// cylinder face bounded by its two circles and a seam line, as CAD writers
// export them.

import { pathToFileURL } from 'node:url';

/**
 * The file's text for an `nx` × `ny` grid of holes: one plate, or with
 * `bodies` one solid block per hole.
 */
export function plateStep(nx, ny, { bodies = false } = {}) {
  const pitch = 10;
  const r = 3;
  const t = 5;
  const lines = [];
  let id = 0;
  const add = (text) => {
    id += 1;
    lines.push(`#${id}=${text};`);
    return `#${id}`;
  };
  const num = (x) => (Number.isInteger(x) ? `${x}.` : `${x}`);
  const point = (p) => add(`CARTESIAN_POINT('',(${p.map(num).join(',')}))`);
  const dir = (d) => add(`DIRECTION('',(${d.map(num).join(',')}))`);
  const axis = (o, z, x) => add(`AXIS2_PLACEMENT_3D('',${point(o)},${dir(z)},${dir(x)})`);
  const vertex = (p) => add(`VERTEX_POINT('',${point(p)})`);
  const sub = (a, b) => a.map((v, i) => v - b[i]);
  const len = (a) => Math.hypot(...a);
  const line = (a, b) => {
    const d = sub(b, a);
    const l = len(d);
    return add(`LINE('',${point(a)},${add(`VECTOR('',${dir(d.map((v) => v / l))},${num(l)})`)})`);
  };
  const edge = (va, vb, curve) => add(`EDGE_CURVE('',${va},${vb},${curve},.T.)`);
  const oriented = (e, sense) => add(`ORIENTED_EDGE('',*,*,${e},${sense ? '.T.' : '.F.'})`);
  const loop = (edges) => add(`EDGE_LOOP('',(${edges.join(',')}))`);
  const face = (name, bounds, surface, sense) =>
    add(`ADVANCED_FACE('${name}',(${bounds.join(',')}),${surface},${sense ? '.T.' : '.F.'})`);

  const unit = add('(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.))');
  const angle = add('(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.))');
  const solidAngle = add('(NAMED_UNIT(*)SI_UNIT($,.STERADIAN.)SOLID_ANGLE_UNIT())');
  const accuracy = add(`UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-06),${unit},'distance_accuracy_value','')`);
  const context = add(
    `(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((${accuracy}))` +
      `GLOBAL_UNIT_ASSIGNED_CONTEXT((${unit},${angle},${solidAngle}))REPRESENTATION_CONTEXT('',''))`,
  );

  // One closed shell: the box [x0, x1] × [y0, y1] × [0, t] with holes at `centres`.
  const solid = (name, [x0, y0], [x1, y1], centres) => {
    // The box: bottom corners b[i], top corners u[i], counter-clockwise from above.
    const corners = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]];
    const b = corners.map(([x, y]) => vertex([x, y, 0]));
    const u = corners.map(([x, y]) => vertex([x, y, t]));
    const at = (i, z) => [...corners[i % 4], z];
    const eb = [0, 1, 2, 3].map((i) => edge(b[i], b[(i + 1) % 4], line(at(i, 0), at(i + 1, 0))));
    const et = [0, 1, 2, 3].map((i) => edge(u[i], u[(i + 1) % 4], line(at(i, t), at(i + 1, t))));
    const ev = [0, 1, 2, 3].map((i) => edge(b[i], u[i], line(at(i, 0), at(i, t))));

    // Each hole: circles at both ends (counter-clockwise about +z) and a seam.
    const holes = [];
    for (const [cx, cy] of centres) {
      const vb = vertex([cx + r, cy, 0]);
      const vt = vertex([cx + r, cy, t]);
      const cb = edge(vb, vb, add(`CIRCLE('',${axis([cx, cy, 0], [0, 0, 1], [1, 0, 0])},${num(r)})`));
      const ct = edge(vt, vt, add(`CIRCLE('',${axis([cx, cy, t], [0, 0, 1], [1, 0, 0])},${num(r)})`));
      const seam = edge(vb, vt, line([cx + r, cy, 0], [cx + r, cy, t]));
      holes.push({ cx, cy, cb, ct, seam });
    }

    const faces = [];
    // Top (normal +z): outer loop counter-clockwise, holes clockwise.
    const topBounds = [add(`FACE_OUTER_BOUND('',${loop(et.map((e) => oriented(e, true)))},.T.)`)];
    for (const h of holes) topBounds.push(add(`FACE_BOUND('',${loop([oriented(h.ct, false)])},.T.)`));
    faces.push(face('top', topBounds, add(`PLANE('',${axis([0, 0, t], [0, 0, 1], [1, 0, 0])})`), true));
    // Bottom (normal -z): the same loops seen from below.
    const bottomBounds = [
      add(`FACE_OUTER_BOUND('',${loop([3, 2, 1, 0].map((i) => oriented(eb[i], false)))},.T.)`),
    ];
    for (const h of holes) bottomBounds.push(add(`FACE_BOUND('',${loop([oriented(h.cb, true)])},.T.)`));
    faces.push(face('bottom', bottomBounds, add(`PLANE('',${axis([0, 0, 0], [0, 0, -1], [1, 0, 0])})`), true));
    // Sides: outward normals, loops counter-clockwise seen from outside.
    for (let i = 0; i < 4; i += 1) {
      const along = sub(at(i + 1, 0), at(i, 0)).map((v) => v / len(sub(at(i + 1, 0), at(i, 0))));
      const out = [along[1], -along[0], 0];
      const edges = [oriented(eb[i], true), oriented(ev[(i + 1) % 4], true), oriented(et[i], false), oriented(ev[i], false)];
      const bound = add(`FACE_OUTER_BOUND('',${loop(edges)},.T.)`);
      faces.push(face(`side ${i + 1}`, [bound], add(`PLANE('',${axis(at(i, 0), out, along)})`), true));
    }
    // Hole walls: the cylinder's normal points away from its axis, into the
    // material, so each face takes the opposite sense.
    for (const [k, h] of holes.entries()) {
      const edges = [oriented(h.cb, true), oriented(h.seam, true), oriented(h.ct, false), oriented(h.seam, false)];
      const bound = add(`FACE_OUTER_BOUND('',${loop(edges)},.T.)`);
      const surface = add(`CYLINDRICAL_SURFACE('',${axis([h.cx, h.cy, 0], [0, 0, 1], [1, 0, 0])},${num(r)})`);
      faces.push(face(`hole ${k + 1}`, [bound], surface, false));
    }

    const shell = add(`CLOSED_SHELL('',(${faces.join(',')}))`);
    return add(`MANIFOLD_SOLID_BREP('${name}',${shell})`);
  };

  const centre = (i, j) => [(i + 0.5) * pitch, (j + 0.5) * pitch];
  const solids = [];
  if (bodies) {
    for (let i = 0; i < nx; i += 1) {
      for (let j = 0; j < ny; j += 1) {
        const [cx, cy] = centre(i, j);
        const half = 0.4 * pitch;
        solids.push(solid(`block ${i * ny + j + 1}`, [cx - half, cy - half], [cx + half, cy + half], [[cx, cy]]));
      }
    }
  } else {
    const centres = [];
    for (let i = 0; i < nx; i += 1) for (let j = 0; j < ny; j += 1) centres.push(centre(i, j));
    solids.push(solid('plate', [0, 0], [nx * pitch, ny * pitch], centres));
  }
  const rep = add(`ADVANCED_BREP_SHAPE_REPRESENTATION('',(${axis([0, 0, 0], [0, 0, 1], [1, 0, 0])},${solids.join(',')}),${context})`);
  const app = add("APPLICATION_CONTEXT('automotive design')");
  const product = add(`PRODUCT('Plate','Plate ${nx}x${ny} holes','',(${add(`PRODUCT_CONTEXT('',${app},'mechanical')`)}))`);
  const formation = add(`PRODUCT_DEFINITION_FORMATION('','',${product})`);
  const defContext = add(`PRODUCT_DEFINITION_CONTEXT('part definition',${app},'design')`);
  const definition = add(`PRODUCT_DEFINITION('design','',${formation},${defContext})`);
  add(`SHAPE_DEFINITION_REPRESENTATION(${add(`PRODUCT_DEFINITION_SHAPE('','',${definition})`)},${rep})`);

  return [
    'ISO-10303-21;',
    'HEADER;',
    `FILE_DESCRIPTION(('surfmesh stress ${bodies ? 'blocks' : 'plate'} ${nx}x${ny}'),'2;1');`,
    "FILE_NAME('plate.stp','2026-01-01T00:00:00',(''),(''),'','','');",
    "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));",
    'ENDSEC;',
    'DATA;',
    ...lines,
    'ENDSEC;',
    'END-ISO-10303-21;',
    '',
  ].join('\n');
}

if (process.argv[1] && import.meta.url === pathToFileURL(process.argv[1]).href) {
  const args = process.argv.slice(2);
  const [nx, ny] = args.filter((a) => a !== '--bodies').map(Number);
  if (!(nx >= 1 && ny >= 1 && Number.isInteger(nx) && Number.isInteger(ny))) {
    console.error('usage: node bench/plate.mjs NX NY [--bodies] > plate.stp');
    process.exit(2);
  }
  process.stdout.write(plateStep(nx, ny, { bodies: args.includes('--bodies') }));
}
