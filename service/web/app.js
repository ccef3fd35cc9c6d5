// The page: the form, the API calls, the results table, and the wiring of the 3-D view and the plots.
// Everything the page shows comes from the service's own answers (API.md); the browser only draws.
import { Viewer } from './view3d.js';
import { drawOmega, drawPolhode } from './plots.js';
import { parseMesh, parseXYZ, BROWSER_FORMATS } from './meshes.js';

const $ = (id) => document.getElementById(id);
const FIELDS = ['file', 'format', 'paste', 'units', 'tolerance', 'density', 'mass', 'model', 'thickness',
  'omega', 'duration', 'samples', 'method'];
// error codes about the input itself rather than one option: shown next to the file (or the pasted text)
const INPUT_CODES = new Set(['unsupported_format', 'unreadable_file', 'empty_geometry', 'not_watertight',
  'zero_volume', 'payload_too_large', 'invalid_inertia', 'unsafe_file', 'too_complex']);
const DEFAULT_SAMPLES = 600;
const PLAYBACK_SECONDS = 12; // one pass of the trajectory at 1x takes this long on screen

// state is on window for the end-to-end tests and for a curious user's console
const state = window.inertiaPage = {
  file: null, result: null, trajectory: null, source: null, exportable: true, busy: false, lastRequest: null,
  playing: false, time: 0, viewer: null, formats: [],
};

function setBusy(busy, text = '') {
  state.busy = busy;
  $('analyze').disabled = busy;
  $('busy').textContent = text;
  document.body.dataset.state = busy ? 'busy' : (state.result ? 'ready' : 'idle');
}

// ---------- errors next to the input that caused them ----------

function clearErrors() {
  for (const id of [...FIELDS, 'request', 'export']) {
    const p = $(`${id}-error`);
    if (p) { p.hidden = true; p.textContent = ''; }
    const input = $(id);
    if (input) input.removeAttribute('aria-invalid');
  }
}

function showError(field, message) {
  const p = $(`${field}-error`) || $('request-error');
  p.textContent = message;
  p.hidden = false;
  const input = $(field);
  if (input) input.setAttribute('aria-invalid', 'true');
  if (field === 'paste') $('paste-box').open = true;
  document.body.dataset.state = 'error';
}

function fieldOf(error, kind) {
  const details = error.details || {};
  const loc = details.errors && details.errors[0] && details.errors[0].loc;
  if (kind === 'points' && loc && loc[1] === 'points') return 'paste';
  const parameter = details.parameter;
  if (parameter === 'points' || parameter === 'position' || parameter === 'element') return 'paste';
  if (parameter && FIELDS.includes(parameter) && !(kind === 'points' && parameter === 'mass')) return parameter;
  if (INPUT_CODES.has(error.code) || parameter === 'file') return kind === 'mesh' ? 'file' : 'paste';
  return 'request';
}

// ---------- reading the form ----------

function number(id) {
  const text = $(id).value.trim();
  return text === '' ? undefined : text;
}

function triple(id) {
  const text = $(id).value.trim();
  if (text === '') return undefined;
  const parts = text.split(/[\s,;]+/).filter(Boolean);
  if (parts.length !== 3 || parts.some((p) => !Number.isFinite(Number(p)))) {
    throw Object.assign(new Error(`${id} needs three numbers wx,wy,wz, e.g. 0.01,1,0.01`), { field: id });
  }
  return parts.map(Number);
}

function motionOptions() {
  const omega = triple('omega');
  if (!omega) return {};
  const duration = number('duration');
  const samples = number('samples') ?? String(DEFAULT_SAMPLES);
  return duration === undefined ? { omega } : { omega, duration, samples };
}

