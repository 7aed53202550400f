// Compares a sweep (`surfmesh check DIR --json NOW.json`) with a committed
// baseline of the same folder and tolerance, file by file, and fails when
// any file got worse:
//
//   - it fails (a read or mesh error, or --timeout) where it meshed before;
//   - fewer of its faces meshed;
//   - more cracks, non-manifold edges or inverted triangles;
//   - its deviation is above its tolerance (where it was not, or by more);
//   - it took over 10 s (where it took under 10 s, or over 1.5 times as long).
//
// What improved is printed too. A file the baseline has and the sweep lacks
// is a failure (the folder changed: regenerate the baseline); a new file is
// listed. Exit status 0 when nothing got worse, 1 when something did, 2 for
// bad arguments or unreadable files.
//
//   node scripts/check-baseline.mjs BASELINE.json NOW.json

import { readFileSync } from 'node:fs';

const SLOW_MS = 10_000;
const SLOWER = 1.5;

/**
 * The command that writes baseline `path` again, from the folder and the
 * tolerance its sweep records ("relative 0.01" or "absolute 0.5").
 */
export function regenerateCommand(path, sweep) {
  const [kind, value] = String(sweep.tolerance).split(' ');
  const tol = kind === 'absolute' ? `--tol ${value}` : `--tol-rel ${value}`;
  const units = sweep.units && sweep.units !== 'file' ? ` --units ${sweep.units}` : '';
  return (
    `cargo build --release --bin surfmesh && target/release/surfmesh check ${sweep.dir} ` +
    `${tol}${units} --timeout 60 --json ${path}`
  );
}

function load(path) {
  try {
    const sweep = JSON.parse(readFileSync(path, 'utf8'));
    if (!Array.isArray(sweep.files)) throw new Error('no "files" list');
    return sweep;
  } catch (e) {
    console.error(`check-baseline: ${path}: ${e.message}`);
    process.exit(2);
  }
}

/** The ways `now` is worse and better than `was` (two rows of one file), as lines. */
export function compareRows(was, now) {
  const worse = [];
  const better = [];
  if (was.ok && !now.ok) worse.push(`fails where it meshed before: ${now.error}`);
  if (!was.ok && now.ok) better.push(`meshes where it failed before (${was.error})`);
  if (was.ok && now.ok) {
    const counts = [
      ['faces_meshed', 'faces meshed', +1],
      ['cracks', 'cracks', -1],
      ['nonmanifold_edges', 'non-manifold edges', -1],
      ['inverted_triangles', 'inverted triangles', -1],
    ];
    for (const [key, name, good] of counts) {
      const d = (now[key] - was[key]) * good;
      if (d < 0) worse.push(`${name} ${was[key]} -> ${now[key]}`);
      if (d > 0) better.push(`${name} ${was[key]} -> ${now[key]}`);
    }
    const over = (r) => !(r.deviation_ratio <= 1);
    if (over(now) && (!over(was) || now.deviation_ratio > was.deviation_ratio)) {
      worse.push(`deviation ${fmt(now.deviation_ratio)} x tolerance (was ${fmt(was.deviation_ratio)})`);
    } else if (over(was) && !over(now)) {
      better.push(`deviation within tolerance (${fmt(was.deviation_ratio)} -> ${fmt(now.deviation_ratio)})`);
    }
  }
  if (now.ok && now.time_ms > SLOW_MS && (was.time_ms <= SLOW_MS || now.time_ms > SLOWER * was.time_ms)) {
    worse.push(`took ${secs(now.time_ms)} (was ${secs(was.time_ms)})`);
  } else if (was.ok && now.ok && was.time_ms > SLOW_MS && now.time_ms <= SLOW_MS) {
    better.push(`time ${secs(was.time_ms)} -> ${secs(now.time_ms)}`);
  }
  return { worse, better };
}

function fmt(x) {
  return x === null || x === undefined ? 'n/a' : Number(x).toPrecision(3);
}

function secs(ms) {
  return `${(ms / 1000).toFixed(1)} s`;
}

function main(argv) {
  if (argv.length !== 2) {
    console.error('usage: node scripts/check-baseline.mjs BASELINE.json NOW.json');
    process.exit(2);
  }
  const [base, now] = argv.map(load);
  if (base.tolerance !== now.tolerance || base.units !== now.units) {
    console.error(
      `check-baseline: the sweeps differ in settings: baseline ${base.tolerance} ${base.units}, ` +
        `now ${now.tolerance} ${now.units}`,
    );
    process.exit(2);
  }
  const byName = new Map(now.files.map((r) => [r.file, r]));
  const known = new Set(base.files.map((r) => r.file));
  const worse = [];
  const better = [];
  for (const was of base.files) {
    const r = byName.get(was.file);
    if (!r) {
      worse.push(`${was.file}: in the baseline, not in the sweep`);
      continue;
    }
    const c = compareRows(was, r);
    for (const w of c.worse) worse.push(`${was.file}: ${w}`);
    for (const b of c.better) better.push(`${was.file}: ${b}`);
  }
  const added = now.files.filter((r) => !known.has(r.file));
  const total = (s) => {
    const ok = s.files.filter((r) => r.ok);
    const sum = (k) => ok.reduce((a, r) => a + r[k], 0);
    return `${ok.length}/${s.files.length} files meshed, faces ${sum('faces_meshed')}/${sum('faces_in_file')}, ` +
      `${sum('cracks')} cracks, ${sum('nonmanifold_edges')} non-manifold, ${sum('inverted_triangles')} inverted`;
  };
  console.log(`baseline: ${total(base)}`);
  console.log(`now:      ${total(now)}`);
  if (better.length) {
    console.log(`\nimproved (${better.length}):`);
    for (const b of better) console.log(`  ${b}`);
  }
  if (added.length) {
    console.log(`\nnot in the baseline (${added.length}):`);
    for (const r of added) console.log(`  ${r.file}: ${r.ok ? 'meshes' : `fails: ${r.error}`}`);
  }
  if (worse.length) {
    console.log(`\nWORSE (${worse.length}):`);
    for (const w of worse) console.log(`  ${w}`);
  }
  console.log(
    `\n${worse.length ? 'check-baseline: worse than the baseline' : 'check-baseline: nothing worse than the baseline'}` +
      `${better.length || added.length ? '; to take the improvements as the new baseline' : '; to regenerate the baseline'}:\n  ${regenerateCommand(argv[0], base)}`,
  );
  process.exit(worse.length ? 1 : 0);
}

if (import.meta.url === `file://${process.argv[1]}`) main(process.argv.slice(2));
