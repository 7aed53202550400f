#!/usr/bin/env node
// Builds the npm package in pkg/ from wasm-pack.toml: per build ([builds.*]:
// the viewer build, the package's default entry, and the full build under
// full/) one cargo build of the cdylib for wasm32-unknown-unknown with that
// build's Cargo features, then per target `wasm-bindgen` (the CLI version
// pinned in Cargo.lock) and `wasm-opt` from the npm package `binaryen`
// (Debian's binaryen writes modules that do not load); wasm features beyond
// rustc's defaults (simd128) come from [build] target_features, other rustc
// codegen options (`-C NAME`) from [build] codegen. Ends with a
// size report: every .wasm raw, gzip -9 and brotli, and per build the 20 largest
// functions and sections (`twiggy top`, on a copy optimized with its names
// kept; scripts/setup.sh installs twiggy) and the bytes per crate or module,
// also written to pkg/SIZES.md.
// The plain-JS helpers in js/ (the three.js adapter and loader, and its
// worker) are copied beside the targets and exported as subpaths.
//
// Usage: node scripts/build-wasm.mjs [--build viewer|full ...] [--target web|bundler|nodejs ...] [--no-opt]

import { spawnSync } from 'node:child_process';
import { createHash } from 'node:crypto';
import { copyFileSync, existsSync, mkdirSync, readFileSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { dirname, join, relative } from 'node:path';
import { fileURLToPath } from 'node:url';
import { brotliCompressSync, constants as zlib, gzipSync } from 'node:zlib';
import { parse as parseToml } from 'smol-toml';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');

/**
 * Plain-JS helpers copied from js/ into the package root: the export subpath,
 * the module and its types, and the optional peer dependency it imports.
 */
const HELPERS = [
  { export: './three', file: 'three.mjs', types: 'three.d.mts', peer: ['three', '>=0.150.0'], extra: ['three-worker.mjs'] },
];

function fail(message) {
  console.error(`build-wasm: ${message}`);
  process.exit(1);
}

function run(cmd, args, options = {}) {
  console.log(`+ ${cmd} ${args.join(' ')}`);
  const r = spawnSync(cmd, args, { cwd: root, stdio: 'inherit', ...options });
  if (r.error) fail(`cannot run ${cmd}: ${r.error.message}`);
  if (r.status !== 0) fail(`${cmd} exited with status ${r.status}`);
}

function capture(cmd, args) {
  const r = spawnSync(cmd, args, { cwd: root, encoding: 'utf8' });
  if (r.error) fail(`cannot run ${cmd}: ${r.error.message}`);
  if (r.status !== 0) fail(`${cmd} ${args.join(' ')} failed:\n${r.stderr}`);
  return r.stdout;
}

function parseArgs(argv) {
  const picked = [];
  const builds = [];
  let opt = true;
  for (let i = 0; i < argv.length; i++) {
    if (argv[i] === '--target' && i + 1 < argv.length) picked.push(argv[++i]);
    else if (argv[i] === '--build' && i + 1 < argv.length) builds.push(argv[++i]);
    else if (argv[i] === '--no-opt') opt = false;
    else fail(`unknown argument ${argv[i]} (expected --build NAME, --target NAME or --no-opt)`);
  }
  return { picked, builds, opt };
}

function readConfig() {
  const config = parseToml(readFileSync(join(root, 'wasm-pack.toml'), 'utf8'));
  const build = config.build ?? {};
  const targets = config.targets ?? {};
  if (Object.keys(targets).length === 0) fail('wasm-pack.toml has no [targets.*]');
  for (const [name, t] of Object.entries(targets)) {
    for (const key of ['out_dir', 'export', 'condition']) {
      if (typeof t[key] !== 'string') fail(`wasm-pack.toml [targets.${name}] needs a string ${key}`);
    }
  }
  const builds = config.builds ?? {};
  if (Object.keys(builds).length === 0) fail('wasm-pack.toml has no [builds.*]');
  for (const [name, b] of Object.entries(builds)) {
    if (!Array.isArray(b.features) || typeof b.dir !== 'string' || typeof b.export !== 'string') {
      fail(`wasm-pack.toml [builds.${name}] needs features (a list), dir and export (strings)`);
    }
  }
  return {
    builds,
    profile: build.cargo_profile ?? 'release',
    optLevel: build.opt_level,
    stackSize: build.stack_size,
    targetFeatures: build.target_features ?? [],
    codegen: build.codegen ?? [],
    outName: build.out_name ?? 'surfmesh',
    packageDir: join(root, build.package_dir ?? 'pkg'),
    opt: config.wasm_opt ?? { enabled: false },
    targets,
  };
}

/** The wasm-bindgen version Cargo.lock pins; the CLI must be the same. */
function lockedBindgenVersion() {
  const lock = parseToml(readFileSync(join(root, 'Cargo.lock'), 'utf8'));
  const pkg = (lock.package ?? []).find((p) => p.name === 'wasm-bindgen');
  if (!pkg) fail('Cargo.lock has no wasm-bindgen package');
  return pkg.version;
}

function checkTools(opt) {
  const want = lockedBindgenVersion();
  const have = capture('wasm-bindgen', ['--version']).trim().split(/\s+/).pop();
  if (have !== want) {
    fail(`wasm-bindgen CLI is ${have}, Cargo.lock pins ${want}: cargo install wasm-bindgen-cli --version ${want} --locked`);
  }
  const wasmOpt = join(root, 'node_modules', '.bin', 'wasm-opt');
  if (opt && !existsSync(wasmOpt)) fail('node_modules/.bin/wasm-opt is missing: run `npm ci` first');
  return wasmOpt;
}

function gzipSize(path) {
  return gzipSync(readFileSync(path), { level: 9 }).length;
}

function kb(n) {
  return `${(n / 1024).toFixed(1)} KiB`;
}

/** package.json of one target folder, so the folder can be required or served alone. */
function targetManifest(name, cargo, outName) {
  const base = {
    name: cargo.name,
    version: cargo.version,
    description: cargo.description,
    license: cargo.license,
    types: `${outName}.d.ts`,
  };
  if (name === 'nodejs') return { ...base, type: 'commonjs', main: `${outName}.js` };
  return { ...base, type: 'module', main: `${outName}.js`, module: `${outName}.js`, sideEffects: [`./${outName}.js`, './snippets/*'] };
}

/** The package.json subpath of `target` in `build`: the build's prefix, then the target's own. */
function exportPath(build, target) {
  return target.export === '.' ? build.export : `${build.export}${target.export.slice(1)}`;
}

/** Top-level package.json: export conditions pick the target ("node" before "default"). */
function packageManifest(cargo, config, built) {
  const exports = {};
  const order = (c) => (c === 'default' ? 1 : 0);
  const entries = built.sort((a, b) => order(a.target.condition) - order(b.target.condition));
  for (const { build, target, dir } of entries) {
    const slot = (exports[exportPath(build, target)] ??= {});
    slot[target.condition] = { types: `./${dir}/${config.outName}.d.ts`, default: `./${dir}/${config.outName}.js` };
  }
  for (const h of HELPERS) exports[h.export] = { types: `./${h.types}`, default: `./${h.file}` };
  exports['./package.json'] = './package.json';
  return {
    name: cargo.name,
    version: cargo.version,
    description: cargo.description,
    license: cargo.license,
    files: [...new Set(built.map(({ dir }) => `${dir}/`)), ...HELPERS.flatMap((h) => [h.file, h.types, ...(h.extra ?? [])])],
    exports,
    peerDependencies: Object.fromEntries(HELPERS.map((h) => h.peer)),
    peerDependenciesMeta: Object.fromEntries(HELPERS.map((h) => [h.peer[0], { optional: true }])),
  };
}

/** The 20 largest items of `wasm` by twiggy, or a line saying why there are none. */
function twiggyTop(wasm) {
  const r = spawnSync('twiggy', ['top', '-n', '20', wasm], { cwd: root, encoding: 'utf8' });
  if (r.error) return `(twiggy not found: scripts/setup.sh installs it)`;
  if (r.status !== 0) return `(twiggy failed: ${r.stderr.trim()})`;
  return r.stdout.trimEnd();
}

/** One line of twiggy's CSV: fields split on commas outside quotes, `""` as a quote. */
function csvFields(line) {
  const out = [];
  let field = '';
  let quoted = false;
  for (let i = 0; i < line.length; i++) {
    const c = line[i];
    if (quoted && c === '"' && line[i + 1] === '"') field += line[++i];
    else if (c === '"') quoted = !quoted;
    else if (c === ',' && !quoted) {
      out.push(field);
      field = '';
    } else field += c;
  }
  out.push(field);
  return out;
}

/**
 * Where an item's bytes belong: the crate for dependencies and the standard
 * library (a generic's copy counts for the crate that defines it), the
 * module up to two levels down for this crate (`surfmesh::io::step`).
 */
function sizeGroup(name) {
  if (name.startsWith('data segment')) return '(data segments)';
  if (name.includes('subsection') || name.startsWith('custom section')) return '(names and custom sections)';
  // Leading `<` / `&` of trait impls and references, and crate disambiguators (`core[abc123]`).
  const segments = name.replace(/^[<&]+(mut )?/, '').replace(/\[[0-9a-f]+\]/g, '').split('::');
  if (/^h[0-9a-f]{16}$/.test(segments.at(-1))) segments.pop();
  segments.pop();
  const modules = [];
  for (const seg of segments.slice(0, segments[0] === 'surfmesh' ? 3 : 1)) {
    if (!/^[a-z_][a-z0-9_]*$/.test(seg)) break;
    modules.push(seg);
  }
  return modules.length ? modules.join('::') : '(other)';
}

/** Shallow bytes per module (see `sizeGroup`), the 20 largest, from `twiggy top` of `wasm`. */
function twiggyModules(wasm) {
  const r = spawnSync('twiggy', ['top', '-n', '1000000', '-f', 'csv', wasm], { cwd: root, encoding: 'utf8', maxBuffer: 1 << 28 });
  if (r.error || r.status !== 0) return '(twiggy failed)';
  const groups = new Map();
  let total = 0;
  for (const line of r.stdout.split('\n').slice(1)) {
    if (!line) continue;
    const [name, bytes] = csvFields(line);
    const n = Number(bytes);
    if (!Number.isFinite(n)) continue;
    total += n;
    const g = sizeGroup(name);
    groups.set(g, (groups.get(g) ?? 0) + n);
  }
  const rows = [...groups].sort((a, b) => b[1] - a[1]).slice(0, 20);
  const width = Math.max(...rows.map(([g]) => g.length));
  return rows.map(([g, n]) => `${g.padEnd(width)} ${String(n).padStart(8)} ${((100 * n) / total).toFixed(1).padStart(5)}%`).join('\n');
}

function main() {
  const args = parseArgs(process.argv.slice(2));
  const config = readConfig();
  const names = args.picked.length ? args.picked : Object.keys(config.targets);
  for (const n of names) if (!config.targets[n]) fail(`no [targets.${n}] in wasm-pack.toml`);
  const buildNames = args.builds.length ? args.builds : Object.keys(config.builds);
  for (const n of buildNames) if (!config.builds[n]) fail(`no [builds.${n}] in wasm-pack.toml`);
  const optimize = args.opt && config.opt.enabled !== false;
  const wasmOpt = checkTools(optimize);

  const cargo = parseToml(readFileSync(join(root, 'Cargo.toml'), 'utf8')).package;
  const env = { ...process.env };
  const optLevelVar = `CARGO_PROFILE_${config.profile.toUpperCase().replace(/-/g, '_')}_OPT_LEVEL`;
  const rustflags = [];
  if (config.stackSize !== undefined) {
    if (!Number.isInteger(config.stackSize) || config.stackSize % 65536 !== 0) fail('wasm-pack.toml stack_size: a whole number of 64 KiB pages');
    rustflags.push(`-C link-arg=-zstack-size=${config.stackSize}`);
  }
  for (const f of config.targetFeatures) {
    if (!/^[a-z0-9-]+$/.test(f)) fail(`wasm-pack.toml target_features: ${JSON.stringify(f)} is not a feature name`);
    rustflags.push(`-C target-feature=+${f}`);
  }
  for (const c of config.codegen) {
    if (typeof c !== 'string' || !/^[a-z0-9-]+(=[A-Za-z0-9_.-]+)?$/.test(c)) fail(`wasm-pack.toml codegen: ${JSON.stringify(c)} is not a rustc -C option`);
    rustflags.push(`-C ${c}`);
  }
  if (rustflags.length) env.CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUSTFLAGS = rustflags.join(' ');
  const meta = JSON.parse(capture('cargo', ['metadata', '--format-version', '1', '--no-deps']));
  const input = join(meta.target_directory, 'wasm32-unknown-unknown', config.profile, `${cargo.name.replace(/-/g, '_')}.wasm`);

  mkdirSync(config.packageDir, { recursive: true });
  const sizes = [];
  const built = [];
  const tops = [];
  // wasm-bindgen writes the same module for every target of a build: wasm-opt
  // (a minute or more each) runs once per distinct module, the others are copies.
  const optimized = new Map();
  for (const buildName of buildNames) {
    const build = config.builds[buildName];
    const features = build.features.join(',');
    // A build's own opt_level, else [build]'s, else the profile's.
    const optLevel = build.opt_level ?? config.optLevel;
    if (optLevel !== undefined) env[optLevelVar] = String(optLevel);
    run('cargo', ['build', '--lib', '--target', 'wasm32-unknown-unknown', '--profile', config.profile, '--no-default-features', '--features', features], { env });
    if (!existsSync(input)) fail(`cargo did not write ${input}`);
    for (const name of names) {
      const t = config.targets[name];
      const dir = build.dir ? `${build.dir}/${t.out_dir}` : t.out_dir;
      const out = join(config.packageDir, dir);
      rmSync(out, { recursive: true, force: true });
      run('wasm-bindgen', ['--target', name, '--out-dir', out, '--out-name', config.outName, input]);
      const wasm = join(out, `${config.outName}_bg.wasm`);
      const optArgs = config.opt.args ?? ['-Oz'];
      if (optimize && tops.every((x) => x.build !== buildName)) {
        // The names survive into a copy for twiggy; the shipped module drops them.
        const named = join(config.packageDir, `${buildName}.names.wasm`);
        run(wasmOpt, [...optArgs, '--debuginfo', wasm, '-o', named]);
        tops.push({ build: buildName, top: twiggyTop(named), modules: twiggyModules(named) });
        rmSync(named, { force: true });
      }
      if (optimize) {
        const key = createHash('sha256').update(readFileSync(wasm)).digest('hex');
        const done = optimized.get(key);
        if (done) copyFileSync(done, wasm);
        else {
          run(wasmOpt, [...optArgs, wasm, '-o', wasm]);
          optimized.set(key, wasm);
        }
      }
      writeFileSync(join(out, 'package.json'), `${JSON.stringify(targetManifest(name, cargo, config.outName), null, 2)}\n`);
      const bytes = readFileSync(wasm);
      const brotli = brotliCompressSync(bytes, { params: { [zlib.BROTLI_PARAM_QUALITY]: 11, [zlib.BROTLI_PARAM_SIZE_HINT]: bytes.length } }).length;
      sizes.push({ build: buildName, name, path: relative(root, wasm), raw: bytes.length, gzip: gzipSize(wasm), brotli });
      built.push({ build, target: t, dir });
    }
  }
  for (const h of HELPERS) {
    for (const file of [h.file, h.types, ...(h.extra ?? [])]) copyFileSync(join(root, 'js', file), join(config.packageDir, file));
  }
  const manifest = packageManifest(cargo, config, built);
  writeFileSync(join(config.packageDir, 'package.json'), `${JSON.stringify(manifest, null, 2)}\n`);

  const lines = [`# Sizes of the npm package's wasm modules (wasm-opt ${optimize ? 'on' : 'off'})`, ''];
  lines.push('| build | target | file | bytes | gzip -9 | brotli |', '|---|---|---|---:|---:|---:|');
  for (const s of sizes) lines.push(`| ${s.build} | ${s.name} | ${s.path} | ${s.raw} (${kb(s.raw)}) | ${s.gzip} (${kb(s.gzip)}) | ${s.brotli} (${kb(s.brotli)}) |`);
  for (const { build, top, modules } of tops) {
    lines.push('', `## ${build}: the 20 largest items (twiggy top, after wasm-opt)`, '', '```', top, '```');
    lines.push('', `## ${build}: bytes per module (crate, or this crate's module two levels down; before gzip)`, '', '```', modules, '```');
  }
  const report = `${lines.join('\n')}\n`;
  writeFileSync(join(config.packageDir, 'SIZES.md'), report);
  console.log(`\npackage written to ${relative(root, config.packageDir)}/\n`);
  console.log(report);
}

main();