// pasted text -> {kind: 'points', json} or {kind: 'mesh', file} (an XYZ molecule goes up as a .xyz file)
function pastedInput(text) {
  const trimmed = text.trim();
  if (/^\d+\s*(\r?\n|$)/.test(trimmed)) {
    return { kind: 'mesh', file: new File([trimmed + '\n'], 'pasted.xyz', { type: 'chemical/x-xyz' }), display: parseXYZ(trimmed) };
  }
  let points;
  if (trimmed.startsWith('[') || trimmed.startsWith('{')) {
    let parsed;
    try { parsed = JSON.parse(trimmed); } catch (e) {
      throw Object.assign(new Error(`the pasted text is not valid JSON (${e.message})`), { field: 'paste' });
    }
    points = Array.isArray(parsed) ? parsed : parsed.points;
    if (!Array.isArray(points)) throw Object.assign(new Error('JSON must be a list of points or {"points": [...]}'), { field: 'paste' });
  } else {
    points = [];
    for (const [i, line] of trimmed.split(/\r?\n/).entries()) {
      const cells = line.split(/[\s,;]+/).filter(Boolean);
      if (cells.length === 0 || (i === 0 && cells.some((c) => !Number.isFinite(Number(c))))) continue; // header
      if (cells.length !== 4 || cells.some((c) => !Number.isFinite(Number(c)))) {
        throw Object.assign(new Error(`line ${i + 1}: expected four numbers mass,x,y,z, got "${line.trim()}"`), { field: 'paste' });
      }
      const [m, x, y, z] = cells.map(Number);
      points.push({ mass: m, position: [x, y, z] });
    }
    if (points.length === 0) throw Object.assign(new Error('no points found in the pasted text'), { field: 'paste' });
  }
  return { kind: 'points', points };
}

function meshQuery(extra = {}) {
  const q = new URLSearchParams();
  const put = (k, v) => { if (v !== undefined && v !== '') q.set(k, v); };
  put('format', $('format').value);
  put('units', $('units').value);
  put('density', number('density'));
  put('mass', number('mass'));
  put('model', $('model').value === 'solid' ? undefined : $('model').value);
  put('thickness', number('thickness'));
  put('tolerance', number('tolerance'));
  put('method', $('method').value === 'exact' ? undefined : $('method').value);
  for (const [k, v] of Object.entries(extra)) put(k, Array.isArray(v) ? v.join(',') : v);
  return q;
}

function pointsBody(points, extra = {}) {
  const body = { points };
  if ($('units').value) body.units = $('units').value;
  if (number('tolerance') !== undefined) body.tolerance = Number(number('tolerance'));
  if ($('method').value !== 'exact') body.method = $('method').value;
  for (const [k, v] of Object.entries(extra)) {
    if (v !== undefined) body[k] = (k === 'duration' || k === 'samples') ? Number(v) : v;
  }
  return body;
}

// the current input as a request; `extra` adds options (omega, duration, samples, export)
function authHeaders() {
  const key = $('apikey').value;
  return key ? { 'X-API-Key': key } : {};
}

function buildRequest(extra) {
  const headers = authHeaders();
  const src = state.source;
  if (src.kind === 'mesh') {
    const form = new FormData();
    form.append('file', src.file, src.file.name);
    return { kind: 'mesh', url: `v1/analyze/mesh?${meshQuery(extra)}`, init: { method: 'POST', body: form, headers } };
  }
  headers['Content-Type'] = 'application/json';
  return { kind: 'points', url: 'v1/analyze/points', init: { method: 'POST', body: JSON.stringify(pointsBody(src.points, extra)), headers } };
}

async function call(url, init) {
  let response;
  try { response = await fetch(url, init); } catch (e) {
    return { error: { code: 'network', message: `could not reach the service (${e.message}); is it still running?`, details: {} } };
  }
  let body;
  try { body = await response.json(); } catch {
    return { error: { code: 'bad_response', message: `the service answered ${response.status} without JSON; try again`, details: {} } };
  }
  if (!response.ok) {
    const error = body && body.error ? body.error : { code: 'http_error', message: `HTTP ${response.status}`, details: {} };
    return { error };
  }
  return { body };
}

// ---------- the analysis ----------

function currentSource() {
  const pasted = $('paste').value.trim();
  if (state.file) return { kind: 'mesh', file: state.file };
  if (pasted) return pastedInput(pasted);
  throw Object.assign(new Error('choose a mesh file, drop one here, or paste point masses'), { field: 'file' });
}

// default length of the animation when the user gave omega but no duration: a few periods of what moves
function defaultDuration(p, omega) {
  const spin = Math.hypot(...omega) || 1;
  if (p.regime === 'asymmetric' && p.period) return 2 * p.period;
  if (p.regime === 'asymmetric') return 12 * 2 * Math.PI / spin; // on the separatrix: no period
  if (p.space_precession_rate) return 3 * 2 * Math.PI / p.space_precession_rate;
  return 3 * 2 * Math.PI / spin;
}

