// The WebSocket to embra-live (docs/live-protocol.md): text messages are JSON with a `type`; each
// `frame` message is followed at once by one binary message with that frame's geometry.

import { parseFrame } from './protocol.js';

export function liveUrl(location = window.location) {
  const scheme = location.protocol === 'https:' ? 'wss:' : 'ws:';
  return `${scheme}//${location.host}/live`;
}

export class LiveClient {
  /**
   * handlers: scene(msg), frame(row, geometry), status(msg), saved(msg), exported(msg),
   * error(msg), open(), close(wasOpen).
   */
  constructor(url, handlers) {
    this.url = url;
    this.handlers = handlers;
    this.pendingRow = null;
    this.opened = false;
    this.socket = new WebSocket(url);
    this.socket.binaryType = 'arraybuffer';
    this.socket.addEventListener('open', () => {
      this.opened = true;
      handlers.open?.();
    });
    this.socket.addEventListener('close', () => handlers.close?.(this.opened));
    this.socket.addEventListener('message', (event) => this.receive(event.data));
  }

  get connected() {
    return this.socket.readyState === WebSocket.OPEN;
  }

  receive(data) {
    if (typeof data !== 'string') {
      let geometry;
      try {
        geometry = parseFrame(data);
      } catch (err) {
        this.handlers.error?.({ type: 'error', message: `page: ${err.message}` });
        return;
      }
      const row = this.pendingRow && this.pendingRow.frame === geometry.frame ? this.pendingRow : { frame: geometry.frame };
      this.pendingRow = null;
      this.handlers.frame?.(row, geometry);
      return;
    }
    let msg;
    try {
      msg = JSON.parse(data);
    } catch (err) {
      this.handlers.error?.({ type: 'error', message: `page: unreadable message (${err.message})` });
      return;
    }
    if (msg.type === 'frame') {
      this.pendingRow = msg;
      return;
    }
    const handler = this.handlers[msg.type];
    if (handler) handler(msg);
  }

  send(msg) {
    if (!this.connected) return false;
    this.socket.send(JSON.stringify(msg));
    return true;
  }

  close() {
    this.socket.close();
  }
}
