// volmorph edit's page: the state from the API, edits sent back one at a time, the in-between
// fetched anew after each edit that changes the pairs or the timing's sweep, and the hooks the
// browser test reads (window.volmorphEditor).
import * as api from './api.js';
import { View } from './view.js';
import { elementOf, interpolate, round4 } from './features.js';
import { showPairs, showFields, showErrors, showLabels } from './panels.js';

const $ = (id) => document.getElementById(id);
const view = new View($('view'));
let state = null;
let selected = 0;
let side = 'target';
let sweepHandle = null; // 'origin' or 'end' while the sweep's handle is selected
let t = 0.5;
let meshRequest = 0;
let editStart = 0;

/** What the browser test and the drag bench read. */
const hooks = {
  ready: false,
  morphUpdates: 0,
  lastUpdateMs: 0,
  state: () => state,
  screenPosition: (pair, s) => view.toScreen(state.pairs[pair - 1][s].origin),
  /** Where the sweep's handle `which` ('origin' or 'end') is on the page. */
  sweepScreenPosition: (which) => {
    const handle = view.sweep.handles.find((h) => h.userData.pick.sweep === which);
    return handle ? view.toScreen(handle.position.toArray()) : null;
  },
  /** The sweep's handle the gizmo holds ('origin', 'end'), or null. */
  sweepHandle: () => sweepHandle,
  /** The in-between's delays as received and whether they colour it: {count, min, max, colored}. */
  morphDelays: () => {
    const mesh = view.surfaces.morph;
    const d = mesh && mesh.geometry.userData.delays;
    if (!d) return { count: 0, colored: false };
    return { count: d.length, min: d.reduce((a, b) => Math.min(a, b)), max: d.reduce((a, b) => Math.max(a, b)),
             colored: mesh.material.vertexColors };
  },
  /** A whole pixel near the view's centre where surface `name` is under the cursor, and its point. */
  surfacePixel: (name) => {
    const r = view.renderer.domElement.getBoundingClientRect();
    const cx = Math.round(r.left + r.width / 2), cy = Math.round(r.top + r.height / 2);
    for (let radius = 0; radius < r.width / 2; radius += 8) {
      for (let k = 0; k < Math.max(1, radius); ++k) {
        const a = (2 * Math.PI * k) / Math.max(1, radius);
        const x = Math.round(cx + radius * Math.cos(a)), y = Math.round(cy + radius * Math.sin(a));
        const p = view.surfacePoint({ clientX: x, clientY: y }, name);
        if (p) return { x, y, point: p.toArray() };
      }
    }
    return null;
  },
  /** Milliseconds one redraw of the view takes, the GPU finished (median of `n`). */
  renderMs: (n = 5) => {
    const gl = view.renderer.getContext(), px = new Uint8Array(4), times = [];
    for (let i = 0; i < n; ++i) {
      const start = performance.now();
      view.renderNow();
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
      times.push(performance.now() - start);
    }
    return times.sort((a, b) => a - b)[Math.floor(n / 2)];
  },
};
window.volmorphEditor = hooks;

function status(text) { $('status').textContent = text; }

function redraw() {
  view.setPairs(state.pairs, t, selected, side);
  view.setTiming(state.timing);
  if (sweepHandle) view.selectSweep(sweepHandle);
  $('delay-legend').hidden = !(state.timing && state.timing.spread > 0);
  showPairs(state, selected, select);
  showFields(state, selected, (key, value) => edit('set', { key, value }));
  showErrors(state);
  labels();
  $('scene-name').textContent = state.scene;
  $('dirty').classList.toggle('on', state.dirty);
  $('undo').disabled = !state.canUndo;
  $('redo').disabled = !state.canRedo;
  $('duplicate').disabled = $('delete').disabled = !state.pairs[selected - 1];
  landmarkMode(state.landmarks);
}