async function analyze() {
  clearErrors();
  stop();
  let motion;
  try {
    state.source = currentSource();
    motion = motionOptions();
    for (const id of ['density', 'mass']) {
      if (state.source.kind === 'points' && number(id) !== undefined) {
        throw Object.assign(new Error(`point masses carry their own masses: leave ${id} empty`), { field: id });
      }
    }
  } catch (e) {
    showError(e.field || 'request', e.message);
    return;
  }
  setBusy(true, 'Analysing…');
  const started = performance.now();
  const request = buildRequest(motion);
  const { body, error } = await call(request.url, request.init);
  if (error) {
    setBusy(false);
    state.result = null;
    showError(fieldOf(error, request.kind), `${error.message} (${error.code})`);
    return;
  }
  let trajectory = body.precession && body.precession.trajectory;
  if (body.precession && !trajectory && motion.omega) {
    // no duration given: ask for a trajectory of a few periods about the same tensor
    setBusy(true, 'Computing the motion…');
    const duration = defaultDuration(body.precession, motion.omega);
    const samples = Number(number('samples') ?? DEFAULT_SAMPLES);
    const rq = { inertia_tensor: body.inertia_tensor, omega: motion.omega, duration, samples, method: $('method').value };
    if (number('tolerance') !== undefined) rq.tolerance = Number(number('tolerance'));
    const headers = { ...authHeaders(), 'Content-Type': 'application/json' };
    const answer = await call('v1/precession', { method: 'POST', headers, body: JSON.stringify(rq) });
    if (answer.error) showError(fieldOf(answer.error, 'precession'), `motion: ${answer.error.message} (${answer.error.code})`);
    else trajectory = answer.body.precession.trajectory;
  }
  state.result = body;
  state.trajectory = trajectory || null;
  state.roundTrip = (performance.now() - started) / 1000;
  renderResults(body);
  await showBody(body);
  setupMotion(body);
  setBusy(false);
  document.body.dataset.state = 'ready';
}

// ---------- results table ----------

const fmt = (x) => (typeof x === 'number' ? (Number.isInteger(x) && Math.abs(x) < 1e15 ? String(x) : Number(x.toPrecision(10)).toString()) : String(x));
const num = (x, key) => `<span class="num" data-key="${key}" data-value="${x}">${fmt(x)}</span>`;
const vec = (v, key) => `(${v.map((x, i) => num(x, `${key}.${i}`)).join(', ')})`;
const escape = (s) => String(s).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' }[c]));

function matrix(m, key) {
  return `<table class="matrix">${m.map((row, i) => `<tr>${row.map((x, j) => `<td>${num(x, `${key}.${i}.${j}`)}</td>`).join('')}</tr>`).join('')}</table>`;
}

function classText(c) {
  const kind = c.kind.replace('_', ' ');
  const parts = [c.shape ? `${kind} (${c.shape})` : kind];
  if (c.asymmetry !== undefined) parts.push(`κ = ${num(c.asymmetry, 'classification.asymmetry')}`);
  if (c.planar) parts.push('planar');
  if (c.symmetry_axis) parts.push(`axis ${vec(c.symmetry_axis, 'classification.symmetry_axis')}`);
  return parts.join(', ');
}

function precessionRows(p) {
  const rows = [['Regime', escape(p.regime.replace('_', ' ')), 'regime']];
  rows.push(['Angular momentum M (kg m²/s)', `${vec(p.angular_momentum, 'precession.angular_momentum')}, |M| = ${num(p.angular_momentum_magnitude, 'precession.angular_momentum_magnitude')}`, 'momentum']);
  rows.push(['Kinetic energy (J)', num(p.kinetic_energy, 'precession.kinetic_energy'), 'energy']);
  if (p.period !== undefined) rows.push(['Period of Ω in the body (s)', num(p.period, 'precession.period'), 'period']);
  if (p.stable !== undefined) rows.push(['Stable', p.stable ? 'yes' : 'no: Ω starts nearest the intermediate axis (tennis-racket flips)', 'stable']);
  if (p.flip_interval !== undefined) rows.push(['Time between flips (s)', num(p.flip_interval, 'precession.flip_interval'), 'flip']);
  for (const [k, label] of [['body_precession_rate', 'Body precession rate (rad/s)'], ['space_precession_rate', 'Space precession rate (rad/s)'],
    ['spin_rate', 'Spin rate ψ̇ (rad/s)'], ['nutation_angle', 'Nutation angle θ (rad)']]) {
    if (p[k] !== undefined) rows.push([label, num(p[k], `precession.${k}`), k]);
  }
  if (p.diagnostics && p.diagnostics.energy_drift !== undefined) rows.push(['Motion drift (energy, |M|)', `${num(p.diagnostics.energy_drift, 'precession.diagnostics.energy_drift')}, ${num(p.diagnostics.momentum_drift, 'precession.diagnostics.momentum_drift')}`, 'drift']);
  return rows;
}

