'use strict';
// embra-live's server: the page over http, the live scene over a WebSocket (docs/live-protocol.md).
// Steps the scene in real time (one frame per scene dt; as fast as it can when a frame takes
// longer, never queuing frames) and streams every stepped frame to every page that keeps up.

const fs = require('fs');
const http = require('http');
const path = require('path');
const { WebSocketServer } = require('ws');
const { Session, RefusedMessage } = require('./session');
const { EmbraError } = require('../lib');

const MAX_BUFFERED = 4 * 1024 * 1024; // a page further behind than this skips frames
const MAX_MESSAGE = 1024 * 1024; // a page's message is a few hundred bytes; anything this big is refused
const TYPES = { '.html': 'text/html; charset=utf-8', '.js': 'text/javascript; charset=utf-8',
                '.css': 'text/css; charset=utf-8', '.json': 'application/json', '.png': 'image/png',
                '.map': 'application/json', '.svg': 'image/svg+xml' };

/** Serves files under `root` (GET/HEAD only, no path outside it). */
function staticHandler(root) {
  const base = path.resolve(root);
  return (req, res) => {
    if (req.method !== 'GET' && req.method !== 'HEAD') {
      res.writeHead(405).end();
      return;
    }
    let rel;
    try {
      rel = decodeURIComponent(new URL(req.url, 'http://localhost').pathname);
    } catch {
      res.writeHead(400).end();
      return;
    }
    if (rel.endsWith('/')) rel += 'index.html';
    const file = path.resolve(base, `.${rel}`);
    if (!file.startsWith(base + path.sep)) {
      res.writeHead(403).end();
      return;
    }
    fs.readFile(file, (err, data) => {
      if (err) {
        res.writeHead(404, { 'content-type': 'text/plain' }).end(`not found: ${rel}\n`);
        return;
      }
      res.writeHead(200, { 'content-type': TYPES[path.extname(file)] || 'application/octet-stream',
                           'cache-control': 'no-store' });
      res.end(req.method === 'HEAD' ? undefined : data);
    });
  };
}

/**
 * Starts a live server. options: {scene (path), host ('127.0.0.1'), port (0 = any free one),
 * web (folder of the built page), saveDir, log (a function taking a line; default stderr)}.
 * Resolves to {url, port, session, close()}.
 */
function startServer(options) {
  const log = options.log || ((line) => process.stderr.write(`embra-live: ${line}\n`));
  const session = new Session(options.scene, { saveDir: options.saveDir });
  const web = options.web || path.join(__dirname, '..', '..', 'web', 'dist');
  const server = http.createServer(staticHandler(web));
  const wss = new WebSocketServer({ server, path: '/live', maxPayload: MAX_MESSAGE });
  const clients = new Set();
  let timer = null;
  let closed = false;
  let next = 0;

  const send = (ws, message) => {
    if (ws.readyState === ws.OPEN) ws.send(typeof message === 'string' ? message : JSON.stringify(message));
  };
  const broadcast = (message) => {
    const text = JSON.stringify(message);
    for (const ws of clients) send(ws, text);
  };
  const sendFrame = (ws, record, geometry) => {
    if (ws.readyState !== ws.OPEN || ws.bufferedAmount > MAX_BUFFERED) return;
    ws.send(record);
    ws.send(geometry, { binary: true });
  };
  const broadcastFrame = () => {
    if (clients.size === 0) return;
    const record = JSON.stringify(session.frameMessage());
    const geometry = Buffer.from(session.geometryMessage());
    for (const ws of clients) sendFrame(ws, record, geometry);
  };
  const stepAndSend = () => {
    const problem = session.step();
    if (problem) {
      log(problem.message);
      broadcast(problem);
      broadcast(session.statusMessage());
    }
    broadcastFrame();
  };

  // The clock: frame k is due at start + k dt. A frame that takes longer than dt delays the next
  // one instead of piling up; a long stall (a paused debugger, a slow machine) restarts the count.
  const tick = () => {
    timer = null;
    if (closed) return;
    const now = performance.now();
    if (!session.paused) {
      try {
        stepAndSend();
      } catch (e) {
        session.paused = true;
        log(`step failed: ${e.message} (paused)`);
        broadcast({ type: 'error', message: `step failed: ${e.message} (paused)` });
        broadcast(session.statusMessage());
      }
    }
    const dtMs = session.dt * 1000;
    next += dtMs;
    const after = performance.now();
    if (after - next > 250 || next < now - dtMs) next = after;
    timer = setTimeout(tick, Math.max(0, next - after));
  };

  wss.on('connection', (ws, req) => {
    clients.add(ws);
    log(`page connected from ${req.socket.remoteAddress}`);
    send(ws, session.sceneMessage());
    sendFrame(ws, JSON.stringify(session.frameMessage()), Buffer.from(session.geometryMessage()));
    ws.on('message', async (data, isBinary) => {
      let msg;
      try {
        if (isBinary) throw new RefusedMessage('binary messages are not part of the protocol');
        try {
          msg = JSON.parse(data.toString('utf8'));
        } catch {
          throw new RefusedMessage('not JSON');
        }
        const result = await session.handle(msg, ws);
        for (const r of result.replies || []) send(ws, r);
        if (result.broadcast) for (const other of clients) if (other !== ws) for (const r of result.replies || []) send(other, r);
        if (result.scene) {
          broadcast(session.sceneMessage());
          broadcastFrame();
        }
        if (result.stepped) stepAndSend();
      } catch (e) {
        if (!(e instanceof RefusedMessage) && !(e instanceof EmbraError) && !(e instanceof TypeError) &&
            !(e instanceof RangeError)) {
          log(`internal error on ${JSON.stringify(msg && msg.type)}: ${e.stack || e}`);
        }
        const text = String(data).slice(0, 200);
        log(`refused ${text}: ${e.message}`);
        send(ws, { type: 'error', message: e.message });
      }
    });
    ws.on('close', () => {
      clients.delete(ws);
      session.releaseDrag(ws); // a page that goes away lets go of what it held
    });
    ws.on('error', (e) => log(`socket error: ${e.message}`));
  });
  wss.on('error', (e) => log(`websocket server error: ${e.message}`));

  return new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(options.port ?? 0, options.host || '127.0.0.1', () => {
      const { port } = server.address();
      const host = options.host || '127.0.0.1';
      next = performance.now();
      timer = setTimeout(tick, 0);
      resolve({
        url: `http://${host.includes(':') ? `[${host}]` : host}:${port}/`,
        port,
        session,
        close: () => new Promise((done) => {
          closed = true;
          if (timer) clearTimeout(timer);
          for (const ws of clients) ws.terminate();
          wss.close(() => server.close(() => {
            session.close();
            done();
          }));
        }),
      });
    });
  });
}

module.exports = { startServer, staticHandler };
