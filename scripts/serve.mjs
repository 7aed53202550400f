#!/usr/bin/env node
// A small static file server for the page, with no dependencies: serves www/
// at /, the npm package pkg/ at /pkg/ and three.js from node_modules at
// /vendor/three/, each file with its MIME type (the .wasm as
// application/wasm, which WebAssembly.instantiateStreaming requires).
// Listens on 127.0.0.1 only.
//
// Usage: node scripts/serve.mjs [--port N] [--mount /url/=dir ...] [--quiet]
//   --port 0 picks a free port; the first line printed is the page's URL.
//   --mount replaces the default mounts (dir relative to the repository root).

import { createReadStream, statSync } from 'node:fs';
import { createServer } from 'node:http';
import { extname, join, normalize, resolve, sep } from 'node:path';
import { fileURLToPath } from 'node:url';

const root = resolve(fileURLToPath(import.meta.url), '..', '..');

const TYPES = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.json': 'application/json; charset=utf-8',
  '.wasm': 'application/wasm',
  '.map': 'application/json; charset=utf-8',
  '.ts': 'text/plain; charset=utf-8',
  '.svg': 'image/svg+xml',
  '.png': 'image/png',
  '.ico': 'image/x-icon',
  '.txt': 'text/plain; charset=utf-8',
  '.igs': 'application/octet-stream',
  '.iges': 'application/octet-stream',
  '.stp': 'application/octet-stream',
  '.step': 'application/octet-stream',
};

const DEFAULT_MOUNTS = [
  ['/pkg/', 'pkg'],
  ['/vendor/three/', 'node_modules/three'],
  ['/', 'www'],
];

/** Starts the server; resolves to { server, url } once it listens. */
export function serve({ port = 8080, mounts = DEFAULT_MOUNTS, quiet = false } = {}) {
  const table = mounts
    .map(([prefix, dir]) => [prefix.endsWith('/') ? prefix : `${prefix}/`, resolve(root, dir)])
    .sort((a, b) => b[0].length - a[0].length);
  const server = createServer((req, res) => {
    let path;
    try {
      path = decodeURIComponent(new URL(req.url ?? '/', 'http://localhost').pathname);
    } catch {
      return answer(res, 400, 'bad request');
    }
    if (req.method !== 'GET' && req.method !== 'HEAD') return answer(res, 405, 'method not allowed');
    const file = locate(table, path);
    if (!file) return answer(res, 404, `not found: ${path}`);
    const type = TYPES[extname(file.path).toLowerCase()] ?? 'application/octet-stream';
    res.writeHead(200, { 'Content-Type': type, 'Content-Length': file.size, 'Cache-Control': 'no-cache' });
    if (req.method === 'HEAD') return res.end();
    createReadStream(file.path)
      .on('error', () => res.destroy())
      .pipe(res);
    if (!quiet) console.log(`${req.method} ${path} 200`);
  });
  return new Promise((done, fail) => {
    server.once('error', fail);
    server.listen(port, '127.0.0.1', () => {
      const { port: bound } = server.address();
      done({ server, url: `http://127.0.0.1:${bound}/` });
    });
  });
}

/** The file a URL path names under one of the mounts (index.html for a folder), or null. */
function locate(table, path) {
  for (const [prefix, dir] of table) {
    if (!path.startsWith(prefix)) continue;
    let full = normalize(join(dir, path.slice(prefix.length)));
    if (full !== dir && !full.startsWith(dir + sep)) return null;
    try {
      let st = statSync(full);
      if (st.isDirectory()) {
        full = join(full, 'index.html');
        st = statSync(full);
      }
      if (st.isFile()) return { path: full, size: st.size };
    } catch {
      // not under this mount; try the next (shorter) prefix
    }
  }
  return null;
}

function answer(res, status, text) {
  res.writeHead(status, { 'Content-Type': 'text/plain; charset=utf-8' });
  res.end(`${text}\n`);
}

function parseArgs(argv) {
  const out = { port: 8080, mounts: [], quiet: false };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a === '--port' && i + 1 < argv.length) out.port = Number(argv[++i]);
    else if (a === '--mount' && i + 1 < argv.length) {
      const [prefix, dir] = argv[++i].split('=');
      if (!prefix || !dir) throw new Error(`--mount expects /url/=dir, found ${argv[i]}`);
      out.mounts.push([prefix, dir]);
    } else if (a === '--quiet') out.quiet = true;
    else throw new Error(`unknown argument ${a} (expected --port N, --mount /url/=dir, --quiet)`);
  }
  if (!Number.isInteger(out.port) || out.port < 0 || out.port > 65535) throw new Error('--port expects 0..65535');
  if (out.mounts.length === 0) out.mounts = DEFAULT_MOUNTS;
  return out;
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  try {
    const args = parseArgs(process.argv.slice(2));
    const { url } = await serve(args);
    console.log(url);
    if (!args.quiet) console.log('(Ctrl-C stops the server)');
  } catch (e) {
    console.error(`serve: ${e.message}`);
    process.exit(1);
  }
}
