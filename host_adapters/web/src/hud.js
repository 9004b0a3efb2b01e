// The numbers at the bottom of the view, as in the paper's figures 12 and 13: the frame, each
// metric's max against its tolerance (model units, and mm per metre through unit_scale for the
// lengths), within tolerance yes / no, ms per frame and the frames received per second.

import { METRICS } from './plot.js';

const LENGTHS = new Set(['thickness', 'miter']); // planarity is 1 - cos: no length

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
    const scale = tolerances?.unit_scale ?? 1;
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
      const length = LENGTHS.has(m.field);
      const sub = length ? `tolerance ${sci(tol.target)} · ${mm(tol.target * scale)} mm/m` : `tolerance ${sci(tol.target)}`;
      const unit = length ? `${mm(value * scale)} mm/m` : '';
      this.set(m.field, sci(value), sub, over ? (m.field === 'miter' ? 'over-yellow' : 'over') : 'ok', unit);
      if (row?.within_tolerance === undefined && over) within = false;
    }
    if (within === undefined && measured) within = true;
    this.set('within', within === undefined ? '–' : within ? 'yes' : 'no', '', within === undefined ? '' : within ? 'ok' : 'over');
    this.set('ms', Number.isFinite(row?.ms) ? row.ms.toFixed(2) : '–', row?.settled ? 'settled' : '');
    this.set('fps', Number.isFinite(fps) ? `${fps.toFixed(0)} fps` : '–', fpsLabel || '');
  }
}
