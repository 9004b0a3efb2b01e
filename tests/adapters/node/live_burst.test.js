'use strict';
// The live server's burst test (issue 17): the embra-live command as a child process on
// 127.0.0.1, 2,000 messages over 30 s from 20 connections - malformed JSON, oversized and binary
// messages, unknown types, NaN, 1e308 and out-of-workspace values, and valid drags, saves and
// exports - four of the pages not reading what they are sent. Every bad message is answered with
// one error (an oversized one closes its socket: 1009), the world keeps stepping with finite
// positions, and the server's peak resident memory (VmHWM) stays within its resident memory after
// warm-up + RSS_GROWTH_MB (docs/live-protocol.md states the same figure).

const assert = require('node:assert/strict');
const { spawn } = require('node:child_process');
const fs = require('node:fs');
const path = require('node:path');
const { test } = require('node:test');
const { sourceDir, packageDir, tempDir } = require('./helpers');

const WebSocket = require(path.join(packageDir, 'node_modules', 'ws'));
const { DEFAULTS } = require(path.join(packageDir, 'live', 'server'));
const { Session } = require(path.join(packageDir, 'live', 'session'));

const CONNECTIONS = 20;
const MESSAGES = 2000;
const SECONDS = 30;
const NOT_READING = 4; // of the connections: they read nothing until the burst is over
const KEEP_FILES = 5;
const RSS_GROWTH_MB = 64;
const scene = path.join(sourceDir, 'examples', 'poq_drape.json');

/** A small deterministic PRNG (mulberry32), so that every run sends the same messages. */
function random(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

function status(pid) {
  const text = fs.readFileSync(`/proc/${pid}/status`, 'utf8');
  const kb = (key) => Number(new RegExp(`^${key}:\\s+(\\d+) kB`, 'm').exec(text)[1]);
  return { rss: kb('VmRSS') / 1024, hwm: kb('VmHWM') / 1024 };
}

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, Math.max(0, ms)));

/** Starts `embra-live` and resolves to {child, port, stderr: lines} once it prints its address. */
function startChild(saveDir, web) {
  const child = spawn(process.execPath, [path.join(packageDir, 'live', 'embra-live.js'), scene, '--port', '0',
                                         '--save-dir', saveDir, '--web', web, '--keep-files', String(KEEP_FILES)],
                      { env: process.env, stdio: ['ignore', 'pipe', 'pipe'] });
  const stderr = [];
  let partial = '';
  child.stderr.on('data', (d) => {
    const lines = (partial + d).split('\n');
    partial = lines.pop();
    stderr.push(...lines);
  });
  return new Promise((resolve, reject) => {
    let out = '';
    child.stdout.on('data', (d) => {
      out += d;
      const m = /at http:\/\/127\.0\.0\.1:(\d+)\//.exec(out);
      if (m) resolve({ child, port: Number(m[1]), stderr });
    });
    child.on('exit', (code) => reject(new Error(`embra-live exited (${code}): ${stderr.join('\n')}`)));
  });
}

/**
 * A page: `sent` the bad messages it sent, `errors` the error messages it received, `frames` the
 * geometry messages' frame numbers, `finite` whether every position streamed to it was finite.
 */
function connect(port, { reading = true } = {}) {
  return new Promise((resolve, reject) => {
    const ws = new WebSocket(`ws://127.0.0.1:${port}/live`, { origin: `http://127.0.0.1:${port}` });
    const p = { ws, sent: [], errors: [], replies: [], closed: null, positions: null, frames: [], finite: true };
    ws.on('message', (data, isBinary) => {
      if (isBinary) {
        const n = data.readUInt32LE(12);
        const f = new Float32Array(data.buffer.slice(data.byteOffset + 24, data.byteOffset + 24 + 12 * n));
        p.positions = f;
        p.finite = p.finite && f.every(Number.isFinite);
        p.frames.push(data.readUInt32LE(8));
        return;
      }
      const m = JSON.parse(data.toString());
      if (m.type === 'error') p.errors.push(m.message.slice(0, 80));
      if (m.type === 'saved' || m.type === 'exported') p.replies.push(m);
    });
    ws.on('close', (code) => { p.closed = code; });
    ws.on('open', () => {
      if (!reading) ws.pause();
      resolve(p);
    });
    ws.on('error', reject);
  });
}

async function until(condition, what, timeoutMs = 20000) {
  const t0 = performance.now();
  while (!condition()) {
    if (performance.now() - t0 > timeoutMs) throw new Error(`no ${what} within ${timeoutMs} ms`);
    await sleep(20);
  }
}

/**
 * One connection's 100 messages: [{kind: 'bad' | 'good' | 'oversized', data}], 'bad' answered with
 * exactly one error, 'good' with none, 'oversized' closing the socket. A drag (start, moves, end)
 * is whole, and an oversized message never falls inside one.
 */
