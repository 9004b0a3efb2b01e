'use strict';
// embra-live's server: the page over http, the live scene over a WebSocket (docs/live-protocol.md).
// Steps the scene in real time (one frame per scene dt; as fast as it can when a frame takes
// longer, never queuing frames) and streams every stepped frame to every page that keeps up.
//
// Only pages of the server itself may drive it: every http request must name the server in its
// Host header (a page of another site that rebinds its own name to 127.0.0.1 is refused), and a
// WebSocket from a browser must come from one of the server's own origins. What one connection can
// send is bounded (message size, messages per second, connections at once): docs/live-protocol.md
// states the figures, DEFAULTS below holds them.

const fs = require('fs');
const http = require('http');
const net = require('net');
const path = require('path');
const { WebSocketServer } = require('ws');
const { Session, RefusedMessage, KEEP_FILES } = require('./session');
const { EmbraError } = require('../lib');

/** The bounds of a server; each can be changed by the startServer option of the same name. */
const DEFAULTS = Object.freeze({
  maxMessageBytes: 64 * 1024, // a page's message is a few hundred bytes; a bigger one closes its socket (1009)
  messagesPerSecond: 250, // per connection, sustained (a drag sends one message per animation frame)
  messageBurst: 500, // per connection, at once (the token bucket's size)
  heavyMessageCost: 50, // save, export and reset count as this many messages
  maxConnections: 32, // WebSocket connections at once; one more is refused with 503
  keepFiles: KEEP_FILES, // output files kept per scene
});
const FRAME_SKIP_BYTES = 4 * 1024 * 1024; // a page further behind than this skips frames
const CLOSE_BEHIND_BYTES = 64 * 1024 * 1024; // a page this far behind (not reading its replies) is closed
const HTTP_EXTRA_SOCKETS = 16; // sockets beyond maxConnections for page loads (server.maxConnections)
const REQUEST_TIMEOUT_MS = 10000; // an http request (or a WebSocket handshake) must arrive within this
const FIGHTS_EVERY = 10; // frames between `fights` messages
const FRAMES_AHEAD = 2; // frames sent to a page that acknowledges what it draws, and not yet drawn
const DRAWN_WAIT_MS = 1000; // a frame not acknowledged within this no longer holds the next back
const HEAVY = new Set(['save', 'export', 'export_all', 'reset']);
const TYPES = { '.html': 'text/html; charset=utf-8', '.js': 'text/javascript; charset=utf-8',
                '.css': 'text/css; charset=utf-8', '.json': 'application/json', '.png': 'image/png',
                '.map': 'application/json', '.svg': 'image/svg+xml' };
const LOOPBACK = ['127.0.0.1', 'localhost', '[::1]'];

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
    if (rel.includes('\0')) {
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
        res.writeHead(404, { 'content-type': 'text/plain' }).end('not found\n');
        return;
      }
      res.writeHead(200, { 'content-type': TYPES[path.extname(file)] || 'application/octet-stream',
                           'cache-control': 'no-store' });
      res.end(req.method === 'HEAD' ? undefined : data);
    });
  };
}

/** `host` as it appears in a URL: an IPv6 address in brackets. */
function urlHost(host) {
  return net.isIPv6(host) ? `[${host}]` : host;
}

/**
 * The Host header values and WebSocket origins a server accepts: its loopback names with its port,
 * the address it is bound to (unless a wildcard), and each extra origin (with its host:port).
 */
function allowed(boundHost, port, extraOrigins) {
  const names = new Set(LOOPBACK);
  if (boundHost && boundHost !== '0.0.0.0' && boundHost !== '::') names.add(urlHost(boundHost).toLowerCase());
  const hosts = new Set([...names].map((h) => `${h}:${port}`));
  if (port === 80) for (const h of names) hosts.add(h);
  const origins = new Set([...names].map((h) => `http://${h}:${port}`));
  for (const o of extraOrigins) {
    const url = new URL(o);
    origins.add(url.origin);
    hosts.add(url.host);
  }
  return { hosts, origins };
}

