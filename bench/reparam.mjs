// Poorly parameterized surfaces (paper 001), side by side: OCCT's mesher
// (occt-import-js) against surfmesh with `--reparam off` and `auto`, on the
// crowded surfaces of tests/data (90% of a parameter range covering 5% of the
// surface), at the same absolute tolerance. The surfaces go to OCCT as IGES
// written by surfmesh's own writer (`surfmesh reparam --reparam off`: the
// ORIGINAL geometry, 128 or 144/142 trimmed), and every mesh, whoever made it,
// is measured against the original surfaces by surfmesh's yardstick
// (examples/measure.rs). A second table gives, per face the ratio test flags
// (the crowded surfaces and the corpus), triangles and 1st-percentile angle
// with off and auto and the measured deviation (examples/reparam_table.rs).
//
//   node bench/reparam.mjs [--tols 1e-2,1e-3] [--no-build] [--no-corpus] [--profile release]
//
// Prints the Markdown tables on stdout.

import { spawnSync } from 'node:child_process';
import { existsSync, mkdtempSync, readdirSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { basename, dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const argv = process.argv.slice(2);
const opt = (name, fallback) => {
  const i = argv.indexOf(name);
  return i >= 0 ? argv[i + 1] : fallback;
};
const TOLS = opt('--tols', '1e-2,1e-3').split(',').map(Number);
const PROFILE = opt('--profile', 'release');
const ANGLE = 0.5; // surfmesh's default angle; OCCT's angular deflection
const CASES = ['crowded_u.json', 'crowded_uv.json', 'crowded_trimmed.json', 'crowded_tube.json'];
const CORPUS_DIR = join(root, '..', 'shared', 'corpus');
const targetDir = process.env.CARGO_TARGET_DIR ?? join(root, 'target');
const binDir = join(targetDir, PROFILE === 'dev' ? 'debug' : PROFILE);
const bin = {
  surfmesh: join(binDir, 'surfmesh'),
  measure: join(binDir, 'examples', 'measure'),
  table: join(binDir, 'examples', 'reparam_table'),
};
const tmp = mkdtempSync(join(tmpdir(), 'surfmesh-reparam-'));
const say = (...a) => console.error('[reparam]', ...a);

function sh(cmd, args, what) {
  const r = spawnSync(cmd, args, { cwd: root, encoding: 'utf8', maxBuffer: 1 << 30 });
  if (r.error) throw r.error;
  if (r.status !== 0) throw new Error(`${what}: ${(r.stderr || r.stdout).trim().split('\n').pop()}`);
  return r.stdout;
}
const lastJson = (out) => JSON.parse(out.trim().split('\n').pop());

if (!argv.includes('--no-build')) {
  say(`cargo build --profile ${PROFILE} (CLI, yardstick, per-face table)`);
  const profile = PROFILE === 'debug' ? 'dev' : PROFILE;
  const r = spawnSync('cargo', ['build', '--profile', profile, '--bin', 'surfmesh', '--example', 'measure', '--example', 'reparam_table'], { cwd: root, stdio: 'inherit' });
  if (r.status !== 0) throw new Error('cargo build failed');
}

const measure = (model, mesh, tol) => lastJson(sh(bin.measure, [model, mesh, '--tol', String(tol)], 'measure'));

function surfmesh(model, rel, mode) {
  const mesh = join(tmp, `surfmesh-${mode}.obj`);
  const report = join(tmp, `surfmesh-${mode}.json`);
  sh(bin.surfmesh, ['mesh', model, '--tol-rel', String(rel), '--reparam', mode, '-o', mesh, '--report', report], 'surfmesh');
  const rep = JSON.parse(readFileSync(report, 'utf8'));
  const m = measure(model, mesh, rep.tolerance);
  return { tolerance: rep.tolerance, triangles: rep.triangles, deviation: m.max_deviation, p1: m.p1_angle_deg, ms: rep.time_ms };
}

function occt(igs, model, tol) {
  const out = join(tmp, 'occt.json');
  const args = [join(root, 'bench', 'run_one.mjs'), 'occt', igs, '--tol', String(tol), '--angle', String(ANGLE), '--unit', 'millimeter', '--runs', '1', '--out', out];
  const run = lastJson(sh('node', args, 'occt'));
  if (run.error) return { error: run.error };
  const m = measure(model, out, tol);
  return { triangles: m.triangles, deviation: m.max_deviation, p1: m.p1_angle_deg, coverage: m.coverage, ms: run.total_ms?.[0] };
}

const f3 = (x) => (x === undefined || x === null ? '–' : Number(x).toPrecision(3));
const f1 = (x) => (x === undefined || x === null ? '–' : Number(x).toFixed(1));

// ---- OCCT against surfmesh on the crowded surfaces ----------------------------------------
const rows = [];
for (const name of CASES) {
  const model = join(root, 'tests', 'data', name);
  const igs = join(tmp, name.replace(/\.json$/, '.igs'));
  sh(bin.surfmesh, ['reparam', model, '-o', igs, '--reparam', 'off'], 'surfmesh reparam');
  for (const rel of TOLS) {
    say(`${name} at ${rel}`);
    const off = surfmesh(model, rel, 'off');
    const auto = surfmesh(model, rel, 'auto');
    const oc = occt(igs, model, off.tolerance);
    rows.push({ name, rel, tol: off.tolerance, off, auto, occt: oc });
  }
}
const lines = [
  '### Crowded surfaces: OCCT and surfmesh at the same absolute tolerance, measured against the original surface',
  '',
  '| surface | tol-rel | tolerance | OCCT tris | OCCT deviation | OCCT dev / tol | OCCT p1° | surfmesh off tris | off deviation | off p1° | surfmesh auto tris | auto deviation | auto p1° |',
  '|---|---|---|---|---|---|---|---|---|---|---|---|---|',
];
for (const r of rows) {
  const o = r.occt;
  const occtCells = o.error
    ? [o.error, '', '', '']
    : [o.triangles, f3(o.deviation), `${(o.deviation / r.tol).toFixed(2)}${o.deviation > r.tol ? ' **over**' : ''}`, f1(o.p1)];
  lines.push(
    `| ${r.name.replace(/\.json$/, '')} | ${r.rel} | ${f3(r.tol)} | ${occtCells.join(' | ')} | ${r.off.triangles} | ${f3(r.off.deviation)} | ${f1(r.off.p1)} | ${r.auto.triangles} | ${f3(r.auto.deviation)} | ${f1(r.auto.p1)} |`,
  );
}
const over = rows.filter((r) => !r.occt.error && r.occt.deviation > r.tol).length;
const ours = rows.filter((r) => r.off.deviation <= r.tol && r.auto.deviation <= r.tol).length;
lines.push('', `OCCT over its own deflection: ${over} of ${rows.length} runs; surfmesh within tolerance (off and auto): ${ours} of ${rows.length}.`, '');

// ---- per flagged face: off against auto -------------------------------------------------
const files = CASES.map((n) => join(root, 'tests', 'data', n));
if (!argv.includes('--no-corpus') && existsSync(CORPUS_DIR)) {
  // Every corpus model with a face the ratio test flags.
  for (const n of readdirSync(CORPUS_DIR).filter((n) => /\.(igs|iges|stp|step)$/i.test(n)).sort()) {
    const p = join(CORPUS_DIR, n);
    const census = lastJson(sh(bin.table, ['--detect', p], 'reparam_table --detect'));
    if (census.flagged.length > 0) files.push(p);
  }
}
let won = 0;
let rowsTotal = 0;
lines.push(
  '### Every face the ratio test flags, meshed alone: off against auto (deviation measured against the original face)',
  '',
  '| file | face | step ratio | tol-rel | tolerance | tris off | tris auto | p1° off | p1° auto | deviation off | deviation auto | rebuild kept | auto wins | detect µs |',
  '|---|---|---|---|---|---|---|---|---|---|---|---|---|---|',
);
for (const file of files) {
  for (const rel of TOLS) {
    say(`table: ${basename(file)} at ${rel}`);
    const out = sh(bin.table, [file, '--tol-rel', String(rel)], 'reparam_table');
    for (const line of out.trim().split('\n').filter(Boolean)) {
      const r = JSON.parse(line);
      const [o, a] = [r.off, r.auto];
      if (o.error || a.error) {
        lines.push(`| ${r.file} | ${r.face} | ${f1(r.ratio)} | ${rel} | ${f3(r.tolerance)} | ${o.error ?? ''} ${a.error ?? ''} |`);
        continue;
      }
      // The acceptance: no more triangles, a higher 1st-percentile angle, within tolerance of the original.
      const wins = a.triangles <= o.triangles && a.p1_angle > o.p1_angle && a.measured <= r.tolerance;
      rowsTotal += 1;
      won += wins ? 1 : 0;
      const p2 = (x) => Number(x).toFixed(2);
      lines.push(
        `| ${r.file} | ${r.face} | ${f1(r.ratio)} | ${rel} | ${f3(r.tolerance)} | ${o.triangles} | ${a.triangles} | ${p2(o.p1_angle)} | ${p2(a.p1_angle)} | ${f3(o.measured)} | ${f3(a.measured)} | ${a.rebuilt ? 'yes' : 'no (guard)'} | ${wins ? 'yes' : 'no'} | ${r.detect_us.toFixed(0)} |`,
      );
    }
  }
}
lines.push('', `auto wins (no more triangles, higher 1st-percentile angle, within tolerance): ${won} of ${rowsTotal} rows.`);
console.log(lines.join('\n'));
rmSync(tmp, { recursive: true, force: true });
