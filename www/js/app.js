// The page: wires the controls to the worker pool and the viewer.
//
// Loading a model runs two jobs side by side: a coarse mesh at relative
// tolerance 1e-2 and a normal-turn limit of 1 radian (shown as soon as it is
// ready, so a big part shows something at once) and the mesh at the
// requested tolerance, which replaces it.
// Changing a setting re-meshes with the current mesh left on screen until the
// new one is ready. Cancel stops the work at once (the worker is terminated
// and respawned). Timings are left on <body> as data attributes
// (data-first-mesh-ms: first mesh on screen, from navigation start;
// data-final-mesh-ms; data-cancel-ms: cancel click to a ready pool).

import { MeshPool } from './pool.js';
import { Viewer, PALETTE } from './viewer.js';
import { toGlb, toObj, toStl } from './export.js';

const $ = (id) => document.getElementById(id);
const body = document.body;
const COARSE_REL = 1e-2;
// The preview's normal-turn limit, radians (the default is 0.5): on parts of
// many small fillets and holes the angle, not the tolerance, sets the count.
// Measured in Node on six corpus parts at 1e-2: a third to a half of the
// triangles, 0.72-0.88x the time (trj6_pm4: 35,966 -> 11,494 triangles,
// 1.95 -> 1.40 s with its parse).
const COARSE_ANGLE = 1.0;
const DEFAULT_ANGLE_DEG = ((0.5 * 180) / Math.PI).toFixed(2);

performance.mark('surfmesh:app-start');
const boot = window.surfmeshBoot ?? { sample: 'grid50.json', workers: [] };
boot.adopted = true;
const pool = new MeshPool({
  // A preview and a full mesh at once, and on more cores a model's bodies split over up to four.
  size: Math.min(4, Math.max(2, navigator.hardwareConcurrency || 2)),
  module: boot.module,
  wasmUrl: new URL('../pkg/web/surfmesh_bg.wasm', import.meta.url),
  workerUrl: new URL('./worker.js', import.meta.url),
  workers: boot.workers,
});
const viewer = new Viewer($('canvas'));
body.dataset.renderer = viewer.software ? 'software' : 'gpu';

const state = {
  model: null, // { name, bytes, format }
  shown: null, // { result, lines, quality }
  run: 0, // bumped by every new request and by cancel; stale answers are dropped
  diagonal: null, // bounding-box diagonal of the current model, once a relative run tells it
};

// ---------------------------------------------------------------- status

let settled = 0;
/** The page state on <body data-state>; data-settled counts the runs that ended (ready, error, cancelled). */
function setState(name) {
  body.dataset.state = name;
  if (name !== 'meshing') body.dataset.settled = String(++settled);
}

function status(text) {
  $('status').textContent = text;
}

function showProgress(done, total) {
  $('progress').hidden = false;
  if (total === 0) {
    $('progress-bar').style.width = '0%';
    $('progress-label').textContent = 'Reading…';
  } else if (done < total) {
    $('progress-bar').style.width = `${(100 * done) / total}%`;
    $('progress-label').textContent = `Meshing face ${done + 1} of ${total}`;
  } else {
    $('progress-bar').style.width = '100%';
    $('progress-label').textContent = `Sewing and measuring ${total} faces…`;
  }
}

function hideProgress() {
  $('progress').hidden = true;
}

/** Shows `message` under `title` over the view (and in the status line). */
function showError(title, message) {
  $('error-title').textContent = title;
  $('error-message').textContent = message;
  $('error').hidden = false;
  status(`Error: ${message}`);
}

function hideError() {
  $('error').hidden = true;
}

// ---------------------------------------------------------------- stats

const fmt = (x) => (x === 0 ? '0' : Math.abs(x) >= 1e-3 && Math.abs(x) < 1e5 ? x.toPrecision(4) : x.toExponential(2));
// Thousands with commas. Not toLocaleString: its first call loads the locale
// data, tens of milliseconds on the way to the first picture.
const count = (n) => String(n).replace(/\B(?=(\d{3})+(?!\d))/g, ',');

function setStat(id, text, cls = '') {
  const el = $(id);
  el.textContent = text;
  el.className = cls;
}

