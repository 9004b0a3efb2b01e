// The chart beside the view: max planarity, thickness error and miter error per frame (log y), their
// targets as dashed horizontal lines, and the shown frame as a vertical line.

import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';

export const METRICS = [
  { field: 'planarity', key: 'planarity_max', label: 'planarity', color: '#c92a2a' },
  { field: 'thickness', key: 'thickness_error_max', label: 'thickness', color: '#1971c2' },
  { field: 'miter', key: 'miter_error_max', label: 'miter', color: '#d49a00' },
];
const MAX_POINTS = 20000;

const positive = (v) => (typeof v === 'number' && v > 0 && Number.isFinite(v) ? v : null);
const sci = (v) => (v === null || v === undefined ? '–' : v.toExponential(2));

export class Plot {
  constructor(container) {
    this.container = container;
    this.frames = [];
    this.values = METRICS.map(() => []);
    this.targets = METRICS.map(() => null);
    this.current = null;
    this.pending = false;
    const series = [{ label: 'frame', value: (u, v) => (v === null ? '–' : String(v)) }];
    for (const m of METRICS) series.push({ label: m.label, stroke: m.color, width: 1.6, value: (u, v) => sci(v), spanGaps: false });
    for (const m of METRICS) {
      series.push({ label: `${m.label} target`, stroke: m.color, width: 1, dash: [6, 4], value: (u, v) => sci(v), points: { show: false } });
    }
    const opts = {
      width: Math.max(200, container.clientWidth),
      height: Math.max(120, container.clientHeight - 30),
      series,
      scales: {
        x: { time: false },
        y: {
          distr: 3,
          log: 10,
          range: (u, min, max) => {
            if (!(min > 0) || !(max > 0)) return [1e-9, 1e-2];
            return [10 ** Math.floor(Math.log10(min)), 10 ** Math.ceil(Math.log10(max))];
          },
        },
      },
      axes: [
        { label: 'frame', labelSize: 16, size: 34, stroke: '#495057', grid: { stroke: '#e9ecef' }, ticks: { stroke: '#ced4da' } },
        {
          size: 58, stroke: '#495057', grid: { stroke: '#e9ecef' }, ticks: { stroke: '#ced4da' },
          // one grid line per decade, or every second / third one over a wide range
          splits: (u, axis, min, max) => {
            const lo = Math.ceil(Math.log10(min) - 1e-9);
            const hi = Math.floor(Math.log10(max) + 1e-9);
            const step = Math.max(1, Math.ceil((hi - lo) / 6));
            const out = [];
            for (let e = hi; e >= lo; e -= step) out.unshift(10 ** e);
            return out;
          },
          filter: (u, splits) => splits,
          values: (u, splits) => splits.map((v) => (v > 0 ? `1e${Math.round(Math.log10(v))}` : '')),
        },
      ],
      legend: { live: false },
      cursor: { drag: { x: false, y: false }, points: { size: 6 } },
      hooks: { draw: [(u) => this.drawCurrent(u)] },
    };
    this.chart = new uPlot(opts, this.data(), container);
    new ResizeObserver(() => this.resize()).observe(container);
  }

  resize() {
    const legend = this.chart.root.querySelector('.u-legend');
    const height = this.container.clientHeight - (legend ? legend.offsetHeight : 30) - 4;
    this.chart.setSize({ width: Math.max(200, this.container.clientWidth), height: Math.max(100, height) });
  }

  data() {
    const n = this.frames.length;
    const lines = this.targets.map((t) => new Array(n).fill(t));
    return [this.frames, ...this.values, ...lines];
  }

  /** Clears the chart; tolerances gives the targets drawn as horizontal lines. */
  reset(tolerances) {
    this.frames = [];
    this.values = METRICS.map(() => []);
    this.targets = METRICS.map((m) => positive(tolerances?.[m.field]?.target));
    this.current = null;
    this.redraw();
  }

  /** All rows of a metrics.jsonl at once (replay). */
  setRows(rows) {
    const sorted = rows.filter((r) => Number.isFinite(r.frame)).sort((a, b) => a.frame - b.frame);
    this.frames = sorted.map((r) => r.frame);
    this.values = METRICS.map((m) => sorted.map((r) => positive(r[m.key])));
    this.redraw();
  }

  /** One frame's metrics (live); redrawn at most once per animation frame. */
  push(row) {
    if (this.frames.length && row.frame <= this.frames[this.frames.length - 1]) {
      // a reset or a replayed frame: start over from here
      const keep = this.frames.findIndex((f) => f >= row.frame);
      this.frames.length = keep;
      for (const v of this.values) v.length = keep;
    }
    this.frames.push(row.frame);
    METRICS.forEach((m, k) => this.values[k].push(positive(row[m.key])));
    if (this.frames.length > MAX_POINTS) {
      const drop = this.frames.length - MAX_POINTS / 2;
      this.frames.splice(0, drop);
      for (const v of this.values) v.splice(0, drop);
    }
    if (!this.pending) {
      this.pending = true;
      requestAnimationFrame(() => {
        this.pending = false;
        this.redraw();
      });
    }
  }

  setCurrent(frame) {
    this.current = frame;
    this.chart.redraw(false, false);
  }

  redraw() {
    this.chart.setData(this.data(), true);
  }

  get points() {
    return this.frames.length;
  }

  drawCurrent(u) {
    if (this.current === null || !this.frames.length) return;
    const x = Math.round(u.valToPos(this.current, 'x', true));
    const { top, height, left, width } = u.bbox;
    if (x < left || x > left + width) return;
    const ctx = u.ctx;
    ctx.save();
    ctx.strokeStyle = 'rgba(33, 37, 41, 0.55)';
    ctx.lineWidth = Math.max(1, window.devicePixelRatio || 1);
    ctx.beginPath();
    ctx.moveTo(x + 0.5, top);
    ctx.lineTo(x + 0.5, top + height);
    ctx.stroke();
    ctx.restore();
  }
}
