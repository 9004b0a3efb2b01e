// embra's page: the live view of an embra-live server (WebSocket /live), or the replay of an
// `embra run` folder when opened as a file, with ?replay, or when no live server answers.
// docs/live-protocol.md is the contract with the server; window.embraView is the tests' view.

import './style.css';
import { errorColor, GREY } from '../../node/lib/colors.js';
import { View } from './view.js';
import { Plot } from './plot.js';
import { Hud, inUnits } from './hud.js';
import { renderLegend } from './legend.js';
import { LiveClient, liveUrl } from './live.js';
import { folderFromFiles, folderFromUrl, openReplay } from './replay.js';
import { base64Blob, basename, download, droppedFiles } from './files.js';

const PLAIN = [0.86, 0.84, 0.8]; // metric "none": the geometry alone
const $ = (id) => document.getElementById(id);
const ROWS_KEPT = 600; // frame rows kept for embraView.rows

const state = {
  mode: 'starting',
  connected: false,
  scene: null,
  frame: null,
  framesReceived: 0,
  firstFrame: null, // the number of the first frame received from the server
  fights: null, // the last `fights` message, with energyOf (a Map) and maxEnergy
  rows: [], // the last ROWS_KEPT frame rows received (the server's metrics of each frame)
  fps: 0,
  positions: null,
  fields: {},
  row: null,
  metric: 'planarity',
  lastError: null,
  paused: false,
  replay: null,
  frameIndex: -1,
};

const view = new View($('view'));
const plot = new Plot($('plot'));
const hud = new Hud($('hud'));
let live = null;
let pendingFrame = null;
const receivedAt = [];

// --- messages --------------------------------------------------------------------------------

function log(message, kind = 'info') {
  const el = $('log');
  el.textContent = message;
  el.dataset.kind = kind;
  el.title = message;
}

function showError(message) {
  state.lastError = message;
  log(message, 'error');
  console.warn(`embra: ${message}`);
}

// --- colours and numbers ---------------------------------------------------------------------

/**
 * Metric "fights": a particle in one of the worst constraints of the last `fights` message shaded
 * from light to full magenta on a log scale of its energy (violation x force) over 6 decades below
 * the largest; every other particle grey.
 */
function fightColor(i) {
  const f = state.fights;
  const e = f?.energyOf.get(i);
  if (!e || !(f.maxEnergy > 0)) return GREY;
  const s = Math.min(1, Math.max(0, 1 + Math.log10(e / f.maxEnergy) / 6));
  return [0.95 - 0.25 * s, 0.75 - 0.65 * s, 0.95 - 0.2 * s];
}

function colorOf(i) {
  if (state.metric === 'fights') return fightColor(i);
  const values = state.fields[state.metric];
  if (state.metric === 'none' || !values) return PLAIN;
  return errorColor(state.metric, values[i], state.scene.tolerances[state.metric]);
}

function recolor() {
  if (state.scene) view.setColors(colorOf);
}

function fieldMaxima() {
  const out = {};
  for (const [name, values] of Object.entries(state.fields)) {
    let max = -Infinity;
    for (const v of values) if (v > max) max = v;
    if (max > -Infinity) out[name] = max;
  }
  return out;
}

function updateHud() {
  hud.update({
    frame: state.frame,
    row: state.row,
    maxima: state.row?.planarity_max === undefined ? fieldMaxima() : null,
    tolerances: state.scene?.tolerances,
    fps: state.mode === 'live' ? state.fps : NaN,
    fpsLabel: state.mode === 'live' ? `${state.framesReceived} frames` : state.mode,
  });
}

function setMetric(metric) {
  state.metric = metric;
  $('metric').value = metric;
  renderLegend($('legend'), metric, state.scene?.tolerances);
  recolor();
}

// --- scene -----------------------------------------------------------------------------------