function showStats(report, quality) {
  // Tessellated faces come as the file's triangles: counted apart, and not in the deviation.
  const tessellated = report.faces_tessellated ?? 0;
  const notes = [
    report.faces_skipped ? `${count(report.faces_skipped)} skipped` : '',
    tessellated ? `${count(tessellated)} tessellated` : '',
  ].filter(Boolean);
  setStat('stat-faces', notes.length ? `${count(report.faces)} (${notes.join(', ')})` : count(report.faces));
  setStat('stat-triangles', count(report.triangles));
  setStat('stat-vertices', count(report.vertices));
  setStat('stat-tolerance', fmt(report.tolerance));
  // Every length of the mesh and the report is in the file's unit.
  $('stat-units').textContent = report.units ? ` (${report.units})` : '';
  const within = report.max_deviation <= report.tolerance;
  if (report.quality) {
    // Quality mode aims at a size, not a tolerance: the deviation is reported, not judged.
    setStat('stat-max-deviation', fmt(report.max_deviation));
    const q = report.quality;
    setStat('stat-good-angles', percent(q.good_angle_fraction), q.good_angle_fraction >= 0.99 ? 'ok' : 'bad');
    setStat('stat-edge-band', percent(q.edge_band_fraction), q.edge_band_fraction >= 0.9 ? 'ok' : 'bad');
  } else if (tessellated > 0 && tessellated === report.faces) {
    setStat('stat-max-deviation', '— (tessellated faces only)');
    setStat('stat-good-angles', '—');
    setStat('stat-edge-band', '—');
  } else {
    const exact = tessellated > 0 ? ' (exact faces)' : '';
    setStat('stat-max-deviation', `${fmt(report.max_deviation)} ${within ? '✓' : '✗'}${exact}`, within ? 'ok' : 'bad');
    setStat('stat-good-angles', '—');
    setStat('stat-edge-band', '—');
  }
  setStat('stat-mean-deviation', fmt(report.mean_deviation));
  setStat('stat-min-angle', `${report.min_angle_deg.toFixed(1)}° (1%: ${report.p1_angle_deg.toFixed(1)}°)`);
  setStat('stat-free-edges', count(report.free_edges), report.free_edges === 0 ? 'ok' : 'bad');
  setStat('stat-open-edges', count(report.boundary_edges));
  setStat('stat-nonmanifold', count(report.nonmanifold_edges), report.nonmanifold_edges === 0 ? '' : 'bad');
  setStat('stat-reparam', rebuiltFaces(report.reparameterized ?? []));
  const workers = report.shares > 1 ? ` · ${report.shares} workers` : '';
  setStat('stat-time', `${report.parse_ms.toFixed(1)} / ${report.time_ms.toFixed(1)} ms${workers}`);
  const badge = $('quality');
  badge.hidden = false;
  badge.textContent = quality === 'final' ? 'final' : 'coarse preview';
  badge.className = `badge ${quality}`;
  showWarnings(report.warnings);
}

function showWarnings(warnings) {
  const list = $('warnings');
  list.replaceChildren();
  for (const w of warnings) {
    const li = document.createElement('li');
    li.textContent = w;
    list.append(li);
  }
  if (warnings.length === 0) {
    const li = document.createElement('li');
    li.className = 'muted';
    li.textContent = 'none';
    list.append(li);
  }
  $('warning-count').textContent = warnings.length ? String(warnings.length) : '';
}

/** The numbers of a repaired mesh: its edge census after repair; what only a mesh from a model has is "—". */
function showRepairStats(report) {
  setStat('stat-faces', '1 (repaired mesh)');
  setStat('stat-triangles', count(report.triangles_out));
  setStat('stat-vertices', count(report.vertices_out));
  for (const id of ['tolerance', 'max-deviation', 'mean-deviation', 'min-angle', 'reparam', 'good-angles', 'edge-band']) {
    setStat(`stat-${id}`, '—');
  }
  $('stat-units').textContent = '';
  const census = report.census_out;
  setStat('stat-free-edges', count(census.free_edges), census.free_edges === 0 ? 'ok' : 'bad');
  setStat('stat-open-edges', count(census.free_edges));
  setStat('stat-nonmanifold', count(census.nonmanifold_edges), census.nonmanifold_edges === 0 ? '' : 'bad');
  setStat('stat-time', `${report.parse_ms.toFixed(1)} / ${report.time_ms.total.toFixed(1)} ms`);
  const badge = $('quality');
  badge.hidden = false;
  badge.textContent = 'repaired';
  badge.className = 'badge final';
  showWarnings(report.warnings);
}