function partRows(parts) {
  const items = parts.map((p, i) => `<li><span class="swatch" style="background:${Viewer.partColor(i)}"></span>${escape(p.name)}: `
    + `${num(p.mass, `parts.${i}.mass`)} kg at ${vec(p.center_of_mass, `parts.${i}.center_of_mass`)}</li>`);
  return [['Parts', `<ul>${items.join('')}</ul>`, 'parts']];
}

function renderResults(r) {
  const rows = [];
  const src = r.source || {};
  const what = [src.filename, src.format, src.kind, src.units && `units ${src.units}`,
    src.triangles !== undefined && `${src.triangles} triangles`, src.watertight !== undefined && (src.watertight ? 'watertight' : 'open')].filter(Boolean);
  rows.push(['Source', escape(what.join(', ')), 'source']);
  rows.push(['Mass (kg)', num(r.mass, 'mass'), 'mass']);
  if (r.volume !== undefined) rows.push(['Volume (m³)', num(r.volume, 'volume'), 'volume']);
  if (r.density !== undefined) rows.push(['Density (kg/m³)', num(r.density, 'density'), 'density']);
  if (r.surface_area !== undefined) rows.push(['Surface area (m²)', num(r.surface_area, 'surface_area'), 'surface_area']);
  rows.push(['Centre of mass (m)', vec(r.center_of_mass, 'center_of_mass'), 'center_of_mass']);
  rows.push(['Inertia tensor about the centre of mass (kg m²)', matrix(r.inertia_tensor, 'inertia_tensor'), 'inertia_tensor']);
  if (r.reference_inertia) rows.push([`Tensor about ${r.reference_inertia.point.map(fmt).join(', ')} (kg m²)`, matrix(r.reference_inertia.tensor, 'reference_inertia.tensor'), 'reference']);
  rows.push(['Principal moments I1 ≤ I2 ≤ I3 (kg m²)', vec(r.principal.moments, 'principal.moments'), 'moments']);
  rows.push(['Principal axes (rows, input frame)', matrix(r.principal.axes, 'principal.axes') + (r.principal.unique_axes ? '' : '<br>(moments coincide: one valid choice of axes)'), 'axes']);
  if (r.principal.radii_of_gyration) rows.push(['Radii of gyration (m)', vec(r.principal.radii_of_gyration, 'principal.radii_of_gyration'), 'radii']);
  rows.push(['Class', classText(r.classification), 'class']);
  if (r.rotational_constants) rows.push(['Rotational constants', `${r.rotational_constants.MHz.map(fmt).join(', ')} MHz`, 'rotational_constants']);
  if (r.parts) rows.push(...partRows(r.parts));
  if (r.precession) rows.push(...precessionRows(r.precession));
  const warnings = r.warnings && r.warnings.length ? `<ul>${r.warnings.map((w) => `<li>${escape(w)}</li>`).join('')}</ul>` : 'none';
  rows.push(['Warnings', warnings, 'warnings']);
  rows.push(['Relative error estimate', num(r.diagnostics.relative_error_estimate, 'diagnostics.relative_error_estimate'), 'error_estimate']);
  rows.push(['Elapsed (s)', `${num(r.diagnostics.elapsed_s, 'diagnostics.elapsed_s')} in the service; ${fmt(Number(state.roundTrip.toFixed(3)))} s round trip`, 'elapsed']);
  $('results-table').tBodies[0].innerHTML = rows.map(([label, html, key]) => `<tr data-row="${key}"><th scope="row">${label}</th><td>${html}</td></tr>`).join('');
  $('results').hidden = false;
  for (const b of document.querySelectorAll('button.export')) b.disabled = !state.exportable;
}