function applyScene(scene) {
  // A new scene (a reset, another page's edit) ends a drag in progress (after a reset the server has
  // already dropped its pin; drag_end then changes nothing).
  if (pointer.drag) {
    if (pointer.drag.kind === 'particle') {
      send({ type: 'drag_end' });
      view.showDrag(null, null);
    }
    else if (pointer.drag.kind === 'collider') view.heldCollider = -1;
    pointer.drag = null;
    view.controls.enabled = true;
  }
  const sameScene = state.scene && state.scene.name === scene.name && state.scene.particles === scene.particles;
  state.scene = scene;
  state.fields = {};
  state.row = null;
  state.frame = null;
  view.setScene(scene);
  if (!sameScene) view.framed = false;
  $('scene-name').textContent = scene.name;
  $('scene-name').title = scene.description || '';
  document.title = `embra · ${scene.name}`;
  const select = $('metric');
  const fights = state.mode === 'live' || state.mode === 'connecting';
  for (const option of select.options) {
    option.disabled = option.value === 'fights' ? !fights : option.value !== 'none' && !scene.fields.includes(option.value);
  }
  const keep = scene.fields.includes(state.metric) || (state.metric === 'fights' && fights);
  const metric = keep ? state.metric : scene.fields[0] || 'none';
  setMetric(metric);
  // An edit (pins, a weight) re-sends the same scene: the history stays; a reset shows in the plot
  // as a frame going back, which plot.push handles.
  if (!sameScene) plot.reset(scene.tolerances);
  view.setPinsVisible(scene.pins_on !== false);
  if (state.mode === 'live') buildLivePanels(scene);
}

/** Geometry of one frame: positions, collider poses, error fields by name. */
function showGeometry(frame, positions, poses, fieldArrays) {
  state.frame = frame;
  state.positions = positions;
  state.fields = {};
  state.scene.fields.forEach((name, k) => {
    if (fieldArrays[k]) state.fields[name] = fieldArrays[k];
  });
  view.setFrame(positions, poses);
  if (!view.framed) view.frameAll();
  recolor();
  updateHud();
}

// --- live ------------------------------------------------------------------------------------

function startLive() {
  state.mode = 'connecting';
  $('mode').textContent = 'connecting';
  const url = liveUrl();
  live = new LiveClient(url, {
    open() {
      state.mode = 'live';
      state.connected = true;
      $('mode').textContent = 'live';
      $('mode').dataset.state = 'live';
      $('live-controls').hidden = false;
      $('help-live').hidden = false;
      log(`connected to ${url}`);
    },
    close(wasOpen) {
      state.connected = false;
      if (!wasOpen) {
        startReplay(null, `no live server at ${url}: replay mode`);
        return;
      }
      $('mode').textContent = 'disconnected';
      $('mode').dataset.state = 'off';
      showError(`connection to ${url} closed`);
    },
    scene(msg) {
      applyScene(msg);
      setStatus(msg);
    },
    frame(row, geometry) {
      if (!state.scene || geometry.particles !== state.scene.particles) return;
      state.framesReceived += 1;
      if (state.firstFrame === null) state.firstFrame = geometry.frame;
      state.rows.push(row);
      if (state.rows.length > ROWS_KEPT) state.rows.shift();
      const now = performance.now();
      receivedAt.push(now);
      while (receivedAt.length && receivedAt[0] < now - 1000) receivedAt.shift();
      state.row = row;
      plot.push(row);
      pendingFrame = geometry; // shown at the next animation frame; older ones are skipped
      state.frame = geometry.frame;
      state.positions = geometry.positions;
    },
    status: setStatus,
    fights: showFights,
    saved(msg) {
      download(basename(msg.path) || `${state.scene?.name || 'scene'}-${state.frame}.json`,
        new Blob([msg.json], { type: 'application/json' }));
      log(`saved ${msg.path}`);
    },
    exported(msg) {
      const ext = msg.format === '3dm' ? '3dm' : 'gltf';
      const type = msg.format === '3dm' ? 'application/octet-stream' : 'model/gltf+json';
      download(basename(msg.path) || `${state.scene?.name || 'scene'}-${state.frame}.${ext}`, base64Blob(msg.base64, type));
      log(`exported ${msg.path}`);
    },
    error(msg) {
      showError(msg.message);
    },
  });
}

const fmt = (v) => (Math.abs(v) >= 0.01 && Math.abs(v) < 1e4 ? String(Number(v.toPrecision(3))) : v.toExponential(2));
const FORCE_UNIT = { m: 'N', rad: 'N m', 'm^3': 'N/m^2' };