/** Which faces the ratio test flagged and which of them were rebuilt (paper 001). */
function rebuiltFaces(flagged) {
  if (flagged.length === 0) return 'none';
  const rebuilt = flagged.filter((f) => f.rebuilt).map((f) => f.face).sort((a, b) => a - b);
  const named = rebuilt.length
    ? ` (face${rebuilt.length > 1 ? 's' : ''} ${rebuilt.slice(0, 8).join(', ')}${rebuilt.length > 8 ? ', …' : ''})`
    : '';
  return `${rebuilt.length} of ${flagged.length} flagged${named}`;
}

function clearStats() {
  for (const el of $('stats').querySelectorAll('dd')) {
    el.textContent = '—';
    el.className = '';
  }
  $('quality').hidden = true;
  $('warnings').innerHTML = '<li class="muted">none</li>';
  $('warning-count').textContent = '';
}

// ---------------------------------------------------------------- options

function tolKind() {
  return document.querySelector('input[name="tol-kind"]:checked').value;
}

function meshMode() {
  return document.querySelector('input[name="mode"]:checked').value;
}

function percent(fraction) {
  return `${(100 * fraction).toFixed(1)} %`;
}

/** The mesher options the controls ask for; the module validates them. */
function readOptions() {
  const value = Number($('tol-value').value);
  const options = tolKind() === 'rel' ? { toleranceRel: value } : { tolerance: value };
  if (meshMode() === 'quality') {
    options.mode = 'quality';
    options.sizeRel = Number($('size-value').value);
  }
  const angle = $('angle').value.trim();
  if (angle !== '' && angle !== DEFAULT_ANGLE_DEG) options.angle = (Number(angle) * Math.PI) / 180;
  const maxEdge = $('max-edge').value.trim();
  if (maxEdge !== '') options.maxEdge = Number(maxEdge);
  const reparam = $('reparam').value;
  if (reparam !== 'auto' && meshMode() !== 'quality') options.reparam = reparam;
  return options;
}

function syncSlider() {
  const value = Number($('tol-value').value);
  const rel = tolKind() === 'rel' ? value : state.diagonal ? value / state.diagonal : NaN;
  if (rel > 0) $('tol-slider').value = String(Math.log10(rel));
}

function sliderToValue() {
  const rel = 10 ** Number($('tol-slider').value);
  const value = tolKind() === 'rel' ? rel : state.diagonal ? rel * state.diagonal : NaN;
  if (value > 0) $('tol-value').value = String(Number(value.toPrecision(3)));
}

// ---------------------------------------------------------------- meshing

function formatOf(name) {
  const ext = name.toLowerCase().split('.').pop();
  if (ext === 'json') return 'json';
  if (ext === 'igs' || ext === 'iges') return 'iges';
  if (ext === 'stp' || ext === 'step') return 'step';
  return 'auto';
}

function load(name, bytes, { prestarted = false } = {}) {
  // bodies: how many the model has, once a mesh of it has said (a re-mesh splits by them).
  state.model = { name, bytes, format: formatOf(name), prestarted, bodies: 1 };
  state.diagonal = null;
  $('model-name').textContent = name;
  remesh({ fresh: true });
}

let timer = 0;
function remeshSoon() {
  clearTimeout(timer);
  timer = setTimeout(() => remesh(), 250);
}

