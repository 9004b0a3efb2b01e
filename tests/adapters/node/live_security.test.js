'use strict';
// embra-live as a page of another site, or a local program gone wrong, would drive it
// (docs/live-protocol.md, "Security"): a foreign Host (DNS rebinding) or Origin refused before
// anything is served, paths outside the page folder and the output folder refused, every bound
// (message size, rate, connections, files kept) holding at its stated figure, and every numeric
// field checked, with nothing changed by a refusal.

const assert = require('node:assert/strict');
const fs = require('node:fs');
const http = require('node:http');
const net = require('node:net');
const path = require('node:path');
const { test, before, after } = require('node:test');
const { sourceDir, packageDir, tempDir } = require('./helpers');

const { startServer, checkOrigin, DEFAULTS } = require(path.join(packageDir, 'live', 'server'));
const { Session, WORKSPACE_REACH } = require(path.join(packageDir, 'live', 'session'));
const WebSocket = require(path.join(packageDir, 'node_modules', 'ws'));

const scene = path.join(sourceDir, 'examples', 'poq_drape.json');
// Small bounds, so that each is reached quickly (the defaults are checked against the docs below).
const LIMITS = { maxConnections: 4, messagesPerSecond: 20, messageBurst: 40, heavyMessageCost: 20, keepFiles: 5,
                 maxMessageBytes: 4096 };
const SECRET = 'secret-outside-the-page-folder';
let live;
let site;
let out;
const logs = [];

before(async () => {
  site = tempDir('live-site');
  fs.mkdirSync(path.join(site, 'page'));
  fs.writeFileSync(path.join(site, 'page', 'index.html'), '<!doctype html><title>page</title>');
  fs.writeFileSync(path.join(site, 'secret.txt'), SECRET);
  out = path.join(tempDir('live-out'), 'out');
  live = await startServer({ scene, port: 0, web: path.join(site, 'page'), saveDir: out, log: (l) => logs.push(l),
                             ...LIMITS });
});

after(() => live.close());

/** An http GET with the given Host header (null: none sent, HTTP/1.0; '': empty) and path, sent as is. */
function get(urlPath, host = `127.0.0.1:${live.port}`) {
  if (host === null || host === '') {
    const head = host === null ? `GET ${urlPath} HTTP/1.0\r\n\r\n` : `GET ${urlPath} HTTP/1.1\r\nHost: \r\nConnection: close\r\n\r\n`;
    return new Promise((resolve, reject) => {
      const socket = net.connect(live.port, '127.0.0.1', () => socket.write(head));
      let text = '';
      socket.on('data', (d) => { text += d; });
      socket.on('end', () => resolve({ status: Number(text.split(' ')[1]), body: text.slice(text.indexOf('\r\n\r\n') + 4) }));
      socket.on('error', reject);
    });
  }
  return new Promise((resolve, reject) => {
    const req = http.request({ host: '127.0.0.1', port: live.port, path: urlPath, headers: { host } }, (res) => {
      let body = '';
      res.on('data', (d) => { body += d; });
      res.on('end', () => resolve({ status: res.statusCode, body }));
    });
    req.on('error', reject);
    req.end();
  });
}

/**
 * A WebSocket to /live with the given Origin (undefined: none) and Host. Resolves to {status: 101,
 * ws, inbox, next(match)} when upgraded, {status, body} when refused.
 */
function connect({ origin, host, server = live } = {}) {
  return new Promise((resolve, reject) => {
    const headers = host ? { host } : {};
    const ws = new WebSocket(`ws://127.0.0.1:${server.port}/live`, { origin, headers });
    const p = { status: 101, ws, inbox: [], waiters: [] };
    ws.on('unexpected-response', (req, res) => {
      let body = '';
      res.on('data', (d) => { body += d; });
      res.on('end', () => resolve({ status: res.statusCode, body }));
    });
    const deliver = (m) => {
      p.inbox.push(m);
      p.waiters = p.waiters.filter((w) => !(w.match(m) && (w.resolve(m), true)));
    };
    ws.on('message', (data, isBinary) => deliver(isBinary ? { type: 'geometry', frame: data.readUInt32LE(8) } : JSON.parse(data.toString())));
    ws.on('close', (code) => deliver({ type: 'closed', code }));
    ws.on('open', () => resolve(p));
    ws.on('error', (e) => { if (ws.readyState === ws.CONNECTING && !e.message.includes('Unexpected server response')) reject(e); });
  });
}