/** An extra origin as given: an http(s) origin exactly (no path, no trailing slash), lower case. */
function checkOrigin(origin) {
  let url;
  try {
    url = new URL(origin);
  } catch {
    throw new RangeError(`allowed origin ${JSON.stringify(origin)} is not a URL`);
  }
  if ((url.protocol !== 'http:' && url.protocol !== 'https:') || url.origin !== origin.toLowerCase())
    throw new RangeError(`allowed origin ${JSON.stringify(origin)} must be scheme://host[:port] (http or https), e.g. http://192.168.1.5:8710`);
  return url.origin;
}

/** A token bucket: `rate` tokens a second, at most `burst` held. */
class Bucket {
  constructor(rate, burst) {
    Object.assign(this, { rate, burst, tokens: burst, last: performance.now() });
  }

  take(n) {
    const now = performance.now();
    this.tokens = Math.min(this.burst, this.tokens + ((now - this.last) / 1000) * this.rate);
    this.last = now;
    if (this.tokens < n) return false;
    this.tokens -= n;
    return true;
  }
}

function positiveInteger(value, what) {
  if (!Number.isInteger(value) || value < 1) throw new RangeError(`${what} must be an integer >= 1`);
  return value;
}

/**
 * Starts a live server. options: {scene (path), host ('127.0.0.1'), port (0 = any free one),
 * web (folder of the built page), saveDir (the output folder), threads (solver threads, 0 = one per
 * core; default the scene's solver.threads), allowOrigins (extra origins a page
 * may come from, e.g. ['http://192.168.1.5:8710']), log (a function taking a line; default
 * stderr), waitForPage (default true: no frame is stepped before the first page connects), and
 * the bounds of DEFAULTS}. Resolves to {url, port, session, limits, connections() (the
 * WebSocket connections open), close()}.
 */