function remesh({ fresh = false } = {}) {
  clearTimeout(timer);
  if (!state.model) return;
  const { name, bytes, format } = state.model;
  const options = readOptions();
  syncSlider();
  // The page's first load may find the default sample already sent to the workers.
  const pre = fresh && state.model.prestarted ? pool.takePrestarted() : [];
  const adopt = (opts) => pre.find((p) => JSON.stringify(p.options) === JSON.stringify(opts))?.job;
  // Never finer than the requested mesh: its own angle limit where that is wider.
  const coarseOptions = { toleranceRel: COARSE_REL, angle: Math.max(COARSE_ANGLE, options.angle ?? 0) };
  for (const p of pre) if (p.job !== adopt(options) && p.job !== adopt(coarseOptions)) p.job.cancel();
  if (pre.length === 0) pool.cancelAll();
  const run = ++state.run;
  hideError();
  setState('meshing');
  showProgress(0, 0);
  if (fresh) {
    state.shown = null;
    viewer.clear();
    clearStats();
    setExport(false);
  }
  status(`Meshing ${name}…`);
  let finished = false;
  performance.mark('surfmesh:mesh-requested');
  const onProgress = (done, total) => {
    if (run === state.run) showProgress(done, total);
  };
  const coarseRel = options.toleranceRel === undefined || options.toleranceRel < COARSE_REL;
  // The coarse preview is a fast-mode mesh: not shown while quality mode is asked for.
  const withCoarse = fresh && coarseRel && options.mode !== 'quality';
  // The requested mesh is split by bodies over the workers the preview leaves free.
  const shares = Math.min(withCoarse ? pool.size - 1 : pool.size, state.model.bodies);
  const fine = adopt(options) ?? pool.meshShared(bytes, format, options, shares, onProgress);
  fine.onProgress = onProgress;
  if (withCoarse) {
    const coarse = adopt(coarseOptions) ?? pool.mesh(bytes, format, coarseOptions);
    coarse.promise.then(
      ({ result, lines }) => {
        performance.mark('surfmesh:coarse-result', { detail: result.report.time_ms });
        // The boot's requested mesh waits for this picture; a hidden tab draws no
        // frames, so it starts a moment later regardless.
        setTimeout(() => boot.release?.(), 250);
        if (run !== state.run || finished) return;
        learnDiagonal(result.report, COARSE_REL);
        learnBodies(result.report);
        display(result, lines, 'coarse', { fit: true });
        status(`Coarse preview (relative ${COARSE_REL}) shown; meshing at the requested tolerance…`);
      },
      () => boot.release?.(), // the requested run reports the same error
    );
  }
  fine.promise.then(
    ({ result, lines }) => {
      performance.mark('surfmesh:final-result');
      if (run !== state.run) return;
      finished = true;
      pool.cancelAll();
      learnDiagonal(result.report, options.toleranceRel);
      learnBodies(result.report);
      display(result, lines, 'final', { fit: fresh && state.shown?.quality !== 'coarse' });
      hideProgress();
      setState('ready');
      const r = result.report;
      status(
        r.quality
          ? `${count(r.triangles)} triangles of size ${fmt(r.quality.size)} · ` +
              `${percent(r.quality.good_angle_fraction)} with angles ≥ 25° · ${r.time_ms.toFixed(0)} ms`
          : `${count(r.triangles)} triangles · max deviation ${fmt(r.max_deviation)} ≤ ${fmt(r.tolerance)} · ` +
              (r.faces_tessellated ? `${count(r.faces_tessellated)} tessellated faces not verified · ` : '') +
              `${r.time_ms.toFixed(0)} ms`,
      );
    },
    (error) => {
      if (run !== state.run) return;
      finished = true;
      pool.cancelAll();
      hideProgress();
      setState('error');
      showError(pool.error ? 'The mesher could not start' : `Could not mesh ${name}`, error.message);
    },
  );
}

function learnBodies(report) {
  if (state.model && report.bodies > 0) state.model.bodies = report.bodies;
}

function learnDiagonal(report, rel) {
  if (rel > 0 && report.tolerance > 0) state.diagonal = report.tolerance / rel;
}