/** Surface mode: the pairs are landmarks, points placed by hand (no other type, no suggestions). */
function landmarkMode(on) {
  $('suggest').disabled = on;
  $('suggest').title = on ? 'surface mode: landmarks are placed by hand'
    : 'append the pairs volmorph pairs suggest proposes';
  if (on) $('new-type').value = 'point';
  $('new-type').disabled = on;
}

/** The labels follow the view: placed after its next redraw. */
function labels() {
  if (view.labelsPending) return;
  view.labelsPending = true;
  view.afterRender.push(() => {
    view.labelsPending = false;
    showLabels(view, state, state.pairs.map((p) => interpolate(p.source, p.target, t)));
  });
  view.render();
}

function select(index) {
  selected = index;
  sweepHandle = null;
  redraw();
}

/** The in-between at t, unless a newer request was made meanwhile; on screen when the promise ends. */
async function refreshMorph() {
  const request = ++meshRequest;
  status('making the in-between...');
  try {
    const asked = performance.now();
    const geometry = await api.getMesh('morph', t);
    if (request !== meshRequest) return;
    const received = performance.now();
    view.setSurface('morph', geometry);
    await view.drawn();
    const shown = performance.now();
    hooks.timing = { edit: editStart ? asked - editStart : 0, mesh: received - asked, draw: shown - received };
    if (editStart) hooks.lastUpdateMs = shown - editStart;
    editStart = 0;
    hooks.morphUpdates += 1;
    status(`in-between at t = ${t.toFixed(2)}: ${geometry.index.count / 3} triangles`);
  } catch (e) {
    if (request === meshRequest) status(`in-between: ${e.message}`);
  }
}

/** Sends one edit after those before it have been answered (their states arrive in order); the new
 * state is drawn, and the in-between remade when the pairs changed. */
let edits = Promise.resolve();
function edit(action, body = {}) {
  edits = edits.then(() => sendEdit(action, body));
  return edits;
}

async function sendEdit(action, body) {
  editStart = performance.now();
  try {
    const morphed = (s) => JSON.stringify([s.pairs, s.timing]);
    const before = morphed(state);
    state = await api.post(action, body);
    if (selected > state.pairs.length) selected = state.pairs.length;
    if (action === 'add' || action === 'duplicate' || action === 'suggest') { selected = state.pairs.length; sweepHandle = null; }
    redraw();
    if (morphed(state) !== before) await refreshMorph();
    else status(action === 'save' ? `saved ${state.scene}` : state.valid ? 'no change to the pairs' : 'the scene has problems (right)');
  } catch (e) {
    status(`${action}: ${e.message}`);
  }
}

/** A new pair at the centres of the two sides, a non-point element a quarter of each side's box. */
function addPair() {
  const type = $('new-type').value;
  const element = (name) => {
    const { centre, size } = view.surfaceBox(name);
    const e = { origin: centre.map(round4) };
    if (type !== 'point') {
      e.axes = [[1, 0, 0], [0, 1, 0]];
      e.scale = size.map((v) => Math.max(round4(v / 4), 1e-3));
    }
    return e;
  };
  edit('add', { type, source: element('source'), target: element('target') });
}

function gizmoEdited() {
  const group = view.gizmo.object;
  if (!group || !group.userData.pick) return;
  if (group.userData.pick.sweep) {
    const values = view.sweep.edited(group, round4);
    if (values) edit('set', { values });
    return;
  }
  const { pair, side: s } = group.userData.pick;
  const field = { translate: 'origin', rotate: 'axes', scale: 'scale' }[view.gizmo.getMode()];
  const round = (v) => JSON.stringify(v, (k, x) => (typeof x === 'number' ? round4(x) : x));
  if (round(elementOf(group)[field]) === round(state.pairs[pair - 1][s][field])) return; // a click
  edit('set', { key: `pair[${pair}].${s}.${field}`, value: elementOf(group)[field] });
}

function pointerDown(event) {
  if (event.button !== 0 || view.gizmo.dragging) return;
  view.pointerStart = { x: event.clientX, y: event.clientY };
}