/** The first message received (or to come) that matches, taken out of the page's inbox. */
function next(p, match, what, timeoutMs = 10000) {
  const take = (m) => {
    p.inbox.splice(p.inbox.indexOf(m), 1);
    return m;
  };
  const seen = p.inbox.find(match);
  if (seen) return Promise.resolve(take(seen));
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`no ${what} within ${timeoutMs} ms`)), timeoutMs);
    p.waiters.push({ match, resolve: (m) => { clearTimeout(timer); resolve(take(m)); } });
  });
}

/** Until the server has seen every earlier socket close. */
async function noConnections() {
  for (let k = 0; live.connections() > 0; ++k) {
    assert.ok(k < 100, `${live.connections()} sockets still open`);
    await new Promise((resolve) => setTimeout(resolve, 20));
  }
}

const ofType = (type) => (m) => m.type === type;
const closeAll = (...pages) => Promise.all(pages.map((p) => new Promise((resolve) => {
  if (p.ws.readyState === p.ws.CLOSED) resolve();
  else {
    p.ws.once('close', resolve);
    p.ws.close();
  }
})));

test('http answers only to the server\'s own names: a rebound name, another port or no Host is refused', async () => {
  const P = live.port;
  for (const host of [`127.0.0.1:${P}`, `localhost:${P}`, `LOCALHOST:${P}`, `[::1]:${P}`]) {
    const r = await get('/', host);
    assert.equal(r.status, 200, host);
    assert.match(r.body, /<title>page<\/title>/);
  }
  for (const host of [`evil.example:${P}`, 'evil.example', `127.0.0.1:${P + 1}`, '127.0.0.1', `127.0.0.1.evil.example:${P}`,
                      `localhost:${P}.evil.example`]) {
    const r = await get('/', host);
    assert.equal(r.status, 403, `Host ${JSON.stringify(host)}`);
    assert.doesNotMatch(r.body, /<title>/);
  }
  for (const host of ['', null]) {
    const r = await get('/', host);
    assert.ok(r.status === 400 || r.status === 403, `Host ${JSON.stringify(host)}: ${r.status}`);
    assert.doesNotMatch(r.body, /<title>/);
  }
});

test('the page folder serves nothing outside it, however the path is spelled', async () => {
  const tries = ['/../secret.txt', '/%2e%2e/secret.txt', '/%2E%2E/secret.txt', '/..%2fsecret.txt', '/%2e%2e%2fsecret.txt',
                 '/page/../../secret.txt', '/./../secret.txt', '/%2e%2e%5csecret.txt', '/..%5c..%5csecret.txt',
                 '/%252e%252e/secret.txt', '/index.html%00.txt', '/%00', '/%', '//../secret.txt'];
  for (const p of tries) {
    const r = await get(p);
    assert.ok([400, 403, 404].includes(r.status), `${p}: ${r.status}`);
    assert.ok(!r.body.includes(SECRET), `${p} served the file outside the page folder`);
  }
  assert.equal((await get('/index.html')).status, 200);
  // The server is still up after all of them.
  assert.equal((await get('/')).status, 200);
});