let firstShown = false;
let finalShown = false;
let linesWarm = false;
function display(result, lines, quality, { fit }) {
  state.shown = { result, lines, quality };
  body.dataset.quality = quality;
  // On screen: the frame after the one that drew the mesh has begun.
  viewer.onRendered = () => {
    viewer.onRendered = null;
    requestAnimationFrame(() => {
      const t = performance.now().toFixed(0);
      if (!firstShown) {
        firstShown = true;
        body.dataset.firstMeshMs = t;
        boot.release?.();
      }
      // A preview is drawn without line overlays; their shaders compile now, before the final mesh.
      if (!linesWarm) {
        linesWarm = true;
        if (quality === 'coarse') viewer.warmUp('lines');
      }
      if (quality === 'final' && !finalShown) {
        finalShown = true;
        body.dataset.finalMeshMs = t;
      }
    });
  };
  viewer.show(result, lines, { fit, overlays: quality !== 'coarse' });
  // How the model is drawn: InstancedMesh objects / copies they place (a plain mesh: 1/1).
  const drawn = viewer.instancing();
  body.dataset.instanced = `${drawn.meshes}/${drawn.copies}`;
  if (quality === 'repaired') showRepairStats(result.report);
  else showStats(result.report, quality);
  setExport(true);
}

function cancel() {
  const start = performance.now();
  state.run++;
  pool.cancelAll();
  hideProgress();
  setState('cancelled');
  status(state.shown ? 'Cancelled; the mesh shown is the previous one' : 'Cancelled');
  pool.ready().then(() => {
    body.dataset.cancelMs = (performance.now() - start).toFixed(0);
  });
}

// ---------------------------------------------------------------- export

function setExport(enabled) {
  for (const id of ['export-stl', 'export-obj', 'export-glb', 'repair']) $(id).disabled = !enabled;
}

function download(blob, filename) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = filename;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 30000);
}

function stem() {
  return (state.model?.name ?? 'mesh').replace(/\.[^.]*$/, '');
}

$('export-stl').onclick = () => state.shown && download(toStl(state.shown.result, `surfmesh ${stem()}`), `${stem()}.stl`);
$('export-obj').onclick = () => state.shown && download(toObj(state.shown.result, `surfmesh ${stem()}`), `${stem()}.obj`);
$('export-glb').onclick = () => state.shown && download(toGlb(state.shown.result, PALETTE), `${stem()}.glb`);

// ---------------------------------------------------------------- repair

/**
 * Repairs the shown mesh in a worker with the full build (loaded on the
 * first use): the mesh goes as binary STL, the repaired one is shown with
 * its edge census. A re-mesh (any option change) shows the model's mesh again.
 */
async function repairShown() {
  if (!state.shown) return;
  const bytes = await toStl(state.shown.result, `surfmesh ${stem()}`).arrayBuffer();
  pool.cancelAll();
  const run = ++state.run;
  hideError();
  setState('meshing');
  showProgress(0, 0);
  status(`Repairing the mesh of ${state.model?.name ?? 'the model'} (full build)…`);
  pool.mesh(bytes, 'stl', { repair: { verify: true } }).promise.then(
    ({ result, lines }) => {
      if (run !== state.run) return;
      display(result, lines, 'repaired', { fit: false });
      hideProgress();
      setState('ready');
      const r = result.report;
      const closed = r.census_out.free_edges === 0 && r.census_out.nonmanifold_edges === 0;
      status(
        `Repaired (${r.build}): ${count(r.triangles_out)} triangles, ` +
          `${closed ? 'closed' : `${count(r.census_out.free_edges)} free edges`}, ` +
          `${r.self_intersections_out ?? '?'} self-intersections · ${r.time_ms.total.toFixed(0)} ms`,
      );
    },
    (error) => {
      if (run !== state.run) return;
      hideProgress();
      setState('error');
      showError('Could not repair the mesh', error.message);
    },
  );
}

// ---------------------------------------------------------------- controls

$('angle').value = DEFAULT_ANGLE_DEG;
$('cancel').onclick = cancel;
$('repair').onclick = repairShown;
$('error-close').onclick = hideError;
$('fit').onclick = () => viewer.fit();
viewer.canvas.addEventListener('dblclick', () => viewer.fit());
// A click (not a drag) picks a face: highlighted, and named in the status line.
let down = null;
viewer.canvas.addEventListener('pointerdown', (e) => {
  down = { x: e.clientX, y: e.clientY };
});
viewer.canvas.addEventListener('pointerup', (e) => {
  if (!down || Math.hypot(e.clientX - down.x, e.clientY - down.y) > 4 || !state.shown) return;
  const face = viewer.pick(e.clientX, e.clientY);
  const ranges = state.shown.result.faceRanges;
  // A STEP assembly names the part the face belongs to.
  const part = state.shown.result.parts?.[state.shown.result.faceParts?.[face]];
  if (face >= 0) status(`Face ${face} of ${ranges.length / 2}${part ? ` (${part})` : ''}: ${count(ranges[2 * face + 1])} triangles`);
});

