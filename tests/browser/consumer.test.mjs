// The built package from a user's side (tests/consumer-vite/, its own
// package.json depending on the package folder): a Node script imports it by
// name and meshes the page's 50-face sample; the same sample is meshed by a
// Vite-built page, on its main thread and in a Web Worker. Both must agree.
//
// Run: node --test tests/browser/   (after `npm run build`; installs the
// consumer's own dependencies when its lock file changed)

import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { existsSync, statSync } from 'node:fs';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { open, root, shot, start } from './harness.mjs';

const app = join(root, 'tests', 'consumer-vite');
let env;
let nodeSummary;

function run(cmd, args) {
  const r = spawnSync(cmd, args, { cwd: app, encoding: 'utf8' });
  assert.equal(r.status, 0, `${cmd} ${args.join(' ')} failed:\n${r.stdout}\n${r.stderr}`);
  return r.stdout;
}

before(async () => {
  const installed = join(app, 'node_modules', '.package-lock.json');
  if (!existsSync(installed) || statSync(join(app, 'package-lock.json')).mtimeMs > statSync(installed).mtimeMs) {
    // Not `npm ci`: the registry mirror serves only some of rollup's optional
    // per-platform packages, so the lock lists only those, and `npm ci` calls
    // that out of sync. `npm install --no-save` installs the locked versions.
    run('npm', ['install', '--no-save', '--no-audit', '--no-fund']);
  }
  run(process.execPath, [join(app, 'node_modules', 'vite', 'bin', 'vite.js'), 'build', '--logLevel', 'warn']);
  env = await start([['/consumer/', 'tests/consumer-vite/dist']]);
});
after(async () => {
  await env?.stop();
});

test('a Node script imports the package by name and meshes the sample', () => {
  nodeSummary = JSON.parse(run(process.execPath, ['node.mjs']));
  const s = nodeSummary;
  assert.equal(s.faces, 50);
  assert.ok(s.triangles > 100);
  assert.ok(s.maxDeviation <= s.tolerance, `${s.maxDeviation} > ${s.tolerance}`);
  assert.equal(s.progressTriangles, s.triangles, 'meshWithProgress meshes the same as mesh');
  assert.equal(s.progress.length, 50, 'one progress call per face');
  assert.deepEqual(s.progress[49], [50, 50]);
  assert.ok(s.progress.every(([done, total], i) => done === i + 1 && total === 50));
  assert.deepEqual(s.cancelled, { message: 'cancelled' }, 'returning false from the callback cancels');
  assert.deepEqual(s.rethrown, { name: 'TypeError', message: 'stop here' }, "the callback's exception comes back as it was");
});

/** The hex three.js gives an sRGB colour of 0..1 components. */
function rgbHex(r, g, b) {
  return [r, g, b].map((c) => Math.round(c * 255).toString(16).padStart(2, '0')).join('');
}

test('a Vite-built page meshes the same sample on its thread and in a worker, and SurfmeshLoader loads a STEP assembly', async () => {
  const page = await open(env.browser, `${env.url}consumer/`, { width: 800, height: 500 });
  await page.waitForSelector('#result[data-state="done"], #result[data-state="error"]', { timeout: 30000 });
  const text = await page.textContent('#result');
  await shot(page, '11-vite-consumer');
  assert.equal(await page.getAttribute('#result', 'data-state'), 'done', text);
  const s = JSON.parse(text);
  assert.equal(s.faces, 50);
  assert.equal(s.triangles, nodeSummary.triangles, 'the browser and Node builds give the same mesh');
  assert.equal(s.workerTriangles, s.triangles);
  assert.equal(s.workerProgressCalls, 50);
  assert.equal(s.groups, 50, 'surfmesh/three makes one group per face');
  assert.ok(s.sharesArrays, 'surfmesh/three wraps the arrays without copying them');
  // SurfmeshLoader, worker-backed: the STEP assembly's two placed blocks are one part drawn twice.
  const l = s.loader;
  assert.equal(l.name, 'Assembly');
  assert.deepEqual(l.children, [
    ['Block', 'Block instance 1'],
    ['Block', 'Block instance 2'],
  ]);
  assert.equal(l.instancedMeshes, 1);
  assert.deepEqual(l.copies, [2]);
  assert.deepEqual(l.groupsPerPart, [6], 'one draw group per face');
  // The file colours the solid (0.8, 0.25, 0.1) and one face blue.
  assert.deepEqual(new Set(l.materials[0]), new Set([rgbHex(0.8, 0.25, 0.1), '0000ff']));
  assert.equal(l.lines, 2, 'edge lines for each copy');
  assert.equal(l.meshProgress, 6, 'the loader reports each face of the one part meshed');
  assert.equal(l.triangles, l.flatTriangles);
  // The InstancedMesh copies, under their matrices, are the flattened mesh vertex for vertex.
  assert.equal(l.compared, l.flatCorners);
  assert.ok(l.worst < 1e-4, `largest distance ${l.worst}`);
  assert.deepEqual(page.errors, []);
  await page.context().close();
});
