#!/usr/bin/env node
// Builds the npm package in pkg/ from wasm-pack.toml: one cargo build of the
// cdylib for wasm32-unknown-unknown, then per target `wasm-bindgen` (the CLI
// version pinned in Cargo.lock) and `wasm-opt` from the npm package
// `binaryen` (Debian's binaryen writes modules that do not load). Prints the
// size of every .wasm, raw and gzipped. The plain-JS helpers in js/ (the
// three.js adapter) are copied beside the targets and exported as subpaths.
//
// Usage: node scripts/build-wasm.mjs [--target web|bundler|nodejs ...] [--no-opt]

import { spawnSync } from 'node:child_process';
import { copyFileSync, existsSync, mkdirSync, readFileSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { dirname, join, relative } from 'node:path';
import { fileURLToPath } from 'node:url';
import { gzipSync } from 'node:zlib';
import { parse as parseToml } from 'smol-toml';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');

/**
 * Plain-JS helpers copied from js/ into the package root: the export subpath,
 * the module and its types, and the optional peer dependency it imports.
 */
const HELPERS = [{ export: './three', file: 'three.mjs', types: 'three.d.mts', peer: ['three', '>=0.150.0'] }];

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
  let opt = true;
  for (let i = 0; i < argv.length; i++) {
    if (argv[i] === '--target' && i + 1 < argv.length) picked.push(argv[++i]);
    else if (argv[i] === '--no-opt') opt = false;
    else fail(`unknown argument ${argv[i]} (expected --target NAME or --no-opt)`);
  }
  return { picked, opt };
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
  return {
    profile: build.cargo_profile ?? 'release',
    optLevel: build.opt_level,
    stackSize: build.stack_size,
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

/** Top-level package.json: export conditions pick the target ("node" before "default"). */
function packageManifest(cargo, config, built) {
  const exports = {};
  const order = (c) => (c === 'default' ? 1 : 0);
  const entries = built
    .map((name) => ({ name, t: config.targets[name] }))
    .sort((a, b) => order(a.t.condition) - order(b.t.condition));
  for (const { t } of entries) {
    const slot = (exports[t.export] ??= {});
    slot[t.condition] = { types: `./${t.out_dir}/${config.outName}.d.ts`, default: `./${t.out_dir}/${config.outName}.js` };
  }
  for (const h of HELPERS) exports[h.export] = { types: `./${h.types}`, default: `./${h.file}` };
  exports['./package.json'] = './package.json';
  return {
    name: cargo.name,
    version: cargo.version,
    description: cargo.description,
    license: cargo.license,
    files: [...built.map((name) => `${config.targets[name].out_dir}/`), ...HELPERS.flatMap((h) => [h.file, h.types])],
    exports,
    peerDependencies: Object.fromEntries(HELPERS.map((h) => h.peer)),
    peerDependenciesMeta: Object.fromEntries(HELPERS.map((h) => [h.peer[0], { optional: true }])),
  };
}

function main() {
  const args = parseArgs(process.argv.slice(2));
  const config = readConfig();
  const names = args.picked.length ? args.picked : Object.keys(config.targets);
  for (const n of names) if (!config.targets[n]) fail(`no [targets.${n}] in wasm-pack.toml`);
  const optimize = args.opt && config.opt.enabled !== false;
  const wasmOpt = checkTools(optimize);

  const cargo = parseToml(readFileSync(join(root, 'Cargo.toml'), 'utf8')).package;
  const env = { ...process.env };
  if (config.optLevel !== undefined) {
    env[`CARGO_PROFILE_${config.profile.toUpperCase().replace(/-/g, '_')}_OPT_LEVEL`] = String(config.optLevel);
  }
  if (config.stackSize !== undefined) {
    if (!Number.isInteger(config.stackSize) || config.stackSize % 65536 !== 0) fail('wasm-pack.toml stack_size: a whole number of 64 KiB pages');
    env.CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUSTFLAGS = `-C link-arg=-zstack-size=${config.stackSize}`;
  }
  run('cargo', ['build', '--lib', '--target', 'wasm32-unknown-unknown', '--profile', config.profile], { env });
  const meta = JSON.parse(capture('cargo', ['metadata', '--format-version', '1', '--no-deps']));
  const input = join(meta.target_directory, 'wasm32-unknown-unknown', config.profile, `${cargo.name.replace(/-/g, '_')}.wasm`);
  if (!existsSync(input)) fail(`cargo did not write ${input}`);

  mkdirSync(config.packageDir, { recursive: true });
  const sizes = [];
  for (const name of names) {
    const t = config.targets[name];
    const out = join(config.packageDir, t.out_dir);
    rmSync(out, { recursive: true, force: true });
    run('wasm-bindgen', ['--target', name, '--out-dir', out, '--out-name', config.outName, input]);
    const wasm = join(out, `${config.outName}_bg.wasm`);
    if (optimize) run(wasmOpt, [...(config.opt.args ?? ['-Oz']), wasm, '-o', wasm]);
    writeFileSync(join(out, 'package.json'), `${JSON.stringify(targetManifest(name, cargo, config.outName), null, 2)}\n`);
    sizes.push({ name, path: relative(root, wasm), raw: statSync(wasm).size, gzip: gzipSize(wasm) });
  }
  for (const h of HELPERS) {
    for (const file of [h.file, h.types]) copyFileSync(join(root, 'js', file), join(config.packageDir, file));
  }
  const manifest = packageManifest(cargo, config, names);
  writeFileSync(join(config.packageDir, 'package.json'), `${JSON.stringify(manifest, null, 2)}\n`);

  console.log(`\npackage written to ${relative(root, config.packageDir)}/ (wasm-opt ${optimize ? 'on' : 'off'})`);
  for (const s of sizes) console.log(`  ${s.name.padEnd(8)} ${s.path}: ${s.raw} bytes (${kb(s.raw)}), gzip ${s.gzip} bytes (${kb(s.gzip)})`);
}

main();