$('tol-value').addEventListener('change', () => {
  syncSlider();
  remesh();
});
$('tol-slider').addEventListener('input', () => {
  sliderToValue();
  remeshSoon();
});
for (const id of ['angle', 'max-edge', 'size-value', 'reparam']) $(id).addEventListener('change', () => remesh());
for (const radio of document.querySelectorAll('input[name="mode"]')) {
  radio.addEventListener('change', () => {
    const quality = meshMode() === 'quality';
    $('size-field').hidden = !quality;
    $('reparam-field').hidden = quality;
    $('mode-hint').textContent = quality
      ? 'Near-equilateral triangles of size H for analysis (paper 003); faces meet node to node.'
      : 'Fewest triangles within the tolerance.';
    remesh();
  });
}
for (const radio of document.querySelectorAll('input[name="tol-kind"]')) {
  radio.addEventListener('change', () => {
    const abs = tolKind() === 'abs';
    $('tol-label').textContent = abs ? 'Chordal, model units' : 'Chordal, × bounding-box diagonal';
    const value = Number($('tol-value').value);
    if (state.diagonal && value > 0) {
      const converted = abs ? value * state.diagonal : value / state.diagonal;
      $('tol-value').value = String(Number(converted.toPrecision(3)));
    }
    syncSlider();
    remesh();
  });
}

const toggles = { 'show-colors': 'faceColors', 'show-wire': 'wireframe', 'show-borders': 'borders', 'show-open': 'openEdges' };
for (const [id, key] of Object.entries(toggles)) {
  $(id).addEventListener('change', () => viewer.set({ [key]: $(id).checked }));
}

$('file-input').addEventListener('change', (event) => {
  const file = event.target.files?.[0];
  event.target.value = '';
  if (file) openFile(file);
});

async function openFile(file) {
  $('sample').value = '';
  load(file.name, await file.arrayBuffer());
}

$('sample').addEventListener('change', () => loadSample($('sample').value));

/** Loads samples/`file` (or `bytes` already fetched for it). */
async function loadSample(file, bytes) {
  $('sample').value = file;
  try {
    const fetched = () =>
      fetch(`samples/${encodeURIComponent(file)}`).then((r) =>
        r.ok ? r.arrayBuffer() : Promise.reject(new Error(`HTTP ${r.status}`)),
      );
    const data = await (bytes ?? fetched());
    load(file, data, { prestarted: bytes !== undefined });
  } catch (e) {
    setState('error');
    showError(`Could not open ${file}`, `cannot fetch the sample: ${e.message}`);
  }
}

const view = $('view');
let dragDepth = 0;
view.addEventListener('dragenter', (e) => {
  e.preventDefault();
  dragDepth++;
  $('drop').hidden = false;
});
view.addEventListener('dragleave', () => {
  dragDepth = Math.max(0, dragDepth - 1);
  if (dragDepth === 0) $('drop').hidden = true;
});
view.addEventListener('dragover', (e) => e.preventDefault());
view.addEventListener('drop', (e) => {
  e.preventDefault();
  dragDepth = 0;
  $('drop').hidden = true;
  const file = e.dataTransfer?.files?.[0];
  if (file) openFile(file);
});
window.addEventListener('keydown', (e) => {
  if (e.key === 'f' && !(e.target instanceof HTMLInputElement)) viewer.fit();
  if (e.key === 'Escape' && !$('progress').hidden) cancel();
});

pool.ready().then(
  () => {
    performance.mark('surfmesh:pool-ready');
    $('version').textContent = `surfmesh ${pool.version}`;
  },
  (e) => {
    setState('error');
    showError('The mesher could not start', e.message);
  },
);

// The boot script has already sent the default sample to the workers: the
// shaders compile now, while they mesh (a warm-up after loadSample, which
// waits for the sample's bytes, came after the preview on a 2-core machine).
viewer.warmUp();
loadSample(boot.sample, boot.bytes);
