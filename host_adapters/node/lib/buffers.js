'use strict';
// Checked conversions of JS values for the C ABI, so nothing reaches koffi that it would silently
// wrap, truncate or misread (koffi turns 2**40 into 0 and 1.5 into 1 for an int32_t).
//
// Bulk inputs: a Float64Array (Int32Array for indices) is handed to C in place; any other typed array
// or a flat or nested JS array ([x, y, z, ...] or [[x, y, z], ...]) is checked and packed once.
// Bulk outputs are Float64Array / Int32Array written by C in place, or the caller's own.

const INT32_MIN = -(2 ** 31);
const INT32_MAX = 2 ** 31 - 1;
const UINT32_MAX = 2 ** 32 - 1;

function describe(value) {
  if (value === null) return 'null';
  if (Array.isArray(value)) return 'an array';
  if (ArrayBuffer.isView(value)) return value.constructor.name;
  return typeof value === 'object' ? (value.constructor ? value.constructor.name : 'an object') : typeof value;
}

/** A number (NaN and infinities pass: the C library refuses them with its own message). */
function number(value, name) {
  if (typeof value !== 'number') throw new TypeError(`${name}: expected a number, got ${describe(value)}`);
  return value;
}

/** An integer that fits int32 (else TypeError for a non-integer, RangeError for one out of range). */
function int32(value, name) {
  if (typeof value !== 'number' || !Number.isInteger(value)) {
    throw new TypeError(`${name}: expected an integer, got ${typeof value === 'number' ? value : describe(value)}`);
  }
  if (value < INT32_MIN || value > INT32_MAX) throw new RangeError(`${name}: ${value} does not fit in int32`);
  return value;
}

function uint32(value, name) {
  if (typeof value !== 'number' || !Number.isInteger(value)) {
    throw new TypeError(`${name}: expected an integer, got ${typeof value === 'number' ? value : describe(value)}`);
  }
  if (value < 0 || value > UINT32_MAX) throw new RangeError(`${name}: ${value} does not fit in uint32`);
  return value;
}

/** An integer within the doubles' exact range (int64 fields). */
function int64(value, name) {
  if (typeof value !== 'number' || !Number.isSafeInteger(value)) {
    throw new TypeError(`${name}: expected a safe integer, got ${typeof value === 'number' ? value : describe(value)}`);
  }
  return value;
}

function isNumericView(value) {
  return ArrayBuffer.isView(value) && !(value instanceof DataView) && !(value instanceof BigInt64Array) &&
    !(value instanceof BigUint64Array);
}

/** The numbers of a flat or once-nested array (or a typed array), each checked by `each`. */
function flatten(value, name, each) {
  if (isNumericView(value)) return Array.from(value, (v) => each(v, name));
  if (!Array.isArray(value)) {
    throw new TypeError(`${name}: expected an array or a typed array of numbers, got ${describe(value)}`);
  }
  const out = [];
  value.forEach((item, i) => {
    if (typeof item === 'number') {
      out.push(each(item, `${name}[${i}]`));
    } else if (Array.isArray(item) || isNumericView(item)) {
      for (let k = 0; k < item.length; k++) out.push(each(item[k], `${name}[${i}][${k}]`));
    } else {
      throw new TypeError(`${name}[${i}]: expected a number or an array of numbers, got ${describe(item)}`);
    }
  });
  return out;
}

/** A Float64Array of the input (the caller's own when it is one: no copy); null for null/undefined. */
function doublesIn(value, name) {
  if (value === null || value === undefined) return null;
  if (value instanceof Float64Array) return value;
  return Float64Array.from(flatten(value, name, number));
}

/** An Int32Array of index data (the caller's own when it is one); null for null/undefined. */
function intsIn(value, name) {
  if (value === null || value === undefined) return null;
  if (value instanceof Int32Array) return value;
  return Int32Array.from(flatten(value, name, int32));
}

/** Exactly `n` numbers (a vector of a def or a call: gravity, target, rotation, ...) as a plain array. */
function fixed(value, n, name) {
  if (!Array.isArray(value) && !isNumericView(value)) {
    throw new TypeError(`${name}: expected ${n} numbers, got ${describe(value)}`);
  }
  if (value.length !== n) throw new RangeError(`${name}: expected ${n} numbers, got ${value.length}`);
  return Array.from(value, (v, i) => number(v, `${name}[${i}]`));
}

/** The caller's output buffer (a Float64Array C writes in place) or a new one of `length` doubles. */
function doublesOut(length, out, name) {
  if (out === null || out === undefined) return new Float64Array(length);
  if (!(out instanceof Float64Array)) throw new TypeError(`${name}: expected a Float64Array, got ${describe(out)}`);
  return out;
}

/** A string for a `const char *` (no NUL inside: C would read only up to it). */
function cString(value, name) {
  if (typeof value !== 'string') throw new TypeError(`${name}: expected a string, got ${describe(value)}`);
  if (value.includes('\0')) throw new RangeError(`${name}: contains a NUL character`);
  return value;
}

module.exports = {
  INT32_MIN, INT32_MAX, describe, number, int32, uint32, int64, doublesIn, intsIn, fixed, doublesOut, cString,
};