// ---------- downloads ----------

function stem() {
  const name = (state.result && state.result.source && state.result.source.filename) || 'points';
  return name.replace(/\.[^.]*$/, '') || 'body';
}

function download(text, filename, type) {
  const url = URL.createObjectURL(new Blob([text], { type }));
  const a = document.createElement('a');
  a.href = url; a.download = filename;
  document.body.append(a); a.click(); a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}

async function exportSnippet(button) {
  const format = button.dataset.export;
  $('export-error').hidden = true;
  button.disabled = true;
  const request = buildRequest({ export: format });
  const { body, error } = await call(request.url, request.init);
  if (error || !body.export) {
    const message = error ? `${error.message} (${error.code})` : 'this service does not offer snippets';
    $('export-error').textContent = `${format.toUpperCase()} export is not available: ${message}`;
    $('export-error').hidden = false;
    return; // the button stays disabled: the same body would get the same answer
  }
  button.disabled = false;
  const ext = { urdf: 'urdf', sdf: 'sdf', mjcf: 'xml' }[format];
  download(body.export.text, `${stem()}.${format}.${ext}`, 'application/xml');
}

// ---------- 3-D view ----------

async function showBody(r) {
  if (!state.viewer) return;
  const src = state.source;
  let shape = null;
  let note = '';
  if (src.kind === 'mesh' && src.display) {
    shape = { points: src.display };
  } else if (src.kind === 'points') {
    shape = { points: src.points.map((p) => ({ position: p.position, mass: p.mass })) };
  } else {
    const format = (r.source && r.source.format) || '';
    if (BROWSER_FORMATS.includes(format)) {
      try {
        shape = await parseMesh(src.file, format);
      } catch (e) {
        note = `The browser could not draw this ${format.toUpperCase()} file (${e.message}); `
          + 'shown are the inertia ellipsoid and principal axes alone.';
      }
    } else {
      note = `The browser does not draw ${format.toUpperCase() || 'this'} files: shown are the inertia ellipsoid `
        + 'and principal axes alone' + (r.parts ? ', and each part\'s centre of mass.' : '.');
    }
  }
  if (shape && shape.decimated) {
    note = `Drawn decimated: ${shape.triangles.toLocaleString('en')} triangles shown of ${shape.originalTriangles.toLocaleString('en')} `
      + '(the numbers are for the full mesh).';
  }
  state.viewer.show(r, shape);
  $('view-note').textContent = note;
}

// ---------- motion ----------

function setupMotion(r) {
  const traj = state.trajectory;
  if (!r.precession || !traj || traj.t.length < 2) {
    $('motion').hidden = true;
    if (state.viewer) state.viewer.setMotion(null);
    return;
  }
  $('motion').hidden = false;
  const p = r.precession;
  const T = traj.t[traj.t.length - 1];
  const bits = [`${traj.t.length} samples over ${fmt(T)} s (method ${$('method').value})`];
  if (p.stable === false) bits.push(`unstable: Ω2 reverses every ${fmt(p.flip_interval ?? NaN)} s (tennis-racket flips)`);
  if (p.regime === 'regular_precession') bits.push('symmetric top: the body cone (fixed in the body) rolls on the space cone (fixed, about M)');
  $('motion-summary').textContent = `${bits.join('; ')}.`;
  state.time = 0;
  $('time').value = 0;
  if (state.viewer) state.viewer.setMotion(r, traj);
  seek(0);
}

function seek(t) {
  const traj = state.trajectory;
  if (!traj) return;
  const T = traj.t[traj.t.length - 1];
  state.time = Math.min(Math.max(t, 0), T);
  $('time').value = String(Math.round(1000 * state.time / T));
  $('time-out').value = `t = ${state.time.toFixed(2)} s`;
  if (state.viewer) state.viewer.setTime(state.time);
  drawOmega($('plot-omega'), traj, state.time);
  drawPolhode($('plot-polhode'), state.result.principal.moments, traj, state.time);
}