test('a WebSocket from another origin, or through a rebound name, is refused with 403 before the upgrade', async () => {
  const P = live.port;
  const refused = [
    { origin: 'http://evil.example' },
    { origin: `http://evil.example:${P}` },
    { origin: 'null' },
    { origin: `https://127.0.0.1:${P}` },
    { origin: `http://127.0.0.1:${P + 1}` },
    { origin: `http://127.0.0.1:${P}.evil.example` },
    { origin: `http://evil.example:${P}`, host: `evil.example:${P}` }, // DNS rebinding: the attacker's own name
    { host: `evil.example:${P}` },
  ];
  for (const r of refused) {
    const p = await connect(r);
    assert.equal(p.status, 403, JSON.stringify(r));
    assert.equal(p.ws, undefined);
  }
  assert.equal(logs.filter((l) => l.startsWith('refused a WebSocket')).length, refused.length);
  // The server's own origins, and a program that sends no Origin (no browser does that), connect.
  for (const origin of [`http://127.0.0.1:${P}`, `http://localhost:${P}`, `http://[::1]:${P}`, undefined]) {
    const p = await connect({ origin });
    assert.equal(p.status, 101, String(origin));
    assert.equal((await next(p, ofType('scene'), 'the scene')).name, 'poq_drape');
    await closeAll(p);
  }
  // Other paths are not the socket.
  const wrongPath = await new Promise((resolve) => {
    const ws = new WebSocket(`ws://127.0.0.1:${P}/elsewhere`);
    ws.on('unexpected-response', (req, res) => resolve(res.statusCode));
    ws.on('error', () => {});
  });
  assert.equal(wrongPath, 404);
});

test('extra origins only by the allowOrigins option (--allow-origin): exact origins, their host accepted too', async () => {
  const other = await startServer({ scene, port: 0, web: path.join(site, 'page'), saveDir: out, log: () => {},
                                    allowOrigins: ['http://192.168.1.5:8710'] });
  try {
    const ok = await connect({ server: other, origin: 'http://192.168.1.5:8710', host: '192.168.1.5:8710' });
    assert.equal(ok.status, 101);
    await closeAll(ok);
    const no = await connect({ server: other, origin: 'http://192.168.1.5:8711' });
    assert.equal(no.status, 403);
  } finally {
    await other.close();
  }
  for (const bad of ['http://192.168.1.5:8710/', 'http://192.168.1.5:8710/page', 'ftp://x', 'null', '*', 'evil.example'])
    assert.throws(() => checkOrigin(bad), RangeError, bad);
  assert.equal(checkOrigin('http://192.168.1.5:8710'), 'http://192.168.1.5:8710');
});

test('at most maxConnections sockets at once: one more is refused with 503, and room comes back', async () => {
  await noConnections();
  const pages = [];
  for (let k = 0; k < LIMITS.maxConnections; ++k) pages.push(await connect());
  assert.ok(pages.every((p) => p.status === 101));
  const extra = await connect();
  assert.equal(extra.status, 503);
  await closeAll(pages.pop());
  while (live.connections() >= LIMITS.maxConnections) await new Promise((resolve) => setTimeout(resolve, 20));
  const again = await connect();
  assert.equal(again.status, 101);
  await closeAll(again, ...pages);
});

test('a message over maxMessageBytes closes that socket (1009); others keep streaming', async () => {
  const a = await connect();
  const b = await connect();
  // Just under the bound: read, and refused for what it says.
  a.ws.send(JSON.stringify({ type: 'fly', pad: 'x'.repeat(LIMITS.maxMessageBytes - 40) }));
  assert.match((await next(a, ofType('error'), 'a refusal')).message, /unknown message type "fly"/);
  a.ws.send('x'.repeat(LIMITS.maxMessageBytes + 1));
  assert.equal((await next(a, ofType('closed'), 'the close')).code, 1009);
  b.ws.send(JSON.stringify({ type: 'pause', paused: false }));
  const f = (await next(b, ofType('geometry'), 'a frame')).frame;
  await next(b, (m) => m.type === 'geometry' && m.frame > f, 'a later frame');
  await closeAll(b);
});