/** The `fights` message: the worst constraints and the groups pulling against each other. */
function showFights(msg) {
  const energyOf = new Map(msg.energy);
  let maxEnergy = 0;
  for (const e of energyOf.values()) maxEnergy = Math.max(maxEnergy, e);
  state.fights = { ...msg, energyOf, maxEnergy };
  const list = $('fights-list');
  list.textContent = '';
  for (const c of msg.worst) {
    const li = document.createElement('li');
    const what = c.pin ? `pin ${c.pin}` : `${c.kind} #${c.index}`;
    li.textContent = `${what} · ${c.group} · particles ${c.particles.join(', ')} · off ${fmt(c.violation)} ${c.unit}, ` +
      `${fmt(c.force)} ${FORCE_UNIT[c.unit] || 'N'}`;
    list.appendChild(li);
  }
  const pairs = $('fights-conflicts');
  pairs.textContent = '';
  for (const c of msg.conflicts.filter((x) => x.particles > 0)) {
    const li = document.createElement('li');
    li.textContent = `${c.a} against ${c.b}: ${fmt(c.force)} N on ${c.particles} particle${c.particles === 1 ? '' : 's'}`;
    pairs.appendChild(li);
  }
  $('fights-panel').hidden = false;
  if (state.metric === 'fights') recolor();
}

function setStatus(msg) {
  if (typeof msg.paused === 'boolean') state.paused = msg.paused;
  $('pause').textContent = state.paused ? 'Run' : 'Pause';
  $('pause').classList.toggle('active', state.paused);
  $('step').disabled = !state.paused;
  if (typeof msg.gravity_on === 'boolean') $('gravity').checked = msg.gravity_on;
  if (typeof msg.pins_on === 'boolean') {
    $('pins').checked = msg.pins_on;
    view.setPinsVisible(msg.pins_on);
  }
}

function send(msg) {
  if (!live || !live.send(msg)) showError('not connected');
}

const pendingRestScale = new Map();

function buildLivePanels(scene) {
  const groups = $('groups');
  groups.textContent = '';
  for (const g of scene.groups || []) {
    const row = document.createElement('label');
    row.className = 'row';
    row.textContent = g.name;
    const input = document.createElement('input');
    Object.assign(input, { type: 'number', min: 1, max: 1000, step: 1, value: g.weight });
    input.addEventListener('change', () => {
      const weight = Math.round(Number(input.value));
      if (weight >= 1 && weight <= 1000) send({ type: 'group_weight', index: g.index, weight });
      else showError(`group weight ${input.value}: a whole number from 1 to 1000`);
    });
    row.appendChild(input);
    groups.appendChild(row);
  }
  $('groups-panel').hidden = !(scene.groups || []).length;

  const bodies = $('bodies');
  bodies.textContent = '';
  for (const b of scene.bodies) {
    const box = document.createElement('div');
    box.className = 'body-scale';
    const title = document.createElement('div');
    title.className = 'body-name';
    title.textContent = b.name;
    box.appendChild(title);
    const values = [...(b.rest_scale || [1, 1, 1])];
    ['scale', 'u', 'v'].forEach((label, k) => {
      const row = document.createElement('label');
      row.className = 'row slider-row';
      const name = document.createElement('span');
      name.textContent = label;
      const input = document.createElement('input');
      Object.assign(input, { type: 'range', min: 0.5, max: 1.5, step: 0.005, value: values[k] });
      const out = document.createElement('output');
      out.textContent = Number(values[k]).toFixed(3);
      input.addEventListener('input', () => {
        values[k] = Number(input.value);
        out.textContent = values[k].toFixed(3);
        pendingRestScale.set(b.index, { type: 'rest_scale', body: b.index, scale: values[0], scale_u: values[1], scale_v: values[2] });
      });
      row.append(name, input, out);
      box.appendChild(row);
    });
    bodies.appendChild(box);
  }
  $('bodies-panel').hidden = scene.bodies.length === 0;
}

function wireLiveControls() {
  $('pause').addEventListener('click', () => send({ type: 'pause', paused: !state.paused }));
  $('step').addEventListener('click', () => send({ type: 'step' }));
  $('reset').addEventListener('click', () => send({ type: 'reset' }));
  $('gravity').addEventListener('change', (e) => send({ type: 'gravity', on: e.target.checked }));
  $('pins').addEventListener('change', (e) => send({ type: 'pins', on: e.target.checked }));
  $('save').addEventListener('click', () => send({ type: 'save' }));
  const metricForExport = () => (state.metric === 'none' || state.metric === 'fights' ? state.scene?.fields[0] || 'planarity' : state.metric);
  $('export-gltf').addEventListener('click', () => send({ type: 'export', format: 'gltf', metric: metricForExport() }));
  $('export-3dm').addEventListener('click', () => send({ type: 'export', format: '3dm', metric: metricForExport() }));
  $('export-all').addEventListener('click', () => send({ type: 'export_all', metric: metricForExport() }));
}