function startServer(options) {
  const log = options.log || ((line) => process.stderr.write(`embra-live: ${line}\n`));
  const limits = { ...DEFAULTS };
  for (const key of Object.keys(DEFAULTS)) if (options[key] !== undefined) limits[key] = positiveInteger(options[key], key);
  if (limits.heavyMessageCost > limits.messageBurst) throw new RangeError('heavyMessageCost must be at most messageBurst');
  const extraOrigins = (options.allowOrigins || []).map(checkOrigin);
  const session = new Session(options.scene, { saveDir: options.saveDir, keepFiles: limits.keepFiles, threads: options.threads });
  const web = options.web || path.join(__dirname, '..', '..', 'web', 'dist');
  const serveStatic = staticHandler(web);
  let gate = { hosts: new Set(), origins: new Set() }; // set once the port is known
  const hostAllowed = (req) => gate.hosts.has(String(req.headers.host || '').toLowerCase());

  const server = http.createServer((req, res) => {
    if (!hostAllowed(req)) {
      log(`refused an http request for Host ${JSON.stringify(req.headers.host)}`);
      res.writeHead(403, { 'content-type': 'text/plain' }).end('this server answers to its own host names only\n');
      return;
    }
    serveStatic(req, res);
  });
  server.maxConnections = limits.maxConnections + HTTP_EXTRA_SOCKETS;
  server.headersTimeout = REQUEST_TIMEOUT_MS;
  server.requestTimeout = REQUEST_TIMEOUT_MS;
  const wss = new WebSocketServer({ noServer: true, maxPayload: limits.maxMessageBytes, perMessageDeflate: false,
                                    clientTracking: false });
  const clients = new Set();
  let sockets = 0; // WebSocket connections accepted and not yet closed
  let timer = null;
  let closed = false;
  let next = 0;
  // Paused until a page connects: a page opened a while after launch sees the scene from frame 0.
  let waiting = options.waitForPage !== false;

  const send = (ws, message) => {
    if (ws.readyState !== ws.OPEN) return;
    if (ws.bufferedAmount > CLOSE_BEHIND_BYTES) {
      log(`closed a page ${ws.bufferedAmount} bytes behind`);
      ws.terminate();
      return;
    }
    ws.send(typeof message === 'string' ? message : JSON.stringify(message));
  };
  const broadcast = (message) => {
    const text = JSON.stringify(message);
    for (const ws of clients) send(ws, text);
  };
  // Pacing (docs/live-protocol.md, `drawn`): a page that acknowledges the frames it draws has at most
  // FRAMES_AHEAD frames sent and not yet drawn; the frames stepped meanwhile are skipped for it, and
  // the latest goes out as soon as it catches up. So what it shows lags the server by a frame or two,
  // however slowly it draws, instead of by the 4 MB a socket may hold. A page that never
  // acknowledges is limited by that buffer alone.
  const pacing = new Map(); // ws -> { sent: [{ frame, at }], behind: the latest frame was skipped }
  let latest = null; // the last frame stepped: { record, geometry }
  const sendFrame = (ws, record, geometry) => {
    if (ws.readyState !== ws.OPEN || ws.bufferedAmount > FRAME_SKIP_BYTES) return;
    const pace = pacing.get(ws);
    if (pace) {
      const now = performance.now();
      pace.sent = pace.sent.filter((f) => f.at > now - DRAWN_WAIT_MS);
      if (pace.sent.length >= FRAMES_AHEAD) {
        pace.behind = true;
        return;
      }
      pace.sent.push({ frame: session.record.frame, at: now });
      pace.behind = false;
    }
    ws.send(record);
    ws.send(geometry, { binary: true });
  };
  const drawn = (ws, frame) => {
    if (!Number.isInteger(frame) || frame < 0) throw new RefusedMessage('drawn: frame must be a frame number');
    let pace = pacing.get(ws);
    if (!pace) pacing.set(ws, pace = { sent: [], behind: false });
    pace.sent = pace.sent.filter((f) => f.frame > frame);
    if (pace.behind && latest) sendFrame(ws, latest.record, latest.geometry);
  };
  const broadcastFrame = () => {
    if (clients.size === 0) return;
    const record = JSON.stringify(session.frameMessage());
    const geometry = Buffer.from(session.geometryMessage());
    latest = { record, geometry };
    for (const ws of clients) sendFrame(ws, record, geometry);
    // What fights, every FIGHTS_EVERY frames and at every frame stepped while paused.
    if (session.paused || session.record.frame % FIGHTS_EVERY === 0) {
      const fights = JSON.stringify(session.fightsMessage());
      for (const ws of clients) if (ws.bufferedAmount <= FRAME_SKIP_BYTES) send(ws, fights);
    }
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
    if (!session.paused && !waiting) {
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
    schedule(next - after);
  };
  // A frame already due runs once the pending I/O has been handled (setImmediate), not after
  // setTimeout's floor of 1 ms: behind the clock, that floor is a millisecond lost every frame.
  const schedule = (delay) => {
    timer = delay > 0 ? { timeout: setTimeout(tick, delay) } : { immediate: setImmediate(tick) };
  };

  // The WebSocket handshake: refused with an http status before any upgrade unless the Host is the
  // server's, the path is /live, a browser's Origin is one of the server's, and there is room.
  server.on('upgrade', (req, socket, head) => {
    socket.on('error', () => {});
    const refuse = (status, reason) => {
      log(`refused a WebSocket from ${req.socket.remoteAddress} (Host ${JSON.stringify(req.headers.host)}, ` +
          `Origin ${JSON.stringify(req.headers.origin)}): ${reason}`);
      const body = `${reason}\n`;
      socket.end(`HTTP/1.1 ${status} ${http.STATUS_CODES[status]}\r\nConnection: close\r\n` +
                 `Content-Type: text/plain\r\nContent-Length: ${Buffer.byteLength(body)}\r\n\r\n${body}`);
    };
    let pathname;
    try {
      pathname = new URL(req.url, 'http://localhost').pathname;
    } catch {
      pathname = null;
    }
    if (!hostAllowed(req)) return refuse(403, 'this server answers to its own host names only');
    if (pathname !== '/live') return refuse(404, 'the WebSocket is at /live');
    const origin = req.headers.origin;
    if (origin !== undefined && !gate.origins.has(origin.toLowerCase()))
      return refuse(403, 'pages of other origins may not connect (see --allow-origin)');
    if (closed) return refuse(503, 'the server is closing');
    if (sockets >= limits.maxConnections) return refuse(503, `at most ${limits.maxConnections} connections at once`);
    sockets += 1;
    socket.once('close', () => { sockets -= 1; });
    wss.handleUpgrade(req, socket, head, (ws) => wss.emit('connection', ws, req));
  });

  wss.on('connection', (ws, req) => {
    clients.add(ws);
    if (waiting) {
      waiting = false;
      next = performance.now();
    }
    log(`page connected from ${req.socket.remoteAddress}`);
    const bucket = new Bucket(limits.messagesPerSecond, limits.messageBurst);
    // Messages over the rate are dropped unread; the page hears of them in one `error` a second at
    // most, carrying how many were dropped since the last one.
    let dropped = 0;
    let lastReport = -Infinity;
    let reportTimer = null;
    const report = () => {
      reportTimer = null;
      lastReport = performance.now();
      log(`dropped ${dropped} messages of a page over the rate limit`);
      send(ws, { type: 'error', dropped, message: `too many messages: ${dropped} dropped unread (at most ` +
        `${limits.messagesPerSecond} a second, ${limits.messageBurst} at once; save, export and reset count ` +
        `${limits.heavyMessageCost})` });
      dropped = 0;
    };
    const drop = () => {
      dropped += 1;
      if (reportTimer) return;
      const wait = lastReport + 1000 - performance.now();
      if (wait <= 0) report();
      else reportTimer = setTimeout(report, wait);
    };
    send(ws, session.sceneMessage());
    sendFrame(ws, JSON.stringify(session.frameMessage()), Buffer.from(session.geometryMessage()));
    ws.on('message', async (data, isBinary) => {
      if (!bucket.take(1)) return drop();
      let msg;
      try {
        if (isBinary) throw new RefusedMessage('binary messages are not part of the protocol');
        try {
          msg = JSON.parse(data.toString('utf8'));
        } catch {
          throw new RefusedMessage('not JSON');
        }
        if (msg && HEAVY.has(msg.type) && !bucket.take(limits.heavyMessageCost - 1)) return drop();
        if (closed) return;
        if (msg && msg.type === 'drawn') return drawn(ws, msg.frame);
        let result = session.handle(msg, ws); // a refusal throws here, answered before the next message
        if (result instanceof Promise) result = await result;
        for (const r of result.replies || []) send(ws, r);
        if (result.broadcast) for (const other of clients) if (other !== ws) for (const r of result.replies || []) send(other, r);
        if (result.scene) {
          broadcast(session.sceneMessage());
          for (const pace of pacing.values()) pace.sent = []; // frame numbers may start again
          broadcastFrame();
        }
        if (result.stepped) stepAndSend();
      } catch (e) {
        if (!(e instanceof RefusedMessage) && !(e instanceof EmbraError) && !(e instanceof TypeError) &&
            !(e instanceof RangeError)) {
          log(`internal error on ${JSON.stringify(msg && msg.type)}: ${e.stack || e}`);
        }
        const text = isBinary ? `${data.length} binary bytes` : JSON.stringify(String(data).slice(0, 200));
        log(`refused ${text}: ${e.message}`);
        send(ws, { type: 'error', message: e.message });
      }
    });
    ws.on('close', () => {
      clients.delete(ws);
      pacing.delete(ws);
      if (reportTimer) clearTimeout(reportTimer);
      if (session.world) session.releaseDrag(ws); // a page that goes away lets go of what it held
    });
    ws.on('error', (e) => log(`socket error: ${e.message}`));
  });
  wss.on('error', (e) => log(`websocket server error: ${e.message}`));

  return new Promise((resolve, reject) => {
    server.once('error', (e) => {
      session.close();
      reject(e);
    });
    const host = options.host || '127.0.0.1';
    server.listen(options.port ?? 0, host, () => {
      const { port } = server.address();
      gate = allowed(host, port, extraOrigins);
      next = performance.now();
      schedule(0);
      resolve({
        url: `http://${urlHost(host)}:${port}/`,
        port,
        session,
        limits,
        connections: () => sockets,
        /** True until the first page connects (the clock does not step before). */
        waiting: () => waiting,
        close: () => new Promise((done) => {
          closed = true;
          if (timer?.timeout) clearTimeout(timer.timeout);
          if (timer?.immediate) clearImmediate(timer.immediate);
          for (const ws of clients) ws.terminate();
          wss.close(() => server.close(() => {
            session.close();
            done();
          }));
          server.closeAllConnections();
        }),
      });
    });
  });
}

module.exports = { startServer, staticHandler, checkOrigin, DEFAULTS, allowed };