test('messages over the rate are dropped unread, counted in one error a second; heavy ones cost more', async () => {
  const p = await connect();
  const N = 100;
  const t0 = performance.now();
  for (let k = 0; k < N; ++k) p.ws.send('{"type": "fly"}');
  // Every message is accounted for: refused for its type when read, or counted as dropped.
  let refused = 0;
  let dropped = 0;
  let reports = 0;
  while (refused + dropped < N) {
    const e = await next(p, ofType('error'), `the refusals (${refused} refused, ${dropped} dropped so far)`, 5000);
    if (e.dropped) {
      dropped += e.dropped;
      reports += 1;
      assert.match(e.message, /too many messages/);
    } else {
      assert.match(e.message, /unknown message type/);
      refused += 1;
    }
  }
  const seconds = (performance.now() - t0) / 1000;
  assert.equal(refused + dropped, N);
  assert.ok(refused >= LIMITS.messageBurst && refused <= LIMITS.messageBurst + LIMITS.messagesPerSecond * seconds + 1,
            `${refused} read in ${seconds} s`);
  assert.ok(reports >= 1 && reports <= 2, `${reports} reports`);
  // A full bucket holds messageBurst / heavyMessageCost saves: the next one is dropped.
  await new Promise((resolve) => setTimeout(resolve, 1000 * LIMITS.messageBurst / LIMITS.messagesPerSecond + 100));
  const saves = LIMITS.messageBurst / LIMITS.heavyMessageCost;
  for (let k = 0; k <= saves; ++k) p.ws.send('{"type": "save"}');
  for (let k = 0; k < saves; ++k) await next(p, ofType('saved'), `save ${k}`);
  assert.equal((await next(p, (m) => m.type === 'error' && m.dropped, 'the dropped save')).dropped, 1);
  await closeAll(p);
});

test('a scene\'s name never reaches a file name: saves and exports stay in the output folder', async () => {
  const root = tempDir('live-name');
  const dir = path.join(root, 'a', 'b');
  fs.mkdirSync(dir, { recursive: true });
  const text = JSON.parse(fs.readFileSync(scene, 'utf8'));
  text.name = '../../escaped_by_name';
  const hostile = path.join(dir, 'poq copy;rm -rf.json');
  fs.writeFileSync(hostile, JSON.stringify(text));
  const saveDir = path.join(dir, 'out');
  const s = await startServer({ scene: hostile, port: 0, web: path.join(site, 'page'), saveDir, log: () => {} });
  try {
    const p = await connect({ server: s });
    assert.equal((await next(p, ofType('scene'), 'the scene')).name, '../../escaped_by_name'); // shown, not used
    const paths = [];
    p.ws.send(JSON.stringify({ type: 'save' }));
    paths.push((await next(p, ofType('saved'), 'saved')).path);
    for (const format of ['gltf', '3dm']) {
      p.ws.send(JSON.stringify({ type: 'export', format }));
      paths.push((await next(p, ofType('exported'), format, 30000)).path);
    }
    await closeAll(p);
    for (const f of paths) {
      assert.equal(path.dirname(f), saveDir, f);
      assert.match(path.basename(f), /^poq_copy_rm_-rf-\d{6}-f\d{5}\.(json|gltf|3dm)$/);
    }
    const all = (d) => fs.readdirSync(d, { withFileTypes: true })
      .flatMap((e) => (e.isDirectory() ? all(path.join(d, e.name)) : [path.join(d, e.name)]));
    assert.deepEqual(all(root).sort(), [hostile, ...paths].sort());
  } finally {
    await s.close();
  }
});