// --- mouse: drag a particle, shift-drag a collider, hover readout -----------------------------

const pointer = { drag: null, hover: null };

function onPointerDown(e) {
  if (state.mode !== 'live' || !state.connected || e.button !== 0 || !state.positions) return;
  if (e.shiftKey) {
    const hit = view.pickCollider(e.clientX, e.clientY);
    if (!hit) return;
    const position = view.colliderPosition(hit.index);
    pointer.drag = {
      kind: 'collider', index: hit.index, plane: view.cameraPlane(hit.point),
      offset: position.sub(hit.point), pending: null, pointerId: e.pointerId,
    };
    view.heldCollider = hit.index;
  } else if (view.pickPin(e.clientX, e.clientY)) {
    const hit = view.pickPin(e.clientX, e.clientY);
    pointer.drag = { kind: 'pin', index: hit.index, plane: view.cameraPlane(hit.point), pending: null, pointerId: e.pointerId };
  } else {
    const hit = view.pickParticle(e.clientX, e.clientY);
    if (!hit) return;
    const p = view.particle(hit.particle);
    pointer.drag = { kind: 'particle', particle: hit.particle, plane: view.cameraPlane(p), pending: null, pointerId: e.pointerId };
    send({ type: 'drag_start', particle: hit.particle, target: [p.x, p.y, p.z] });
    view.showDrag(hit.particle, p);
  }
  view.controls.enabled = false; // OrbitControls' own pointerdown (on the canvas) now does nothing
  view.canvas.setPointerCapture(e.pointerId);
  view.showHover(null);
  $('hover').hidden = true;
  e.preventDefault();
}

function onPointerMove(e) {
  const drag = pointer.drag;
  if (drag) {
    const point = view.onPlane(e.clientX, e.clientY, drag.plane);
    if (point) drag.pending = point;
    return;
  }
  if (e.buttons === 0) pointer.hover = { x: e.clientX, y: e.clientY };
}

function onPointerUp(e) {
  const drag = pointer.drag;
  if (!drag) return;
  flushDrag();
  if (drag.kind === 'particle') {
    const pin = $('pin-here').checked || e.altKey;
    send(pin ? { type: 'drag_end', pin: true } : { type: 'drag_end' });
    view.showDrag(null, null);
  } else if (drag.kind === 'pin') {
    // the dot follows its particle, which the hard pin carries to the target
  } else {
    view.heldCollider = -1;
  }
  if (view.canvas.hasPointerCapture(drag.pointerId)) view.canvas.releasePointerCapture(drag.pointerId);
  pointer.drag = null;
  view.controls.enabled = true;
}

/** Sends the latest drag target (once per animation frame). */
function flushDrag() {
  const drag = pointer.drag;
  if (!drag || !drag.pending) return;
  const point = drag.pending;
  drag.pending = null;
  if (drag.kind === 'particle') {
    send({ type: 'drag', target: [point.x, point.y, point.z] });
    view.showDrag(drag.particle, point);
  } else if (drag.kind === 'pin') {
    send({ type: 'pin_target', index: drag.index, target: [point.x, point.y, point.z] });
  } else {
    const position = point.clone().add(drag.offset);
    view.moveCollider(drag.index, position);
    send({ type: 'collider_pose', index: drag.index, position: [position.x, position.y, position.z], rotation: view.colliderRotation(drag.index) });
  }
}

function updateHover() {
  const at = pointer.hover;
  pointer.hover = null;
  if (!at || !state.scene || !state.positions) return;
  const hit = view.pickParticle(at.x, at.y);
  const el = $('hover');
  if (!hit) {
    el.hidden = true;
    view.showHover(null);
    return;
  }
  view.showHover(hit.particle);
  const tol = state.scene.tolerances || {};
  const parts = [`particle ${hit.particle}`];
  for (const [name, values] of Object.entries(state.fields)) {
    const v = values[hit.particle];
    if (!Number.isFinite(v)) {
      parts.push(`${name} –`);
      continue;
    }
    parts.push(`${name} ${inUnits(name, v, tol)}${tol[name] && v > tol[name].target ? ' ▲' : ''}`);
  }
  el.textContent = parts.join('  ·  ');
  el.hidden = false;
}

