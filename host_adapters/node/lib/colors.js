'use strict';
// The paper's colour convention for fabrication errors (figures 12 and 13), shared by the page and
// the glTF / .3dm export: at or below the target grey; above it shaded on a log scale up to the
// max (clamped), light to full red (miter: yellow); not measured blue-grey.

const GREY = [0.62, 0.62, 0.62];
const UNMEASURED = [0.55, 0.62, 0.72];
const RAMPS = {
  red: [[0.98, 0.72, 0.66], [0.8, 0.02, 0.02]],
  yellow: [[0.99, 0.93, 0.6], [0.92, 0.7, 0.0]],
};

/** Where value sits between target (0) and max (1) on a log scale; 0 at or below the target. */
function severity(value, tolerance) {
  const { target, max } = tolerance;
  if (!(value > target)) return 0;
  if (!(max > target) || target <= 0) return 1;
  const s = Math.log(value / target) / Math.log(max / target);
  return Math.min(1, Math.max(0, s));
}

/** RGB in [0, 1] for a metric's value against its tolerance {target, max}. */
function errorColor(metric, value, tolerance) {
  if (value === null || value === undefined || Number.isNaN(value)) return UNMEASURED.slice();
  if (!(value > tolerance.target)) return GREY.slice();
  const [lo, hi] = metric === 'miter' ? RAMPS.yellow : RAMPS.red;
  const s = severity(value, tolerance);
  return [0, 1, 2].map((k) => lo[k] + (hi[k] - lo[k]) * s);
}

module.exports = { errorColor, severity, GREY, UNMEASURED };
