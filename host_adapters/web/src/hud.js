// The numbers at the bottom of the view, as in the paper's figures 12 and 13: the frame, each
// metric's max against its tolerance (the model's number and its value in units, inUnits), within
// tolerance yes / no, ms per frame and the frames received per second.

import { METRICS } from './plot.js';

/**
 * A metric's value in the units a designer reads, from the model's units and the tolerances'
 * unit_scale (mm per metre of panel per model unit: the model's lengths as mm on panels 1 m wide):
 * planarity (1 - n1.n2 of a quad's two triangles) as the fold angle acos(1 - v) in mrad; thickness
 * (model units) as mm at that scale; miter (a joint's twist, model units per panel) as mm per metre
 * of joint, that is mrad.
 */
export function inUnits(field, v, tolerances) {
  if (!Number.isFinite(v)) return '–';
  const scale = tolerances?.unit_scale ?? 1;
  if (field === 'planarity') return `${mm(1000 * Math.acos(Math.min(1, Math.max(-1, 1 - v))))} mrad`;
  if (field === 'thickness') return `${mm(v * scale)} mm`;
  if (field === 'miter') return `${mm(v * scale)} mrad`;
  return sci(v);
}

export function sci(v) {
  if (v === null || v === undefined || !Number.isFinite(v)) return '–';
  return v === 0 ? '0' : v.toExponential(2);
}

export function mm(v) {
  if (!Number.isFinite(v)) return '–';
  if (v === 0) return '0';
  if (Math.abs(v) < 1e-3) return v.toExponential(1);
  if (Math.abs(v) >= 100) return v.toFixed(0);
  return String(Number(v.toPrecision(3)));
}

function cell(className) {
  const el = document.createElement('div');
  el.className = `hud-cell ${className}`;
  el.innerHTML = '<span class="hud-label"></span><span class="hud-value"><span class="hud-number"></span>'
    + '<span class="hud-unit"></span></span><span class="hud-sub"></span>';
  return el;
}

export class Hud {
  constructor(container) {
    this.container = container;
    this.cells = {};
    const add = (key, label, cls = '') => {
      const el = cell(cls);
      el.querySelector('.hud-label').textContent = label;
      container.appendChild(el);
      this.cells[key] = el;
    };
    add('frame', 'frame', 'hud-frame');
    for (const m of METRICS) add(m.field, `${m.label} max`, `hud-metric hud-${m.field}`);
    add('within', 'within tolerance', 'hud-within');
    add('ms', 'ms / frame');
    add('fps', 'received');
  }

  set(key, value, sub = '', state = '', unit = '') {
    const el = this.cells[key];
    el.querySelector('.hud-number').textContent = value;
    el.querySelector('.hud-unit').textContent = unit;
    el.querySelector('.hud-sub').textContent = sub;
    el.dataset.state = state;
  }

  /**
   * frame: number; row: that frame's metrics (metrics.jsonl keys) or null; maxima: per field max
   * of the per-vertex errors (when the row lacks them); tolerances: the scene's.
   */
  update({ frame, row, maxima, tolerances, fps, fpsLabel }) {
    this.set('frame', frame === null || frame === undefined ? '–' : String(frame));
    let within = row?.within_tolerance;
    let measured = false;
    for (const m of METRICS) {
      const tol = tolerances?.[m.field];
      const value = row && Number.isFinite(row[m.key]) ? row[m.key] : maxima?.[m.field];
      if (value === undefined || value === null || !Number.isFinite(value) || !tol) {
        this.set(m.field, '–', tol ? `tolerance ${sci(tol.target)}` : '', '');
        continue;
      }
      measured = true;
      const over = value > tol.target;
      const sub = `target ${inUnits(m.field, tol.target, tolerances).split(' ')[0]} · max ${inUnits(m.field, tol.max, tolerances)}`;
      this.set(m.field, sci(value), sub, over ? (m.field === 'miter' ? 'over-yellow' : 'over') : 'ok',
        inUnits(m.field, value, tolerances));
      if (row?.within_tolerance === undefined && over) within = false;
    }
    if (within === undefined && measured) within = true;
    this.set('within', within === undefined ? '–' : within ? 'yes' : 'no', '', within === undefined ? '' : within ? 'ok' : 'over');
    this.set('ms', Number.isFinite(row?.ms) ? row.ms.toFixed(2) : '–', row?.settled ? 'settled' : '');
    this.set('fps', Number.isFinite(fps) ? `${fps.toFixed(0)} fps` : '–', fpsLabel || '');
  }
}