function wirePointer() {
  const wrap = $('view');
  // capture phase on the container: runs before OrbitControls' listener on the canvas
  wrap.addEventListener('pointerdown', onPointerDown, { capture: true });
  wrap.addEventListener('pointermove', onPointerMove);
  wrap.addEventListener('pointerup', onPointerUp);
  wrap.addEventListener('pointercancel', onPointerUp);
  wrap.addEventListener('pointerleave', () => {
    if (!pointer.drag) {
      $('hover').hidden = true;
      view.showHover(null);
    }
  });
}

// --- replay ----------------------------------------------------------------------------------

let playTimer = null;
let frameRequest = 0;

function startReplay(url, message) {
  if (live) {
    live.close();
    live = null;
  }
  state.mode = 'replay';
  state.connected = false;
  $('mode').textContent = 'replay';
  $('mode').dataset.state = 'replay';
  $('live-controls').hidden = true;
  $('groups-panel').hidden = true;
  $('bodies-panel').hidden = true;
  $('replay-controls').hidden = false;
  $('help-live').hidden = true;
  $('help-replay').hidden = false;
  $('drop-hint').hidden = !!url;
  if (message) log(message);
  if (url) loadReplay(() => folderFromUrl(url), url);
}

async function loadReplay(makeFolder, label) {
  stopPlay();
  log(`loading ${label}…`);
  try {
    const folder = await makeFolder();
    const replay = await openReplay(folder);
    state.replay = replay;
    state.frameIndex = -1;
    state.metricsByFrame = new Map(replay.metrics.map((row) => [row.frame, row]));
    applyScene(replay.scene);
    plot.setRows(replay.metrics);
    const slider = $('slider');
    slider.max = String(replay.frames.length - 1);
    slider.disabled = replay.frames.length < 2;
    $('drop-hint').hidden = true;
    await showFrameIndex(replay.frames.length - 1);
    const errors = replay.frames.filter((f) => f.errors).length;
    log(`${label}: ${replay.frames.length} frames, ${replay.metrics.length} metrics rows, ${errors} error maps`);
  } catch (err) {
    showError(`${label}: ${err.message}`);
  }
}

async function showFrameIndex(index) {
  const replay = state.replay;
  if (!replay) return;
  const i = Math.max(0, Math.min(replay.frames.length - 1, Math.round(index)));
  const request = ++frameRequest;
  const entry = replay.frames[i];
  $('slider').value = String(i);
  $('slider-label').textContent = `frame ${entry.frame}${entry.final ? ' (final)' : ''} · ${i + 1} / ${replay.frames.length}`;
  let data;
  try {
    data = await replay.frameData(i);
  } catch (err) {
    showError(`${entry.obj}: ${err.message}`);
    return;
  }
  if (request !== frameRequest) return; // a later request won
  state.frameIndex = i;
  state.row = state.metricsByFrame.get(data.frame) || null;
  showGeometry(data.frame, data.positions, data.poses, data.fields);
  plot.setCurrent(data.frame);
}

function stopPlay() {
  if (playTimer) clearInterval(playTimer);
  playTimer = null;
  $('play').textContent = 'Play';
}

function togglePlay() {
  if (playTimer) {
    stopPlay();
    return;
  }
  const replay = state.replay;
  if (!replay || replay.frames.length < 2) return;
  if (state.frameIndex >= replay.frames.length - 1) showFrameIndex(0);
  $('play').textContent = 'Stop';
  playTimer = setInterval(() => {
    if (state.frameIndex >= replay.frames.length - 1) stopPlay();
    else showFrameIndex(state.frameIndex + 1);
  }, 125);
}

function wireReplayControls() {
  const pick = (e) => {
    const files = [...e.target.files];
    if (files.length) loadReplay(async () => folderFromFiles(files), files[0].webkitRelativePath?.split('/')[0] || `${files.length} files`);
    e.target.value = '';
  };
  $('folder').addEventListener('change', pick);
  $('files').addEventListener('change', pick);
  $('slider').addEventListener('input', (e) => {
    stopPlay();
    showFrameIndex(Number(e.target.value));
  });
  $('play').addEventListener('click', togglePlay);
  document.addEventListener('dragover', (e) => {
    e.preventDefault();
    document.body.classList.add('dropping');
  });
  document.addEventListener('dragleave', (e) => {
    if (e.target === document.documentElement || e.clientX <= 0 || e.clientY <= 0) document.body.classList.remove('dropping');
  });
  document.addEventListener('drop', async (e) => {
    e.preventDefault();
    document.body.classList.remove('dropping');
    if (state.mode === 'live') return;
    const files = await droppedFiles(e.dataTransfer);
    if (files.length) loadReplay(async () => folderFromFiles(files), `${files.length} dropped files`);
  });
}