test('at most keepFiles of a scene\'s files are kept: the oldest go, other files stay, nothing is overwritten', () => {
  const dir = tempDir('live-keep');
  const others = ['notes.txt', 'other-000001-f00001.json', 'poq_drape-000001-f00001.json.bak', 'poq_drape.json'];
  for (const f of others) fs.writeFileSync(path.join(dir, f), 'not embra-live\'s');
  fs.mkdirSync(path.join(dir, 'poq_drape-000000-f00000.json')); // a folder with such a name is no file of it
  const keep = 3;
  const written = [];
  let s = new Session(scene, { saveDir: dir, keepFiles: keep });
  for (let k = 0; k < 5; ++k) written.push(s.writeOutput(['json', 'gltf', '3dm'][k % 3], `file ${k}`, k));
  s.close();
  // A new server in the same folder counts on from the files there.
  s = new Session(scene, { saveDir: dir, keepFiles: keep });
  for (let k = 5; k < 8; ++k) written.push(s.writeOutput('json', `file ${k}`, k));
  s.close();
  const names = written.map((f) => path.basename(f));
  assert.deepEqual(names.map((n) => Number(n.split('-')[1])), [1, 2, 3, 4, 5, 6, 7, 8]);
  const kept = s.outputFiles().map((f) => f.name);
  assert.deepEqual(kept, names.slice(-keep));
  for (const f of written.slice(-keep)) assert.equal(fs.readFileSync(f, 'utf8'), `file ${written.indexOf(f)}`);
  for (const f of others) assert.equal(fs.readFileSync(path.join(dir, f), 'utf8'), 'not embra-live\'s');
  assert.ok(fs.statSync(path.join(dir, 'poq_drape-000000-f00000.json')).isDirectory());
  assert.throws(() => new Session(scene, { saveDir: dir, keepFiles: 0 }), RangeError);
});

test('a save into a folder that cannot be written is refused with a reason; the server goes on', async () => {
  const blocked = path.join(tempDir('live-blocked'), 'file');
  fs.writeFileSync(blocked, 'a file where the output folder should be');
  const s = await startServer({ scene, port: 0, web: path.join(site, 'page'), saveDir: blocked, log: () => {} });
  try {
    const p = await connect({ server: s });
    p.ws.send(JSON.stringify({ type: 'save' }));
    assert.match((await next(p, ofType('error'), 'the refusal')).message, /output folder .*file/);
    p.ws.send(JSON.stringify({ type: 'pause', paused: false }));
    await next(p, (m) => m.type === 'geometry' && m.frame > 1, 'a frame after it');
    await closeAll(p);
  } finally {
    await s.close();
  }
});

test('every numeric field: non-finite, out of the C API\'s range or outside the workspace is refused, nothing changed', async () => {
  const p = await connect();
  p.ws.send(JSON.stringify({ type: 'pause', paused: true }));
  await next(p, (m) => m.type === 'status' && m.paused, 'paused');
  const w = live.session.world;
  const before = w.saveJson();
  const { min, max } = live.session.workspace;
  const outside = max[2] + 1;
  const raw = [
    '{"type": "drag_start", "particle": 3, "target": [NaN, 0, 0]}', '{"type": "drag_start", "particle": 3, "target": [0, 0, 1e999]}',
    '{"type": "collider_pose", "index": 0, "position": [0, 0, -Infinity]}',
  ];
  const bad = [
    { type: 'drag_start', particle: 3, target: [0, 0, 1e308] }, { type: 'drag_start', particle: 3, target: [0, 0, 1e200] },
    { type: 'drag_start', particle: 3, target: [0, 0, outside] }, { type: 'drag_start', particle: 3, target: [min[0] - 1, 0, 0] },
    { type: 'drag_start', particle: 1e308, target: [0, 0, 0] }, { type: 'drag_start', particle: '3', target: [0, 0, 0] },
    { type: 'drag_start', particle: 3, target: { 0: 0, 1: 0, 2: 0, length: 3 } },
    { type: 'collider_pose', index: 0, position: [1e308, 0, 0] }, { type: 'collider_pose', index: 0, position: [0, 0, outside] },
    { type: 'collider_pose', index: 0, position: [0, 0, 0], rotation: [1e308, 0, 0, 0] },
    { type: 'collider_pose', index: 0, position: [0, 0, 0], rotation: [2, 0, 0, 0] },
    { type: 'collider_pose', index: 1e308, position: [0, 0, 0] }, { type: 'collider_pose', index: -0.5, position: [0, 0, 0] },
    { type: 'group_weight', index: 0, weight: 1e308 }, { type: 'group_weight', index: 0, weight: 1001 },
    { type: 'group_weight', index: 0, weight: -1 }, { type: 'group_weight', index: 0, weight: 2 ** 31 },
    { type: 'group_weight', index: 2 ** 53, weight: 2 },
    { type: 'rest_scale', body: 0, scale: 1e308 }, { type: 'rest_scale', body: 0, scale: 1, scale_u: -1e308 },
    { type: 'rest_scale', body: 0, scale: 1, scale_v: '1' }, { type: 'rest_scale', body: 1e308, scale: 1 },
    { type: 'export', format: 'gltf', metric: 1e308 }, { type: 'pause', paused: 1e308 },
  ];
  for (const msg of [...raw, ...bad]) {
    p.ws.send(typeof msg === 'string' ? msg : JSON.stringify(msg));
    const e = await next(p, ofType('error'), `the refusal of ${JSON.stringify(msg)}`);
    assert.ok(e.message.length > 5);
    if (typeof msg === 'object' && msg.target && msg.target[2] === outside) assert.match(e.message, /workspace/);
    await new Promise((resolve) => setTimeout(resolve, 1000 / LIMITS.messagesPerSecond));
  }
  assert.equal(w.saveJson(), before);
  // The workspace's edge is in it.
  p.ws.send(JSON.stringify({ type: 'drag_start', particle: 3, target: [0, 0, max[2]] }));
  p.ws.send(JSON.stringify({ type: 'drag_end' }));
  p.ws.send(JSON.stringify({ type: 'step' }));
  await next(p, ofType('geometry'), 'a step after the refusals');
  assert.ok(!p.inbox.some(ofType('error')), JSON.stringify(p.inbox.filter(ofType('error'))));
  await closeAll(p);
});