let lastFrame = null;
function frame(now) {
  if (!state.playing) return;
  const traj = state.trajectory;
  const T = traj.t[traj.t.length - 1];
  if (lastFrame !== null) {
    const rate = Number($('speed').value) * T / PLAYBACK_SECONDS;
    let t = state.time + rate * (now - lastFrame) / 1000;
    if (t > T) t = 0;
    seek(t);
  }
  lastFrame = now;
  requestAnimationFrame(frame);
}

function play() {
  if (!state.trajectory) return;
  state.playing = true;
  lastFrame = null;
  $('play').textContent = 'Pause';
  $('play').setAttribute('aria-pressed', 'true');
  requestAnimationFrame(frame);
}

function stop() {
  state.playing = false;
  $('play').textContent = 'Play';
  $('play').setAttribute('aria-pressed', 'false');
}

// ---------- start-up ----------

async function loadFormats() {
  const { body, error } = await call('v1/formats', { headers: authHeaders() });
  if (error) {
    const hint = error.code === 'unauthorized' ? ': this server needs an API key (under "Server")' : '';
    $('formats').textContent = `(the list is not available${hint})`;
    if (hint) $('apikey').closest('details').open = true;
    return;
  }
  $('format').length = 1;
  state.formats = body.formats.map((f) => f.format);
  $('formats').textContent = state.formats.join(', ');
  for (const f of body.formats) {
    const option = document.createElement('option');
    option.value = f.format;
    option.textContent = `${f.format} (${f.kind}${f.parts ? ', parts' : ''})`;
    $('format').append(option);
  }
  $('file').accept = state.formats.map((f) => `.${f}`).join(',');
}

async function probeExport() {
  // export=urdf|sdf|mjcf is a 1.1 addition: offer the buttons only where the service's schema has it
  const { body } = await call('openapi.json', {});
  const params = body && body.paths && body.paths['/v1/analyze/mesh'] && body.paths['/v1/analyze/mesh'].post.parameters;
  state.exportable = Boolean(params && params.some((p) => p.name === 'export'));
  for (const b of document.querySelectorAll('button.export')) {
    b.hidden = !state.exportable;
  }
}

function setFile(file) {
  state.file = file;
  $('file-error').hidden = true;
  $('file').removeAttribute('aria-invalid');
  if (file) $('paste').value = '';
}

function wire() {
  $('form').addEventListener('submit', (e) => { e.preventDefault(); if (!state.busy) analyze(); });
  $('file').addEventListener('change', () => setFile($('file').files[0] || null));
  $('paste').addEventListener('input', () => { if ($('paste').value.trim()) { state.file = null; $('file').value = ''; } });
  const drop = $('drop');
  for (const ev of ['dragenter', 'dragover']) drop.addEventListener(ev, (e) => { e.preventDefault(); drop.classList.add('over'); });
  for (const ev of ['dragleave', 'drop']) drop.addEventListener(ev, () => drop.classList.remove('over'));
  drop.addEventListener('drop', (e) => {
    e.preventDefault();
    const file = e.dataTransfer.files[0];
    if (file) { setFile(file); $('file-formats').textContent = `Dropped: ${file.name}`; analyze(); }
  });
  $('dl-json').addEventListener('click', () => download(JSON.stringify(state.result, null, 2), `${stem()}.inertia.json`, 'application/json'));
  for (const b of document.querySelectorAll('button.export')) b.addEventListener('click', () => exportSnippet(b));
  $('play').addEventListener('click', () => (state.playing ? stop() : play()));
  $('time').addEventListener('input', () => {
    stop();
    const T = state.trajectory.t[state.trajectory.t.length - 1];
    seek(Number($('time').value) / 1000 * T);
  });
  $('apikey').addEventListener('change', () => { if (state.formats.length === 0) loadFormats(); });
  for (const id of ['body', 'axes', 'ellipsoid', 'cones']) {
    $(`show-${id}`).addEventListener('change', () => state.viewer && state.viewer.setVisible(id, $(`show-${id}`).checked));
  }
  window.addEventListener('resize', () => { if (state.trajectory && !$('motion').hidden) seek(state.time); });
}

async function main() {
  wire();
  state.viewer = Viewer.create($('viewer'));
  if (!state.viewer) $('view-note').textContent = 'WebGL is not available in this browser: the 3-D view is off; the numbers and plots still work.';
  await Promise.all([loadFormats(), probeExport()]);
  document.body.dataset.state = 'idle';
}

main();