// --- keys, loop, start -----------------------------------------------------------------------

function onKey(e) {
  if (e.target.closest('input, select, textarea')) return;
  if (state.mode === 'replay' && state.replay) {
    if (e.key === 'ArrowLeft') showFrameIndex(state.frameIndex - 1);
    else if (e.key === 'ArrowRight') showFrameIndex(state.frameIndex + 1);
    else if (e.key === ' ') togglePlay();
    else return;
  } else if (state.mode === 'live') {
    if (e.key === ' ') send({ type: 'pause', paused: !state.paused });
    else if (e.key === '.' && state.paused) send({ type: 'step' });
    else return;
  } else {
    return;
  }
  e.preventDefault();
}

function loop() {
  if (pendingFrame) {
    const g = pendingFrame;
    pendingFrame = null;
    showGeometry(g.frame, g.positions, g.poses, g.fields);
    // Paces the server (docs/live-protocol.md, `drawn`): it sends the next frames as this one is
    // drawn, so a page that draws slowly shows the latest frame, not a queue of old ones.
    if (state.mode === 'live' && live) live.send({ type: 'drawn', frame: g.frame });
  }
  if (state.mode === 'live') {
    const now = performance.now();
    while (receivedAt.length && receivedAt[0] < now - 1000) receivedAt.shift();
    const fps = receivedAt.length;
    if (fps !== state.fps) {
      state.fps = fps;
      updateHud();
    }
    flushDrag();
    for (const msg of pendingRestScale.values()) send(msg);
    pendingRestScale.clear();
  }
  updateHover();
  view.tick();
  requestAnimationFrame(loop);
}

window.embraView = {
  get mode() { return state.mode; },
  get connected() { return state.connected; },
  get frame() { return state.frame; },
  get framesReceived() { return state.framesReceived; },
  get firstFrame() { return state.firstFrame; },
  /** The last frame rows received (up to 600), oldest first. */
  get rows() { return state.rows; },
  get fps() { return state.fps; },
  get positions() { return state.positions; },
  get plotPoints() { return plot.points; },
  get scene() { return state.scene; },
  get lastError() { return state.lastError; },
  /** The particle a mouse drag holds (null when none). */
  get dragParticle() { return pointer.drag?.kind === 'particle' ? pointer.drag.particle : null; },
  /** The scene pin whose dot a mouse drag holds (null when none). */
  get dragPin() { return pointer.drag?.kind === 'pin' ? pointer.drag.index : null; },
  get metric() { return state.metric; },
  get fields() { return state.fields; },
  /** The last `fights` message (null before one arrives). */
  get fights() { return state.fights; },
  /** The colour attribute's array (3 floats per particle, errorColor's values). */
  get colors() { return view.color ? view.color.array : null; },
  get vertexCount() { return view.position ? view.position.count : 0; },
  /** Edges drawn as lines (edge-only bodies: `l` lines of a replay's OBJ). */
  get edgeCount() { return view.edgeLines.reduce((n, l) => n + l.geometry.index.count / 2, 0); },
  get triangleCount() { return view.meshes.reduce((n, m) => n + m.geometry.index.count / 3, 0); },
  /** Replay: the frame numbers the slider steps through, and the shown one's index. */
  get replayFrames() { return state.replay ? state.replay.frames.map((f) => f.frame) : []; },
  get frameIndex() { return state.frameIndex; },
  screenOf: (particle) => view.screenOf(particle),
  /** A world point's page pixel coordinates, e.g. a collider's centre: screenOfPoint([x, y, z]). */
  screenOfPoint: ([x, y, z]) => view.screenOfPoint({ x, y, z }),
  /** A collider's shown position (moved by frames and by shift-drags). */
  colliderPosition: (index) => view.colliderPosition(index)?.toArray() ?? null,
  setMetric,
  showFrameIndex,
  frameAll: () => view.frameAll(),
};

$('metric').addEventListener('change', (e) => setMetric(e.target.value));
document.addEventListener('keydown', onKey);
wireLiveControls();
wireReplayControls();
wirePointer();
updateHud();

const params = new URLSearchParams(window.location.search);
if (window.location.protocol === 'file:' || params.has('replay')) {
  startReplay(params.get('replay') || null, params.get('replay') ? null : 'open an embra run folder');
} else {
  startLive();
}
requestAnimationFrame(loop);