function script(seed, count, workspace, positions) {
  const r = random(seed);
  const pick = (list) => list[Math.floor(r() * list.length)];
  const big = DEFAULTS.maxMessageBytes;
  const out = [];
  const bad = (data) => out.push({ kind: 'bad', data });
  const near = (p) => [0, 1, 2].map((k) => positions[3 * p + k] + (r() - 0.5) * 0.4);
  while (out.length < count) {
    const x = r();
    if (x < 0.15) {
      bad(pick(['{"type": "drag"', 'not json', '{"type": "drag", "target": [NaN, 0, 0]}', '\u0000\u00ff', '',
                '{"type": "pause", "paused": tru}', '{"type": "drag_start", "particle": 3, "target": [0, 0, 0]]',
                Array.from({ length: 1 + Math.floor(r() * 300) }, () => String.fromCharCode(32 + Math.floor(r() * 95))).join('')]));
    } else if (x < 0.18) {
      const size = pick([big + 1, 256 * 1024, 1024 * 1024, 4 * 1024 * 1024]);
      out.push({ kind: 'oversized', data: r() < 0.5 ? '{"type": "drag", "pad": "'.padEnd(size, 'x') : Buffer.alloc(size, 7) });
    } else if (x < 0.20) {
      bad(Buffer.from(Array.from({ length: 1 + Math.floor(r() * 64) }, () => Math.floor(r() * 256))));
    } else if (x < 0.30) {
      bad(pick(['{"type": "fly"}', '{"type": 42}', '{"type": null}', '{}', '[]', 'null', '42', '"drag"', '{"type": "__proto__"}',
                '{"type": "constructor"}', '{"type": "toString"}', '{"__proto__": {"type": "save"}}', '{"type": ["save"]}']));
    } else if (x < 0.52) {
      bad(pick([
        JSON.stringify({ type: 'drag_start', particle: 3, target: [0, 0, 1e308] }),
        JSON.stringify({ type: 'drag_start', particle: 3, target: [-1e308, 0, 0] }),
        JSON.stringify({ type: 'drag_start', particle: 3, target: [0, 0, 1e200] }),
        JSON.stringify({ type: 'drag_start', particle: 3, target: [0, workspace.max[1] + 1, 0] }),
        JSON.stringify({ type: 'collider_pose', index: 0, position: [workspace.min[0] - 1, 0, 0] }),
        '{"type": "drag_start", "particle": 3, "target": [0, 0, 1e999]}',
        '{"type": "drag_start", "particle": 3, "target": [NaN, 0, 0]}',
        JSON.stringify({ type: 'drag_start', particle: 1e308, target: [0, 0, 0] }),
        JSON.stringify({ type: 'drag', target: [0, 0, 1e308] }), // with no drag_start, or out of range: refused either way
        JSON.stringify({ type: 'collider_pose', index: 0, position: [1e308, 0, 0] }),
        JSON.stringify({ type: 'collider_pose', index: 0, position: [0, 0, 0], rotation: [1e308, 0, 0, 0] }),
        JSON.stringify({ type: 'collider_pose', index: 1e308, position: [0, 0, 0] }),
        JSON.stringify({ type: 'group_weight', index: 0, weight: 1e308 }),
        JSON.stringify({ type: 'group_weight', index: 0, weight: -1e308 }),
        JSON.stringify({ type: 'rest_scale', body: 0, scale: 1e308 }),
        JSON.stringify({ type: 'rest_scale', body: 0, scale: 1, scale_u: -1e308 }),
        '{"type": "rest_scale", "body": 0, "scale": -1e999}',
      ]));
    } else if (x < 0.98) {
      const particle = Math.floor(r() * (positions.length / 3));
      const moves = 2 + Math.floor(r() * 6);
      if (out.length + moves + 2 > count) continue;
      out.push({ kind: 'good', data: JSON.stringify({ type: 'drag_start', particle, target: near(particle) }) });
      for (let k = 0; k < moves; ++k) out.push({ kind: 'good', data: JSON.stringify({ type: 'drag', target: near(particle) }) });
      out.push({ kind: 'good', data: JSON.stringify({ type: 'drag_end' }) });
    } else {
      out.push({ kind: 'good', data: JSON.stringify(pick([{ type: 'save' }, { type: 'export', format: '3dm' },
                                                          { type: 'export', format: 'gltf', metric: 'miter' }])) });
    }
  }
  return out.slice(0, count);
}

