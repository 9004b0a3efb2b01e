'use strict';
// The ctest entries of the Node adapter tests: checks that the adapter's npm packages are installed,
// then runs *.test.js here with `node --test`: `run.js live` the live server's (live*.test.js,
// ctest adapters.node.live), `run.js` the rest (adapters.node).

const { spawnSync } = require('node:child_process');
const fs = require('node:fs');
const path = require('node:path');

const source = process.env.EMBRA_SOURCE_DIR;
if (!source) {
  console.error('adapters.node: EMBRA_SOURCE_DIR is not set (run through ctest)');
  process.exit(1);
}
const modules = path.join(source, 'host_adapters', 'node', 'node_modules');
if (!fs.existsSync(path.join(modules, 'koffi', 'package.json'))) {
  console.error(`adapters.node: ${modules} has no koffi: the Node adapter's packages are not installed.\n` +
    `  Install them with: (cd ${path.dirname(modules)} && npm ci)   (scripts/deps.sh does)`);
  process.exit(1);
}
const live = process.argv[2] === 'live';
const tests = fs.readdirSync(__dirname).filter((f) => f.endsWith('.test.js'))
  .filter((f) => f.startsWith('live') === live).sort()
  .map((f) => path.join(__dirname, f));
if (tests.length === 0) {
  console.error(`adapters.node: no *.test.js in ${__dirname}`);
  process.exit(1);
}
const run = spawnSync(process.execPath, ['--test', ...tests], { stdio: 'inherit' });
process.exit(run.status === null ? 1 : run.status);