function pointerUp(event) {
  const start = view.pointerStart;
  view.pointerStart = null;
  if (!start || Math.hypot(event.clientX - start.x, event.clientY - start.y) > 4) return; // an orbit
  if (event.shiftKey && selected) {
    const p = view.surfacePoint(event, side);
    if (p) edit('set', { key: `pair[${selected}].${side}.origin`, value: p.toArray().map(round4) });
    return;
  }
  const hit = view.pick(event);
  if (hit && hit.sweep) { sweepHandle = hit.sweep; setMode('translate'); view.selectSweep(sweepHandle); return; }
  if (hit) { side = hit.side; document.querySelector(`input[name=side][value=${side}]`).checked = true; select(hit.pair); }
}

function keys(event) {
  if (event.target.tagName === 'INPUT' && event.target.type === 'number') return;
  const ctrl = event.ctrlKey || event.metaKey;
  const k = event.key.toLowerCase();
  if (ctrl && k === 'z') { event.preventDefault(); edit(event.shiftKey ? 'redo' : 'undo'); }
  else if (ctrl && k === 'y') { event.preventDefault(); edit('redo'); }
  else if (ctrl && k === 's') { event.preventDefault(); edit('save'); }
  else if (ctrl) return;
  else if (k === 'g' || k === 'r' || k === 's') setMode({ g: 'translate', r: 'rotate', s: 'scale' }[k]);
  else if (k === 'a') addPair();
  else if (k === 'd' && selected) edit('duplicate', { index: selected });
  else if ((k === 'delete' || k === 'backspace') && selected) edit('delete', { index: selected });
}

function setMode(mode) {
  view.gizmo.setMode(mode);
  document.querySelector(`input[name=mode][value=${mode}]`).checked = true;
}

function wire() {
  $('add').onclick = addPair;
  $('duplicate').onclick = () => edit('duplicate', { index: selected });
  $('delete').onclick = () => edit('delete', { index: selected });
  $('suggest').onclick = () => { status('suggesting pairs...'); edit('suggest'); };
  $('undo').onclick = () => edit('undo');
  $('redo').onclick = () => edit('redo');
  $('save').onclick = () => edit('save');
  for (const r of document.querySelectorAll('input[name=mode]')) r.onchange = () => setMode(r.value);
  for (const r of document.querySelectorAll('input[name=side]')) r.onchange = () => { side = r.value; view.select(selected, side); };
  for (const name of ['source', 'target', 'morph']) $(`show-${name}`).onchange = (e) => view.showSurface(name, e.target.checked);
  $('t').oninput = () => { t = Number($('t').value); $('t-value').textContent = t.toFixed(2); view.setTime(state.pairs, t); labels(); };
  $('t').onchange = () => refreshMorph();
  view.gizmo.addEventListener('dragging-changed', (e) => { if (!e.value) gizmoEdited(); });
  view.gizmo.addEventListener('objectChange', () => {
    if (view.gizmo.object && view.gizmo.object.userData.pick.sweep) view.sweep.follow(view.gizmo.object);
    labels();
  });
  $('show-delay').onchange = (e) => view.showDelay(e.target.checked);
  view.orbit.addEventListener('change', labels);
  const canvas = view.renderer.domElement;
  canvas.addEventListener('pointerdown', pointerDown);
  canvas.addEventListener('pointerup', pointerUp);
  window.addEventListener('keydown', keys);
}

async function start() {
  wire();
  try {
    state = await api.getState();
    view.setCamera(state.camera);
    const [source, target] = await Promise.all([api.getMesh('source'), api.getMesh('target')]);
    view.setSurface('source', source);
    view.setSurface('target', target);
    selected = state.pairs.length ? 1 : 0;
    redraw();
    await refreshMorph();
    hooks.ready = true;
  } catch (e) {
    status(`cannot load the scene: ${e.message}`);
  }
}

start();
