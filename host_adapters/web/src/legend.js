// The colour bar of the selected metric, drawn with the shared colour function itself.

import { errorColor, GREY, UNMEASURED } from '../../node/lib/colors.js';
import { inUnits } from './hud.js';

const css = (c) => `rgb(${c.map((v) => Math.round(v * 255)).join(', ')})`;

export function renderLegend(container, metric, tolerances) {
  container.textContent = '';
  const tol = tolerances?.[metric];
  if (metric === 'none' || !tol) {
    container.hidden = true;
    return;
  }
  container.hidden = false;
  const stops = [];
  const steps = 24;
  for (let k = 0; k <= steps; k++) {
    const s = k / steps;
    const value = tol.target * (tol.max / tol.target) ** s * (1 + 1e-9);
    stops.push(`${css(errorColor(metric, value, tol))} ${(100 * s).toFixed(1)}%`);
  }
  const label = (v) => inUnits(metric, v, tolerances);

  const bar = document.createElement('div');
  bar.className = 'legend-bar';
  bar.style.background = `linear-gradient(to right, ${stops.join(', ')})`;
  const ends = document.createElement('div');
  ends.className = 'legend-ends';
  ends.innerHTML = '<span></span><span></span>';
  ends.children[0].textContent = `target ${label(tol.target)}`;
  ends.children[1].textContent = `max ${label(tol.max)}`;
  const keys = document.createElement('div');
  keys.className = 'legend-keys';
  for (const [color, text] of [[GREY, 'within tolerance'], [UNMEASURED, 'not measured']]) {
    const key = document.createElement('span');
    key.innerHTML = '<i></i>';
    key.firstChild.style.background = css(color);
    key.append(text);
    keys.appendChild(key);
  }
  const caption = document.createElement('div');
  caption.className = 'legend-caption';
  caption.textContent = 'log scale from the target to the max (clamped)';
  container.append(bar, ends, keys, caption);
}
