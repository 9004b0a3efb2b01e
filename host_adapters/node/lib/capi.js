'use strict';
// The C ABI of libembra as koffi sees it, loaded: the generated mirror and the library.
//
// The constants, enums, structs and the table of prototypes are generated from
// capi/include/embra/embra.h into capi_generated.js by scripts/gen_bindings.py (run it after changing
// the header; the test bindings.fresh fails while a generated file is stale). This module finds
// libembra and declares every prototype.
//
// Conventions of the generated declarations (koffi 3):
// - a world is an opaque `embra_world *`, a BigInt to JS; World (world.js) never lets a caller pass one;
// - bulk inputs and outputs are plain `double *` / `int32_t *` / `char *` parameters, given a
//   Float64Array / Int32Array / Buffer, whose memory C reads or writes during the call, no copy;
//   a buffer of ids (`embra_body_id *out`) is a Uint32Array of 2 * capacity values;
// - small outputs (ids, counts, reports, defs: a non-const pointer not followed by a capacity) are
//   `_Out_` pointers filled into a JS object or a one-element array;
// - fixed arrays inside structs (gravity[3], rotation[4], ...) decode as plain JS arrays.

const fs = require('fs');
const nodePath = require('path');
const generated = require('./capi_generated');

// ABI_VERSION: the EMBRA_ABI_VERSION these bindings were generated for (the SONAME's number).
const { koffi, PROTOTYPES, ABI_VERSION } = generated;
const LIBRARY_ENV = 'EMBRA_LIBRARY';

// --- loading --------------------------------------------------------------------------------------
function defaultLibraryName() {
  if (process.platform === 'darwin') return `libembra.${ABI_VERSION}.dylib`;
  if (process.platform === 'win32') return 'embra.dll';
  return `libembra.so.${ABI_VERSION}`; // by SONAME, through the dynamic loader's search
}

// Beside the package (a copy of embra.dll or libembra carried with it), else the name for the
// system's search (on Windows: the program's folder, the system folders, PATH).
function defaultLibraryPath() {
  const name = defaultLibraryName();
  for (const folder of [nodePath.join(__dirname, '..'), __dirname]) {
    const candidate = nodePath.join(folder, name);
    if (fs.existsSync(candidate)) return candidate;
  }
  return name;
}

function load() {
  const env = process.env[LIBRARY_ENV];
  const path = env ? env : defaultLibraryPath();
  let handle;
  try {
    handle = koffi.load(path);
  } catch (e) {
    throw new Error(`embra: cannot load libembra from '${path}' (set ${LIBRARY_ENV} to its path): ${e.message}`);
  }
  const lib = {};
  for (const [name, prototype] of Object.entries(PROTOTYPES)) {
    try {
      lib[name] = handle.func(prototype.replace(/\s+/g, ' '));
    } catch (e) {
      // a missing symbol: a library older than these bindings
      throw new Error(`embra: ${path} has no usable ${name} (${e.message})`);
    }
  }
  return { lib: Object.freeze(lib), libraryPath: path };
}

const { lib, libraryPath } = load();

module.exports = {
  ...generated,
  lib, libraryPath, LIBRARY_ENV, ABI_VERSION,
};
