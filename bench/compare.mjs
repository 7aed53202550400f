// Side-by-side benchmark: surfmesh (wasm in Node, and native) against
// occt-import-js (OCCT's mesher in wasm), verb-nurbs (JS) and the curvo crate
// (native), on every JSON surface in tests/data/ and every file of
// ../shared/corpus/ that surfmesh reads, and two drilled plates (bench/plate.mjs),
// at relative tolerances 1e-2 and 1e-3.
//
// Every mesh, whoever made it, is measured by the same code (examples/measure.rs,
// i.e. surfmesh::measure_mesh): deviation from the exact surfaces, coverage,
// edges after welding, angles. The peers' settings:
//   - OCCT: the same absolute linear deflection as surfmesh's tolerance and
//     angular deflection 0.5 (surfmesh's default angle); then the deflection is
//     rescaled until OCCT's measured deviation matches surfmesh's, so that
//     triangle counts compare at equal verified deviation;
//   - verb-nurbs and curvo (JSON surfaces): normTol lowered until their measured
//     deviation is no larger than surfmesh's (verb cannot trim: trimmed files skip it).
// Times: median of RUNS runs after a warm-up, parse and mesh apart where the
// mesher allows. Memory: peak resident set of a process that runs one mesher
// on one file (Node: above a bare Node's).
//
// npm run bench [-- --runs 5 --tols 1e-2,1e-3 --only NAME[,NAME...] --dir DIR --no-corpus --no-plates
//                   --no-build --no-wasm --no-equal --no-scaling --out DIR --profile debug]
// Writes DIR/latest.json and DIR/latest.md (DIR: bench/results). Builds what it
// needs first: the CLI and the two example runners (cargo, release unless
// --profile debug), and the npm package when it is older than the sources.
//   --only: files whose names contain any of the comma-separated parts.
//   --dir: the CAD files of DIR instead of ../shared/corpus (e.g.
//     ../shared/corpus-wide, with --only to pick some of them).
//   --no-wasm: surfmesh's native build only (no npm package needed); its
//     mesh stands for surfmesh in the comparisons and times are native
//     against OCCT's wasm.
//   --no-equal: OCCT at surfmesh's deflection only (no rescaled runs): enough
//     for the edge counts, which the report lists per file beside surfmesh's.
//   --no-scaling: without the scaling section (bench/scaling.mjs: plates and
//     parts of 10 to 4000 holes, wasm against OCCT), which runs last
//     otherwise (not with --only or --no-wasm).

import { spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, mkdtempSync, readdirSync, readFileSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { cpus, loadavg, tmpdir } from 'node:os';
import { dirname, extname, join, relative } from 'node:path';
import { fileURLToPath } from 'node:url';
import { plateStep } from './plate.mjs';
import { scaling } from './scaling.mjs';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const argv = process.argv.slice(2);
const opt = (name, fallback) => {
  const i = argv.indexOf(name);
  return i >= 0 ? argv[i + 1] : fallback;
};
const RUNS = Math.max(1, Number(opt('--runs', 5)));
const TOLS = opt('--tols', '1e-2,1e-3').split(',').map(Number);
const ONLY = opt('--only')?.split(',').filter(Boolean);
const CORPUS = opt('--dir', join(root, '..', 'shared', 'corpus'));
const WASM = !argv.includes('--no-wasm');
const EQUAL = !argv.includes('--no-equal');
const ANGLE = 0.5; // surfmesh's default angle; OCCT's angular deflection
const CHILD_TIMEOUT_MS = Number(opt('--timeout', 120)) * 1000;
/** The first native run of each file: longer than this and the file is skipped. */
const PREFLIGHT_MS = Number(opt('--preflight', 10)) * 1000;
const PROFILE = opt('--profile', 'release');
const OUT_DIR = opt('--out', join(root, 'bench', 'results'));
const targetDir = process.env.CARGO_TARGET_DIR ?? join(root, 'target');
const binDir = join(targetDir, PROFILE === 'dev' ? 'debug' : PROFILE);
const bin = {
  surfmesh: join(binDir, 'surfmesh'),
  measure: join(binDir, 'examples', 'measure'),
  curvo: join(binDir, 'examples', 'curvo_mesh'),
};
const tmp = mkdtempSync(join(tmpdir(), 'surfmesh-bench-'));
const started = Date.now();
const say = (...a) => console.error(`[${((Date.now() - started) / 1000).toFixed(0).padStart(4)} s]`, ...a);

// ---- building --------------------------------------------------------------------------
function sh(cmd, args, options = {}) {
  const r = spawnSync(cmd, args, { cwd: root, encoding: 'utf8', maxBuffer: 1 << 30, ...options });
  if (r.error) throw r.error;
  return r;
}

function newestSource() {
  let newest = 0;
  const walk = (dir) => {
    for (const e of readdirSync(dir, { withFileTypes: true })) {
      const p = join(dir, e.name);
      if (e.isDirectory()) walk(p);
      else newest = Math.max(newest, statSync(p).mtimeMs);
    }
  };
  walk(join(root, 'src'));
  for (const f of ['Cargo.toml', 'Cargo.lock', 'wasm-pack.toml']) newest = Math.max(newest, statSync(join(root, f)).mtimeMs);
  return newest;
}

function build() {
  say(`cargo build --profile ${PROFILE} (CLI, yardstick, curvo runner)`);
  const profile = PROFILE === 'debug' ? 'dev' : PROFILE;
  const args = ['build', '--profile', profile, '--bin', 'surfmesh', '--example', 'measure', '--example', 'curvo_mesh'];
  if (sh('cargo', args, { stdio: 'inherit' }).status !== 0) throw new Error('cargo build failed');
  const wasm = join(root, 'pkg', 'node', 'surfmesh_bg.wasm');
  if (WASM && (!existsSync(wasm) || statSync(wasm).mtimeMs < newestSource())) {
    say('npm package out of date: node scripts/build-wasm.mjs');
    if (sh('node', ['scripts/build-wasm.mjs'], { stdio: 'inherit' }).status !== 0) throw new Error('wasm build failed');
  }
}

// ---- running ---------------------------------------------------------------------------
/** Last line of stdout as JSON (a mesher may print before it), or {error}. */
function lastJson(r, what) {
  if (r.error?.code === 'ETIMEDOUT' || r.signal) return { error: `${what}: timed out after ${CHILD_TIMEOUT_MS / 1000} s` };
  const line = (r.stdout ?? '').trim().split('\n').pop();
  try {
    return JSON.parse(line);
  } catch {
    return { error: `${what}: ${(r.stderr || r.stdout || `exit ${r.status}`).trim().split('\n').pop()}` };
  }
}

function node(args, what) {
  return lastJson(spawnSync('node', [join(root, 'bench', 'run_one.mjs'), ...args], { cwd: root, encoding: 'utf8', maxBuffer: 1 << 30, timeout: CHILD_TIMEOUT_MS }), what);
}

/**
 * A native command under /usr/bin/time (peak RSS, KB) and coreutils' timeout
 * (killed after `timeout` ms: inside /usr/bin/time, so the command itself dies).
 */
function native(cmd, args, what, timeout = CHILD_TIMEOUT_MS) {
  const rssFile = join(tmp, 'rss.txt');
  rmSync(rssFile, { force: true });
  const limited = ['timeout', '--signal=KILL', String(Math.ceil(timeout / 1000)), cmd, ...args];
  const useTime = existsSync('/usr/bin/time');
  const r = useTime
    ? spawnSync('/usr/bin/time', ['-f', '%M', '-o', rssFile, ...limited], { encoding: 'utf8', maxBuffer: 1 << 30 })
    : spawnSync(limited[0], limited.slice(1), { encoding: 'utf8', maxBuffer: 1 << 30 });
  if (r.status === 137 || r.status === 124) r.signal = 'SIGKILL';
  const rss = useTime && existsSync(rssFile) ? Number(readFileSync(rssFile, 'utf8').trim().split('\n').pop()) : null;
  return { r, rss: Number.isFinite(rss) ? rss : null, what };
}

function measure(model, mesh, tol) {
  const r = spawnSync(bin.measure, [model, mesh, '--tol', String(tol)], { encoding: 'utf8', maxBuffer: 1 << 28, timeout: CHILD_TIMEOUT_MS * 2 });
  return lastJson(r, 'measure');
}

const median = (xs) => {
  const s = xs.filter((x) => x !== null && Number.isFinite(x)).sort((a, b) => a - b);
  if (!s.length) return null;
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
};

const OCCT_UNITS = { mm: 'millimeter', millimeter: 'millimeter', cm: 'centimeter', m: 'meter', meter: 'meter', in: 'inch', inch: 'inch', ft: 'foot', foot: 'foot' };

// ---- one mesher at a time ------------------------------------------------------------
function runSurfmeshWasm(file, rel) {
  const out = join(tmp, 'surfmesh-wasm.json');
  const run = node(['surfmesh', file, '--rel', String(rel), '--runs', String(RUNS), '--out', out], 'surfmesh wasm');
  if (run.error) return { run };
  return { run, mesh: out, tolerance: run.report.tolerance };
}

function runSurfmeshNative(file, rel) {
  const out = join(tmp, 'surfmesh-native.obj'); // full precision, a group per face
  const report = join(tmp, 'surfmesh-native-report.json');
  const times = { parse_ms: [], mesh_ms: [], total_ms: [] };
  let rss = 0;
  for (let k = 0; k <= RUNS; k++) {
    rmSync(out, { force: true });
    rmSync(report, { force: true });
    const args = ['mesh', file, '--tol-rel', String(rel), '-o', out, '--report', report];
    const { r, rss: kb } = native(bin.surfmesh, args, 'surfmesh native', k === 0 ? PREFLIGHT_MS : CHILD_TIMEOUT_MS);
    if (r.status !== 0 || !existsSync(report)) {
      const timedOut = r.error?.code === 'ETIMEDOUT' || r.signal;
      const why = timedOut ? `timed out after ${(k === 0 ? PREFLIGHT_MS : CHILD_TIMEOUT_MS) / 1000} s` : (r.stderr || '').trim().split('\n').pop();
      return { run: { error: `surfmesh: ${why.replace(/^surfmesh: [^:]*: /, '')}` } };
    }
    const rep = JSON.parse(readFileSync(report, 'utf8'));
    rss = Math.max(rss, kb ?? 0);
    if (k === 0) continue; // warm-up: file cache
    times.parse_ms.push(rep.parse_ms);
    times.mesh_ms.push(rep.time_ms);
    times.total_ms.push(rep.parse_ms + rep.time_ms);
    times.triangles = rep.triangles;
  }
  return { run: { ...times, rss_kb: rss }, mesh: out };
}

/** Without the npm package: the native build's mesh (an OBJ with a group per face) stands for surfmesh. */
function nativeAsOurs(sn) {
  const report = JSON.parse(readFileSync(join(tmp, 'surfmesh-native-report.json'), 'utf8'));
  const { warnings, ...rest } = report;
  const run = { ...sn.run, report: rest, warnings: warnings.slice(0, 5), native: true };
  return { run, mesh: sn.mesh, tolerance: report.tolerance };
}

function runOcct(file, tol, unit, target) {
  const same = join(tmp, 'occt.json');
  const run = node(['occt', file, '--tol', String(tol), '--angle', String(ANGLE), '--unit', unit, '--runs', String(RUNS), '--out', same], 'occt');
  if (run.error) return { run };
  const m = measure(file, same, tol);
  const result = { run, deflection: tol, measure: m };
  if (m.error || !(target > 0) || !EQUAL) return result;
  // Equal verified deviation: rescale the deflection (a few single runs).
  const tried = [{ deflection: tol, triangles: m.triangles, max_deviation: m.max_deviation }];
  let best = m.max_deviation <= target ? { deflection: tol, measure: m } : null;
  let defl = tol;
  let dev = m.max_deviation;
  for (let k = 0; k < 3; k++) {
    if (dev <= target && dev >= 0.8 * target) break;
    const scale = Math.min(4, Math.max(0.25, target / Math.max(dev, 1e-300)));
    defl *= dev > target ? scale * 0.95 : scale;
    const path = join(tmp, 'occt-eq.json');
    const r = node(['occt', file, '--tol', String(defl), '--angle', String(ANGLE), '--unit', unit, '--runs', '1', '--out', path], 'occt');
    if (r.error) break;
    const mm = measure(file, path, tol);
    if (mm.error) break;
    dev = mm.max_deviation;
    tried.push({ deflection: defl, triangles: mm.triangles, max_deviation: dev });
    if (dev <= target && (!best || mm.triangles < best.measure.triangles)) best = { deflection: defl, measure: mm };
  }
  return { ...result, equal: best, tried };
}

/** Why a peer's search failed, with the closest it came. */
function notReached(peer, target, search) {
  const best = (search.tried ?? []).reduce((b, t) => (!b || t.max_deviation < b.max_deviation ? t : b), null);
  const closest = best ? `; closest ${best.max_deviation.toPrecision(3)} with ${best.triangles} triangles` : '';
  return `${peer} did not reach deviation ${target.toPrecision(3)}${closest}`;
}

function runVerb(file, tol, target) {
  const search = node(['verb', file, '--match', String(target), '--tol', String(tol), '--measure', bin.measure], 'verb search');
  if (search.error || !search.reached) return { search, run: { error: search.error ?? notReached('verb', target, search) } };
  const out = join(tmp, 'verb.json');
  const run = node(['verb', file, '--norm-tol', String(search.norm_tolerance), '--runs', String(RUNS), '--out', out], 'verb');
  if (run.error) return { search, run };
  return { search, run, measure: measure(file, out, tol) };
}

function runCurvo(file, tol, target) {
  const search = lastJson(spawnSync(bin.curvo, [file, '--match', String(target)], { encoding: 'utf8', timeout: CHILD_TIMEOUT_MS * 2 }), 'curvo search');
  if (search.error || !search.reached) return { search, run: { error: search.error ?? notReached('curvo', target, search) } };
  const out = join(tmp, 'curvo.json');
  const { r, rss } = native(bin.curvo, [file, '--norm-tol', String(search.norm_tolerance), '--runs', String(RUNS), '-o', out], 'curvo');
  const run = lastJson(r, 'curvo');
  if (run.error) return { search, run };
  run.total_ms = run.parse_ms.map((p, i) => p + run.mesh_ms[i]);
  run.rss_kb = rss;
  return { search, run, measure: measure(file, out, tol) };
}

// ---- the inputs ------------------------------------------------------------------------
function inputs() {
  const formats = JSON.parse(sh(bin.measure, ['formats']).stdout);
  const list = [];
  const skipped = [];
  const data = join(root, 'tests', 'data');
  for (const f of readdirSync(data).sort()) {
    if (!f.endsWith('.json') || f.startsWith('bad_')) continue;
    list.push({ path: join(data, f), name: f, kind: 'json' });
  }
  const corpus = CORPUS;
  if (existsSync(corpus) && !argv.includes('--no-corpus')) {
    for (const f of readdirSync(corpus).sort()) {
      const ext = extname(f).slice(1).toLowerCase();
      if (!ext || f === 'SOURCES.md') continue;
      if (formats.includes(ext)) list.push({ path: join(corpus, f), name: f, kind: 'cad' });
      else skipped.push({ name: f, reason: `surfmesh does not read .${ext} yet` });
    }
  }
  // Stress parts written here (bench/plate.mjs): a face with 100 holes, and
  // a part of 1006 faces whose top and bottom have 1000 holes each.
  if (!argv.includes('--no-corpus') && !argv.includes('--no-plates')) {
    for (const [nx, ny] of [[10, 10], [25, 40]]) {
      const name = `plate_${nx}x${ny}_holes.stp`;
      const path = join(tmp, name);
      writeFileSync(path, plateStep(nx, ny));
      list.push({ path, name, kind: 'cad' });
    }
  }
  return { list: list.filter((x) => !ONLY || ONLY.some((part) => x.name.includes(part))), skipped, formats };
}

// ---- one file at one tolerance ------------------------------------------------------------
function benchOne(input, rel, info) {
  const row = { file: input.name, kind: input.kind, rel, faces: info.faces, units: info.units };
  // Native first: its warm-up run is the pre-flight (a failure or a hang skips the rest).
  say(`${input.name} @ ${rel}: surfmesh (native)`);
  const sn = runSurfmeshNative(input.path, rel);
  row.surfmesh_native = { run: sn.run };
  if (sn.run.error) {
    row.surfmesh_wasm = { run: { error: sn.run.error } };
    return row;
  }
  say(`${input.name} @ ${rel}: surfmesh (${WASM ? 'wasm' : 'native, measured'})`);
  const sw = WASM ? runSurfmeshWasm(input.path, rel) : nativeAsOurs(sn);
  row.surfmesh_wasm = { run: sw.run };
  if (sw.run.error) return row;
  row.tolerance = sw.tolerance;
  row.surfmesh_wasm.measure = measure(input.path, sw.mesh, sw.tolerance);
  // Deviations at rounding level (planes) are equal whoever reaches them.
  const target = Math.max(row.surfmesh_wasm.measure.max_deviation, 1e-6 * sw.tolerance);
  // The two builds run the same code: measure the native mesh only if it differs.
  if (sn.run.triangles === sw.run.triangles) row.surfmesh_native.measure = row.surfmesh_wasm.measure;
  else {
    row.surfmesh_native.measure = measure(input.path, sn.mesh, sw.tolerance);
    row.surfmesh_native.note = `the native build made ${sn.run.triangles} triangles, the wasm build ${sw.run.triangles}`;
  }
  if (input.kind === 'cad') {
    const unit = OCCT_UNITS[String(info.units).toLowerCase()];
    say(`${input.name} @ ${rel}: occt-import-js`);
    row.occt = unit ? runOcct(input.path, sw.tolerance, unit, target) : { run: { error: `unit ${info.units} has no OCCT name` } };
  } else {
    if (info.trimmed_faces > 0) row.verb = { run: { skipped: 'verb-nurbs has no trimmed-surface tessellation' } };
    else {
      say(`${input.name} @ ${rel}: verb-nurbs`);
      row.verb = runVerb(input.path, sw.tolerance, target);
    }
    say(`${input.name} @ ${rel}: curvo`);
    row.curvo = runCurvo(input.path, sw.tolerance, target);
  }
  return row;
}

// ---- comparing -------------------------------------------------------------------------
const PEERS = [
  { key: 'occt', label: 'OCCT (occt-import-js, wasm)', ours: 'surfmesh_wasm', js: true },
  { key: 'verb', label: 'verb-nurbs (JS)', ours: 'surfmesh_wasm', js: true },
  { key: 'curvo', label: 'curvo (native)', ours: 'surfmesh_native', js: false },
];

const memKb = (run, js) => (run?.rss_kb == null ? null : js ? Math.max(1, run.rss_kb - run.base_rss_kb) : run.rss_kb);
const totalMs = (run) => median(run?.total_ms ?? []);
/** Cracks as the yardstick can tell them: cracks with face ranges, else every boundary edge. */
const defects = (m) => (m ? (m.face_ranges ? m.free_edges : m.boundary_edges) + m.nonmanifold_edges : null);

function compare(row, peer) {
  const p = row[peer.key];
  const ours = row[peer.ours];
  if (!p || !ours?.measure || ours.run?.error) return null;
  if (p.run?.skipped || p.run?.error) return { peer: peer.key, note: p.run.skipped ?? p.run.error };
  const eq = peer.key === 'occt' ? p.equal?.measure : p.measure;
  // Quality from the wasm build's mesh: it carries face ranges, so cracks can be
  // told from the open boundary (the native build writes the same mesh as STL).
  const sm = row.surfmesh_wasm.measure;
  const c = { peer: peer.key };
  c.triangles = eq ? sm.triangles / eq.triangles : null;
  if (!eq) c.note = `${peer.key} did not reach surfmesh's deviation ${sm.max_deviation?.toPrecision(3) ?? '(none measured)'}`;
  c.time = totalMs(ours.run) / totalMs(p.run);
  c.memory = memKb(ours.run, peer.js) / memKb(p.run, peer.js);
  const pm = p.measure;
  c.defects = [defects(sm), defects(pm)];
  // Boundary edges of an open sheet are not defects: judge cracks on what both could tell.
  c.boundary = [sm.boundary_edges, pm?.boundary_edges];
  c.coverage = [sm.coverage, pm?.coverage];
  return c;
}

const verdict = (ratio, lowerIsBetter = true) =>
  ratio == null || !Number.isFinite(ratio) ? 'n/a' : Math.abs(ratio - 1) < 0.02 ? 'even' : (ratio < 1) === lowerIsBetter ? 'ahead' : 'behind';
const crackVerdict = ([a, b]) => (a == null || b == null ? 'n/a' : a < b ? 'ahead' : a > b ? 'behind' : 'even');
const geomean = (xs) => {
  const v = xs.filter((x) => x != null && Number.isFinite(x) && x > 0);
  return v.length ? Math.exp(v.reduce((s, x) => s + Math.log(x), 0) / v.length) : null;
};

// ---- report ----------------------------------------------------------------------------
const f3 = (x) => (x == null || !Number.isFinite(x) ? '–' : Number(x).toPrecision(3));
const fms = (x) => (x == null ? '–' : x < 10 ? x.toFixed(2) : x < 100 ? x.toFixed(1) : x.toFixed(0));
const fmb = (kb) => (kb == null ? '–' : (kb / 1024).toFixed(1));

function meshRow(label, setting, m, run, js) {
  if (run?.skipped || run?.error) return `| ${label} | ${setting} | ${run.skipped ?? run.error} ||||||||||||||`;
  const p = median(run?.parse_ms ?? []);
  return `| ${label} | ${setting} | ${m?.triangles ?? run?.triangles ?? '–'} | ${f3(m?.max_deviation)} | ${f3(m?.mean_deviation)} | ${f3(m?.coverage)} | ${m?.boundary_edges ?? '–'} | ${m?.face_ranges ? m.free_edges : 'n/a'} | ${m?.nonmanifold_edges ?? '–'} | ${m ? `${m.min_angle_deg.toFixed(1)} / ${m.p1_angle_deg.toFixed(1)}` : '–'} | ${fms(p)} | ${fms(median(run?.mesh_ms ?? []))} | ${fms(totalMs(run))} | ${fms(run?.cold_ms)} | ${fmb(memKb(run, js))} | ${wasmMemory(run)} |`;
}

/** Wasm linear memory, MB: surfmesh's after its first call (its peak) with the ratio to the mesh it returned; OCCT's heap. */
function wasmMemory(run) {
  if (run?.wasm_peak_bytes) {
    const ratio = run.output_bytes > 0 ? ` (${(run.wasm_peak_bytes / run.output_bytes).toFixed(1)}× output)` : '';
    return `${fmb(run.wasm_peak_bytes / 1024)}${ratio}`;
  }
  return run?.heap_bytes ? fmb(run.heap_bytes / 1024) : '–';
}

/** Reading speed of the CAD files in wasm: bytes over the reader's median time (each file once, at its first tolerance). */
function readingSpeed(rows) {
  const seen = new Set();
  const lines = [];
  for (const r of rows) {
    const ms = median(r.surfmesh_wasm?.run?.parse_ms ?? []);
    if (r.kind === 'json' || !r.bytes || !ms || seen.has(r.file)) continue;
    seen.add(r.file);
    lines.push(`| ${r.file} | ${(r.bytes / 1e6).toFixed(2)} | ${fms(ms)} | ${(r.bytes / 1e3 / ms).toFixed(1)} |`);
  }
  if (!lines.length) return [];
  return [
    '',
    '## Reading speed (surfmesh wasm)',
    '',
    "The reader's whole time: parsing the text and building every face with its trim loops (edges without pcurves are inverted onto their surfaces, which takes most of it). `cargo bench --bench readers` times the STEP text parsing alone, natively.",
    '',
    '| file | MB | read ms | MB/s |',
    '|---|---:|---:|---:|',
    ...lines,
  ];
}

function markdown(rows, meta) {
  const out = [];
  out.push(`# surfmesh side-by-side benchmark`);
  out.push('');
  out.push(`${meta.date}; ${meta.cpus}; Node ${meta.node}; load average at start ${meta.load.map((x) => x.toFixed(1)).join(' ')}; ${RUNS} timed runs per mesher (median).`);
  out.push('Ratios are surfmesh / peer; below 1 means surfmesh needs fewer triangles, less time or less memory. Triangles compare at equal verified deviation: each peer\'s setting is chosen so that its measured deviation is no larger than surfmesh\'s (OCCT: also shown at the same deflection). Time: wasm peers against surfmesh in wasm, curvo against surfmesh native; parse + mesh; surfmesh\'s mesh time includes measuring its own mesh against the exact surfaces (the verified deviation of its report), the peers\' does not. Cracks: free edges along another face\'s border (needs face ranges) plus non-manifold edges.');
  out.push('');
  out.push('## Summary (geometric means over the files each peer meshed)');
  out.push('');
  out.push('| peer | rel. tol | files | triangles at equal deviation | time | memory | cracks + non-manifold: ahead / even / behind |');
  out.push('|---|---|---:|---:|---:|---:|---|');
  for (const peer of PEERS) {
    for (const rel of TOLS) {
      const cs = rows.filter((r) => r.rel === rel).map((r) => compare(r, peer)).filter((c) => c && c.time != null);
      if (!cs.length) continue;
      const g = (k) => geomean(cs.map((c) => c[k]));
      const cv = cs.map((c) => crackVerdict(c.defects));
      const n = (v) => cv.filter((x) => x === v).length;
      const gt = g('triangles');
      const gtime = g('time');
      const gm = g('memory');
      out.push(`| ${peer.label} | ${rel} | ${cs.length} | ${f3(gt)} (${verdict(gt)}) | ${f3(gtime)} (${verdict(gtime)}) | ${f3(gm)} (${verdict(gm)}) | ${n('ahead')} / ${n('even')} / ${n('behind')} |`);
    }
  }
  out.push(...readingSpeed(rows));
  out.push('');
  out.push('## Edges per file (the yardstick\'s counts; OCCT at surfmesh\'s deflection)');
  out.push('');
  out.push('surfmesh\'s own report beside them: its weld distance can differ from the yardstick\'s. The yardstick counts per body, finding each face\'s body from the model faces nearest it; faces of two bodies that coincide and face one way can go to either.');
  out.push('');
  out.push('| file | rel. tol | surfmesh non-manifold | OCCT non-manifold | surfmesh cracks | OCCT cracks | surfmesh boundary | OCCT boundary | surfmesh report: free / non-manifold / inverted |');
  out.push('|---|---|---:|---:|---:|---:|---:|---:|---|');
  for (const r of rows) {
    const sm = r.surfmesh_wasm?.measure;
    const om = r.occt?.measure;
    if (!sm && !om) continue;
    const rep = r.surfmesh_wasm?.run?.report;
    const own = rep ? `${rep.free_edges} / ${rep.nonmanifold_edges} / ${rep.inverted_triangles}` : '–';
    const cell = (m, k) => (m && m[k] != null ? m[k] : r.occt?.run?.error && m === om ? 'failed' : '–');
    out.push(`| ${r.file} | ${r.rel} | ${cell(sm, 'nonmanifold_edges')} | ${cell(om, 'nonmanifold_edges')} | ${cell(sm, 'free_edges')} | ${cell(om, 'free_edges')} | ${cell(sm, 'boundary_edges')} | ${cell(om, 'boundary_edges')} | ${own} |`);
  }
  out.push('');
  out.push('## Per file');
  out.push('');
  out.push('| file | rel. tol | peer | triangles | cracks (s / peer) | time | memory |');
  out.push('|---|---|---|---|---|---|---|');
  for (const r of rows) {
    if (r.surfmesh_wasm?.run?.error) {
      out.push(`| ${r.file} | ${r.rel} | – | surfmesh failed: ${r.surfmesh_wasm.run.error} | | | |`);
      continue;
    }
    for (const peer of PEERS) {
      const c = compare(r, peer);
      if (!c) continue;
      if (c.time == null && c.note) {
        out.push(`| ${r.file} | ${r.rel} | ${peer.key} | ${c.note} | | | |`);
        continue;
      }
      const tri = c.triangles == null ? `n/a (${c.note})` : `${f3(c.triangles)}× ${verdict(c.triangles)}`;
      out.push(`| ${r.file} | ${r.rel} | ${peer.key} | ${tri} | ${c.defects[0]} / ${c.defects[1]} ${crackVerdict(c.defects)} | ${f3(c.time)}× ${verdict(c.time)} | ${f3(c.memory)}× ${verdict(c.memory)} |`);
    }
  }
  out.push('');
  out.push('## Every mesh, measured by the same yardstick');
  out.push('');
  out.push('Deviation: largest / mean distance from 15 points per triangle to the exact surfaces. Coverage: largest distance from exact-surface samples to the mesh (holes, dropped faces). Cracks need face ranges (n/a without). Angles: smallest / 1st percentile, degrees. Times: median of the timed runs after warm-up; first run: the first call in a fresh process (wasm compilation and JIT included; in-process runners only). Memory: peak RSS, MB (Node: above a bare Node process). Wasm memory: the module\'s linear memory after its first call, i.e. its peak, with the ratio to the typed arrays of the mesh it returned (surfmesh); OCCT\'s wasm heap.');
  for (const r of rows) {
    out.push('');
    out.push(`### ${r.file} at ${r.rel} (tolerance ${f3(r.tolerance)} ${r.units}, ${r.faces} faces)`);
    out.push('');
    out.push('| mesher | setting | triangles | max dev | mean dev | coverage | boundary | cracks | non-manifold | angles | parse ms | mesh ms | total ms | first run ms | memory MB | wasm memory MB |');
    out.push('|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|');
    out.push(meshRow(WASM ? 'surfmesh wasm' : 'surfmesh native (measured)', `rel ${r.rel}`, r.surfmesh_wasm?.measure, r.surfmesh_wasm?.run, true));
    if (r.surfmesh_native) out.push(meshRow('surfmesh native', `rel ${r.rel}`, r.surfmesh_native.measure, r.surfmesh_native.run, false));
    if (r.surfmesh_native?.note) out.push(`| | ${r.surfmesh_native.note} |||||||||||||||`);
    if (r.occt) {
      out.push(meshRow('OCCT', `deflection ${f3(r.occt.deflection)}, angle ${ANGLE}`, r.occt.measure, r.occt.run, true));
      if (r.occt.equal) out.push(meshRow('OCCT, equal deviation', `deflection ${f3(r.occt.equal.deflection)}`, r.occt.equal.measure, { triangles: r.occt.equal.measure.triangles }, true));
      else if (!r.occt.run?.error) out.push(`| OCCT, equal deviation | not reached in ${r.occt.tried?.length ?? 0} tries |||||||||||||||`);
    }
    for (const k of ['verb', 'curvo']) {
      if (!r[k]) continue;
      const setting = r[k].search?.reached ? `normTol ${f3(r[k].search.norm_tolerance)}` : '';
      out.push(meshRow(k, setting, r[k].measure, r[k].run, k === 'verb'));
    }
  }
  if (meta.skipped.length) {
    out.push('');
    out.push('## Not measured');
    out.push('');
    for (const s of meta.skipped) out.push(`- ${s.name}: ${s.reason}`);
  }
  return out.join('\n');
}

// ---- main ------------------------------------------------------------------------------
try {
  if (!argv.includes('--no-build')) build();
  const { list, skipped } = inputs();
  const meta = {
    date: new Date().toISOString(),
    cpus: `${cpus().length} × ${cpus()[0]?.model ?? 'cpu'}`,
    node: process.versions.node,
    load: loadavg(),
    runs: RUNS,
    tolerances: TOLS,
    skipped,
  };
  const rows = [];
  for (const input of list) {
    const info = lastJson(spawnSync(bin.measure, ['info', input.path], { encoding: 'utf8' }), 'info');
    if (info.error) {
      skipped.push({ name: input.name, reason: info.error });
      continue;
    }
    let failed = null;
    for (const rel of [...TOLS].sort((a, b) => b - a)) {
      // A finer tolerance only takes longer: after a failure at a coarser one, note it and move on.
      if (failed) {
        rows.push({ file: input.name, kind: input.kind, rel, faces: info.faces, units: info.units, surfmesh_wasm: { run: { error: failed } } });
        continue;
      }
      const row = benchOne(input, rel, info);
      row.bytes = statSync(input.path).size;
      rows.push(row);
      if (row.surfmesh_wasm?.run?.error) failed = `${row.surfmesh_wasm.run.error} (at ${rel}; not tried finer)`;
    }
  }
  let md = markdown(rows, meta);
  if (WASM && !ONLY && !argv.includes('--no-scaling')) {
    const s = await scaling({ runs: Math.min(RUNS, 2), say });
    md += `\n\n${s.markdown}`;
    meta.scaling = s.rows;
  }
  const dir = OUT_DIR;
  mkdirSync(dir, { recursive: true });
  writeFileSync(join(dir, 'latest.json'), `${JSON.stringify({ meta, rows, comparisons: rows.map((r) => PEERS.map((p) => compare(r, p)).filter(Boolean)) }, null, 1)}\n`);
  writeFileSync(join(dir, 'latest.md'), `${md}\n`);
  console.log(md);
  say(`done; wrote ${relative(root, join(dir, 'latest.md'))} and latest.json`);
} finally {
  rmSync(tmp, { recursive: true, force: true });
}
