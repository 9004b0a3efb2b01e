#!/usr/bin/env node
'use strict';
// embra-live SCENE.json [--port P] [--host H] [--save-dir DIR] [--web DIR] [--allow-origin ORIGIN]...
//                       [--max-connections N] [--keep-files N] [--threads T]
//
// Loads a scene, steps it in real time and serves the page at http://H:P/ (loopback by default):
// drag the mesh, move colliders, toggle gravity and pins, change group weights and rest scales,
// save a design alternative as scene JSON, export glTF or Rhino .3dm. The protocol and the security
// model are docs/live-protocol.md. Exit codes: 0 stopped by a signal, 1 usage, 2 the scene or a
// file is invalid.

const fs = require('fs');
const path = require('path');
const { startServer, checkOrigin, DEFAULTS } = require('./server');

const USAGE = 'usage: embra-live SCENE.json [--port P] [--host 127.0.0.1] [--save-dir DIR] [--web DIR]\n' +
  '                  [--allow-origin ORIGIN]... [--max-connections N] [--keep-files N] [--threads T]\n' +
  `  --save-dir DIR         the output folder of save and export (default: the current folder)\n` +
  `  --keep-files N         files of this scene kept there, the oldest deleted beyond (default ${DEFAULTS.keepFiles})\n` +
  `  --allow-origin ORIGIN  another origin whose pages may connect, e.g. http://192.168.1.5:8710 (repeatable)\n` +
  `  --max-connections N    WebSocket connections at once (default ${DEFAULTS.maxConnections})\n` +
  `  --threads T            solver threads, 0 = one per core (default: the scene's solver.threads)\n`;

function usage(message) {
  if (message) process.stderr.write(`embra-live: ${message}\n`);
  process.stderr.write(USAGE);
  process.exit(1);
}

function parse(argv) {
  const o = { port: 8710, host: '127.0.0.1', saveDir: '.', web: undefined, scene: undefined, allowOrigins: [] };
  const count = (what, text) => {
    const n = Number(text);
    if (!Number.isInteger(n) || n < 1) usage(`${what} must be an integer >= 1`);
    return n;
  };
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    const value = () => {
      if (i + 1 >= argv.length) usage(`${a} needs a value`);
      return argv[++i];
    };
    if (a === '--port') {
      o.port = Number(value());
      if (!Number.isInteger(o.port) || o.port < 0 || o.port > 65535) usage('--port must be 0..65535');
    } else if (a === '--host') o.host = value();
    else if (a === '--save-dir') o.saveDir = value();
    else if (a === '--web') o.web = value();
    else if (a === '--allow-origin') {
      try {
        o.allowOrigins.push(checkOrigin(value()));
      } catch (e) {
        usage(e.message);
      }
    }
    else if (a === '--max-connections') o.maxConnections = count(a, value());
    else if (a === '--keep-files') o.keepFiles = count(a, value());
    else if (a === '--threads') {
      o.threads = Number(value());
      if (!Number.isInteger(o.threads) || o.threads < 0) usage('--threads must be an integer >= 0');
    }
    else if (a === '-h' || a === '--help') usage();
    else if (a.startsWith('-')) usage(`unknown option ${a}`);
    else if (o.scene === undefined) o.scene = a;
    else usage('one scene at a time');
  }
  if (o.scene === undefined) usage('no scene given');
  return o;
}

async function main() {
  const o = parse(process.argv.slice(2));
  const web = o.web || path.join(__dirname, '..', '..', 'web', 'dist');
  if (!fs.existsSync(path.join(web, 'index.html')))
    process.stderr.write(`embra-live: no page at ${web} (build it: cd host_adapters/web && npm run build); serving the socket only\n`);
  let live;
  try {
    live = await startServer({ ...o, web });
  } catch (e) {
    process.stderr.write(`embra-live: ${o.scene}: ${e.message}\n`);
    process.exit(2);
  }
  const s = live.session;
  const name = s.name.replace(/[\u0000-\u001f\u007f-\u009f]/g, '?'); // the scene's own text: no terminal controls
  process.stdout.write(`embra-live: ${name} (${s.particles} particles, dt ${s.dt.toFixed(4)} s) at ${live.url}\n`);
  const stop = () => live.close().then(() => process.exit(0));
  process.on('SIGINT', stop);
  process.on('SIGTERM', stop);
}

main();
