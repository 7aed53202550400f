#!/usr/bin/env node
// Writes the page's bundled samples (JSON models, README's format) next to
// this script. The files are committed; run again after changing a shape:
//   node www/samples/make.mjs
//
// grid50.json   50 bicubic Bézier patches (10 × 5) of one wavy sheet, sharing
//               their borders exactly: the page's default and its 1-second test.
// plate.json    one bicubic dome trimmed to a rounded slot plate with three
//               round holes (rational quadratic arcs in (u, v)).
// can.json      a closed can: four rational quarter-cylinders and two flat
//               caps trimmed to circles, sewn into one watertight shell.
// freeform.json a copy of tests/data/js_freeform.json (one bicubic patch with
//               non-uniform knots, the benchmarks' surface).
// can.igs       the same can as IGES 5.3: four B-spline surfaces (entity 128)
//               and two trimmed surfaces (144) bounded by curves on surface
//               (142) whose parameter-space circles are rational B-splines (126).

import { copyFileSync, writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const W = Math.SQRT1_2;
const round = (x) => Math.round(x * 1e6) / 1e6;

function save(name, model) {
  writeFileSync(join(here, name), `${JSON.stringify(model)}\n`);
  console.log(`wrote ${name}: ${model.faces.length} faces`);
}

/** Height of the wavy sheet at (x, y), mm. */
function sheet(x, y) {
  return 6 * Math.sin(x / 22) * Math.cos(y / 17) + 0.0009 * (x - 100) ** 2;
}

function grid50() {
  const cols = 10;
  const rows = 5;
  const size = 20;
  const faces = [];
  for (let r = 0; r < rows; r++) {
    for (let c = 0; c < cols; c++) {
      const points = [0, 1, 2, 3].map((i) =>
        [0, 1, 2, 3].map((j) => {
          const x = (c + i / 3) * size;
          const y = (r + j / 3) * size;
          return [round(x), round(y), round(sheet(x, y))];
        }),
      );
      const bezier = [0, 0, 0, 0, 1, 1, 1, 1];
      faces.push({ name: `patch ${r},${c}`, surface: { degree: [3, 3], knots: [bezier, bezier], points } });
    }
  }
  return { units: 'mm', faces };
}

function line(a, b) {
  return { degree: 1, knots: [0, 0, 1, 1], points: [a, b] };
}

/** Quarter arcs (rational quadratic) of a circle in (u, v), counter-clockwise from angle `start`. */
function arcs(cu, cv, ru, rv, start = 0) {
  const out = [];
  for (let k = 0; k < 4; k++) {
    const a0 = start + (k * Math.PI) / 2;
    const a1 = a0 + Math.PI / 2;
    const p = (a) => [round(cu + ru * Math.cos(a)), round(cv + rv * Math.sin(a))];
    const corner = [
      round(cu + ru * (Math.cos(a0) + Math.cos(a1))),
      round(cv + rv * (Math.sin(a0) + Math.sin(a1))),
    ];
    out.push({ degree: 2, knots: [0, 0, 0, 1, 1, 1], points: [p(a0), corner, p(a1)], weights: [1, W, 1] });
  }
  // Close exactly: each arc ends where the next starts.
  for (let k = 0; k < 4; k++) out[k].points[2] = out[(k + 1) % 4].points[0];
  return out;
}

function plate() {
  const lx = 120;
  const ly = 80;
  const points = [0, 1, 2, 3].map((i) =>
    [0, 1, 2, 3].map((j) => {
      const x = (i / 3) * lx;
      const y = (j / 3) * ly;
      const bump = (i === 1 || i === 2) && (j === 1 || j === 2) ? 18 : 0;
      return [x, y, bump];
    }),
  );
  const bezier = [0, 0, 0, 0, 1, 1, 1, 1];
  // Outer loop: a slot (two straight sides and two half-circle ends) in (u, v).
  const r = 0.4;
  const u0 = 0.1 + r * (ly / lx);
  const u1 = 0.9 - r * (ly / lx);
  const ru = r * (ly / lx);
  const half = (cu, from) => {
    const a = arcs(cu, 0.5, ru, r, from);
    return [a[0], a[1]];
  };
  const right = half(u1, -Math.PI / 2);
  const left = half(u0, Math.PI / 2);
  const outer = [
    line([u0, 0.1], [u1, 0.1]),
    ...right,
    line([u1, 0.9], [u0, 0.9]),
    ...left,
  ];
  // Chain exactly.
  outer[0].points[1] = right[0].points[0];
  outer[3].points[0] = right[1].points[2];
  outer[3].points[1] = left[0].points[0];
  outer[0].points[0] = left[1].points[2];
  const hole = (cu, cv, rr) => ({ curves: arcs(cu, cv, rr * (ly / lx), rr) });
  return {
    units: 'mm',
    faces: [
      {
        name: 'slotted dome',
        surface: { degree: [3, 3], knots: [bezier, bezier], points },
        loops: [{ curves: outer }, hole(0.3, 0.5, 0.14), hole(0.5, 0.5, 0.08), hole(0.7, 0.5, 0.14)],
      },
    ],
  };
}

function can() {
  const radius = 25;
  const height = 60;
  const faces = [];
  // Quarter cylinders: u along the arc (rational quadratic), v along the axis (linear).
  for (let k = 0; k < 4; k++) {
    const a0 = (k * Math.PI) / 2;
    const a1 = a0 + Math.PI / 2;
    const ring = [
      [radius * Math.cos(a0), radius * Math.sin(a0)],
      [radius * (Math.cos(a0) + Math.cos(a1)), radius * (Math.sin(a0) + Math.sin(a1))],
      [radius * Math.cos(a1), radius * Math.sin(a1)],
    ].map(([x, y]) => [round(x), round(y)]);
    faces.push({
      name: `side ${k}`,
      surface: {
        degree: [2, 1],
        knots: [[0, 0, 0, 1, 1, 1], [0, 0, 1, 1]],
        points: ring.map(([x, y]) => [[x, y, 0], [x, y, height]]),
        weights: [[1, 1], [W, W], [1, 1]],
      },
    });
  }
  // Caps: a square plane trimmed to the circle; the bottom one faces down.
  for (const [name, z, flip] of [['bottom', 0, true], ['top', height, false]]) {
    const s = radius * 1.2;
    const ys = flip ? [s, -s] : [-s, s];
    faces.push({
      name: `${name} cap`,
      surface: {
        degree: [1, 1],
        knots: [[0, 0, 1, 1], [0, 0, 1, 1]],
        points: [
          [[-s, ys[0], z], [-s, ys[1], z]],
          [[s, ys[0], z], [s, ys[1], z]],
        ],
      },
      loops: [{ curves: arcs(0.5, 0.5, radius / (2 * s), radius / (2 * s)) }],
    });
  }
  return { units: 'mm', faces };
}

// ---------------------------------------------------------------- IGES

/**
 * IGES 5.3 fixed-format text for `entities` ({ type, params, form?, dependent? }); entity i has
 * directory number 2i + 1. Parameters: numbers are written as reals, strings as they are (integers).
 */
function iges(entities, fileName) {
  const pad = (text, width) => text.padEnd(width).slice(0, width);
  const field = (v) => String(v).padStart(8);
  const seq = (letter, n) => `${letter}${String(n).padStart(7)}`;
  const hollerith = (t) => `${t.length}H${t}`;
  const num = (x) => (Number.isInteger(x) ? `${x}.` : String(x));
  const wrap = (tokens, width) => {
    const lines = [];
    let line = '';
    for (const t of tokens) {
      if (line.length + t.length > width) {
        lines.push(line);
        line = '';
      }
      line += t;
    }
    if (line) lines.push(line);
    return lines;
  };
  const start = [`surfmesh sample ${fileName}, written by www/samples/make.mjs`];
  const global = [
    '1H,', '1H;', hollerith('surfmesh'), hollerith(fileName), hollerith('surfmesh make.mjs'), hollerith('1'),
    '32', '38', '6', '308', '15', hollerith('surfmesh'), '1.', '2', hollerith('MM'), '1', '0.', hollerith('20260101.000000'),
    '1.E-06', '100.', hollerith('surfmesh'), hollerith('surfmesh'), '11', '0',
  ];
  const gLines = wrap(global.map((t, i) => `${t}${i === global.length - 1 ? ';' : ','}`), 72);
  const dLines = [];
  const pLines = [];
  entities.forEach((e, i) => {
    const de = 2 * i + 1;
    const tokens = [String(e.type), ...e.params.map((x) => (typeof x === 'string' ? x : num(x)))];
    const body = wrap(tokens.map((t, k) => `${t}${k === tokens.length - 1 ? ';' : ','}`), 64);
    const first = pLines.length + 1;
    for (const line of body) pLines.push(`${pad(line, 64)}${String(de).padStart(8)}${seq('P', pLines.length + 1)}`);
    const status = e.dependent ? '00010000' : '00000000';
    const one = [e.type, first, 0, 0, 0, 0, 0, 0].map(field).join('') + status;
    const two = [e.type, 0, 0, body.length, e.form ?? 0, '', '', '', 0].map(field).join('');
    dLines.push(`${one}${seq('D', de)}`, `${two}${seq('D', de + 1)}`);
  });
  const out = [
    ...start.map((l, i) => `${pad(l, 72)}${seq('S', i + 1)}`),
    ...gLines.map((l, i) => `${pad(l, 72)}${seq('G', i + 1)}`),
    ...dLines,
    ...pLines,
  ];
  const counts = `${seq('S', start.length)}${seq('G', gLines.length)}${seq('D', dLines.length)}${seq('P', pLines.length)}`;
  out.push(`${pad(counts, 72)}${seq('T', 1)}`);
  return `${out.join('\n')}\n`;
}

/** Entity 128 from a JSON surface ({ degree, knots, points[i][j], weights? }). */
function bspline128(surface) {
  const [p, q] = surface.degree;
  const nu = surface.points.length;
  const nv = surface.points[0].length;
  const w = (i, j) => (surface.weights ? surface.weights[i][j] : 1);
  const params = [nu - 1, nv - 1, p, q, 0, 0, surface.weights ? 0 : 1, 0, 0].map(String);
  params.push(...surface.knots[0], ...surface.knots[1]);
  for (let j = 0; j < nv; j++) for (let i = 0; i < nu; i++) params.push(w(i, j));
  for (let j = 0; j < nv; j++) for (let i = 0; i < nu; i++) params.push(...surface.points[i][j]);
  const u = surface.knots[0];
  const v = surface.knots[1];
  params.push(u[p], u[u.length - 1 - p], v[q], v[v.length - 1 - q]);
  return { type: 128, params };
}

/** Entity 126: a whole circle in (u, v) as one rational quadratic, nine control points. */
function circle126(cu, cv, r) {
  const knots = [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1];
  const corners = [[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1], [1, 0]];
  const weights = corners.map((_, k) => (k % 2 ? W : 1));
  const params = ['8', '2', '1', '1', '0', '0', ...knots, ...weights];
  for (const [x, y] of corners) params.push(cu + r * x, cv + r * y, 0);
  params.push(0, 1, 0, 0, 1);
  return { type: 126, params, dependent: true };
}

function canIges() {
  const model = can();
  const entities = [];
  const de = () => 2 * entities.length + 1;
  for (const face of model.faces) {
    if (!face.loops) {
      entities.push(bspline128(face.surface));
      continue;
    }
    const surface = de();
    entities.push({ ...bspline128(face.surface), dependent: true });
    const curve = de();
    entities.push(circle126(0.5, 0.5, face.loops[0].curves[0].points[0][0] - 0.5));
    const onSurface = de();
    entities.push({ type: 142, params: ['0', String(surface), String(curve), '0', '1'], dependent: true });
    entities.push({ type: 144, params: [String(surface), '1', '0', String(onSurface)] });
  }
  return iges(entities, 'can.igs');
}

save('grid50.json', grid50());
save('plate.json', plate());
save('can.json', can());
copyFileSync(join(here, '..', '..', 'tests', 'data', 'js_freeform.json'), join(here, 'freeform.json'));
console.log('copied freeform.json');
writeFileSync(join(here, 'can.igs'), canIges());
console.log('wrote can.igs');