test(`${MESSAGES} messages over ${SECONDS} s from ${CONNECTIONS} connections: still stepping, memory bounded`, { timeout: 180000 }, async () => {
  const saveDir = tempDir('live-burst-out');
  const web = tempDir('live-burst-web');
  fs.writeFileSync(path.join(web, 'index.html'), '<!doctype html><title>page</title>');
  const session = new Session(scene); // the server's own view of the scene, for its workspace
  session.close();
  const { child, port, stderr } = await startChild(saveDir, web);
  const pid = child.pid;
  const samples = [];
  let sampler = null;
  try {
    // Warm-up: an observing page, a save and both exports (rhino3dm loaded), two seconds of frames.
    const observer = await connect(port);
    for (const msg of [{ type: 'save' }, { type: 'export', format: '3dm' }, { type: 'export', format: 'gltf' }])
      observer.ws.send(JSON.stringify(msg));
    await until(() => observer.replies.length === 3, 'the warm-up replies');
    await sleep(2000);
    await until(() => observer.positions, 'a frame');
    const positions = Float64Array.from(observer.positions);
    const { workspace } = session;
    const baseline = status(pid);
    const frameBefore = observer.frames[observer.frames.length - 1];

    // The burst: connection c sends its message k at (k + jitter) * 30 s / 100.
    const perConnection = MESSAGES / CONNECTIONS;
    const interval = (SECONDS * 1000) / perConnection;
    const t0 = performance.now();
    sampler = setInterval(() => {
      try {
        samples.push(status(pid).rss);
      } catch {
        // the server is gone: the checks below say so
      }
    }, 250);
    let sent = 0;
    let oversized = 0;
    const run = async (c) => {
      const reading = c >= NOT_READING;
      const messages = script(1000 + c, perConnection, workspace, positions);
      let p = await connect(port, { reading });
      let bad = 0;
      const done = [];
      const r = random(c);
      for (let k = 0; k < messages.length; ++k) {
        await sleep(t0 + (k + r()) * interval - performance.now());
        const m = messages[k];
        p.ws.send(m.data);
        sent += 1;
        if (m.kind === 'bad') {
          bad += 1;
          p.sent.push(typeof m.data === 'string' ? m.data.slice(0, 80) : `${m.data.length} binary bytes`);
        }
        if (m.kind === 'oversized') {
          oversized += 1;
          if (!reading) p.ws.resume();
          await until(() => p.closed !== null, 'the close of an oversized message');
          assert.equal(p.closed, 1009);
          done.push({ p, bad });
          bad = 0;
          p = await connect(port, { reading });
        }
      }
      if (!reading) p.ws.resume();
      done.push({ p, bad });
      return done;
    };
    const pages = (await Promise.all(Array.from({ length: CONNECTIONS }, (_, c) => run(c)))).flat();
    const seconds = (performance.now() - t0) / 1000;
    assert.equal(sent, MESSAGES);
    assert.ok(seconds >= SECONDS - 1 && seconds < SECONDS + 10, `the burst took ${seconds} s`);

    // Every bad message was answered with one error.
    for (const { p, bad } of pages) {
      await until(() => p.errors.length === bad,
                  `${bad} errors (${p.errors.length} so far) for ${JSON.stringify(p.sent)}: ${JSON.stringify(p.errors)}`);
    }
    for (const { p } of pages) p.ws.close();

    // The world still steps: frames keep coming, numbered on, every position finite.
    const last = observer.frames.length;
    await until(() => observer.frames.length >= last + 60, '60 more frames');
    const numbers = observer.frames;
    for (let k = 1; k < numbers.length; ++k) assert.ok(numbers[k] > numbers[k - 1], `frame ${numbers[k]} after ${numbers[k - 1]}`);
    assert.ok(numbers[numbers.length - 1] > frameBefore + 60);
    assert.ok(observer.finite, 'a frame held a non-finite position');
    clearInterval(sampler);
    sampler = null;

    const end = status(pid);
    const peak = Math.max(end.hwm, ...samples);
    console.log(`# burst: ${seconds.toFixed(1)} s, ${oversized} oversized; VmRSS ${baseline.rss.toFixed(1)} MB after warm-up ` +
                `(VmHWM ${baseline.hwm.toFixed(1)}), peak ${peak.toFixed(1)} MB, ${end.rss.toFixed(1)} MB at the end`);
    assert.ok(peak <= baseline.rss + RSS_GROWTH_MB,
              `the server's peak resident memory ${peak.toFixed(1)} MB > ${baseline.rss.toFixed(1)} + ${RSS_GROWTH_MB} MB`);

    // Nothing went wrong inside it, and the output folder holds at most KEEP_FILES files.
    assert.deepEqual(stderr.filter((l) => /internal error|step failed|non-finite/.test(l)), []);
    assert.ok(fs.readdirSync(saveDir).length <= KEEP_FILES, fs.readdirSync(saveDir).join(' '));
    observer.ws.close();
  } finally {
    if (sampler) clearInterval(sampler);
    child.kill('SIGTERM');
    await new Promise((resolve) => (child.exitCode !== null ? resolve() : child.once('exit', resolve)));
  }
  assert.equal(child.exitCode, 0);
});

test('docs/live-protocol.md states the burst test\'s memory bound', () => {
  const doc = fs.readFileSync(path.join(sourceDir, 'docs', 'live-protocol.md'), 'utf8');
  assert.match(doc, new RegExp(`\\+ ${RSS_GROWTH_MB} MB`));
});