test('the bounds stated in docs/live-protocol.md are the server\'s', () => {
  const doc = fs.readFileSync(path.join(sourceDir, 'docs', 'live-protocol.md'), 'utf8');
  for (const [key, value] of Object.entries(DEFAULTS)) {
    const row = doc.split('\n').find((l) => l.startsWith(`| \`${key}\` |`));
    assert.ok(row, `docs/live-protocol.md has no row for ${key}`);
    assert.equal(Number(row.split('|')[3].trim()), value, `${key} in docs/live-protocol.md`);
  }
  const reach = doc.split('\n').find((l) => l.startsWith('| workspace reach |'));
  assert.ok(reach, 'docs/live-protocol.md has no row for the workspace reach');
  assert.equal(Number(reach.split('|')[3].trim()), WORKSPACE_REACH);
});

test('a session steps on the scene\'s threads or the option\'s, to the same bits', () => {
  const dir = tempDir('live-threads');
  const own = new Session(scene, { saveDir: dir }); // poq_drape.json sets no solver.threads: 1
  const all = new Session(scene, { saveDir: dir, threads: 0 });
  assert.equal(own.world.solver.threads, 1);
  assert.equal(all.world.solver.threads, 0);
  const text = JSON.parse(fs.readFileSync(scene, 'utf8'));
  text.solver.threads = 2;
  const path2 = path.join(dir, 'poq_drape_two_threads.json');
  fs.writeFileSync(path2, JSON.stringify(text));
  const two = new Session(path2, { saveDir: dir });
  assert.equal(two.world.solver.threads, 2); // the scene's own setting
  for (let f = 0; f < 40; ++f) for (const s of [own, all, two]) assert.equal(s.step(), null);
  const bytes = (s) => Buffer.from(s.world.positions().buffer);
  assert.ok(bytes(all).equals(bytes(own)));
  assert.ok(bytes(two).equals(bytes(own)));
  for (const s of [own, all, two]) s.close();
  assert.throws(() => new Session(scene, { saveDir: dir, threads: -1 }), RangeError);
  assert.throws(() => new Session(scene, { saveDir: dir, threads: 1.5 }), RangeError);
});
