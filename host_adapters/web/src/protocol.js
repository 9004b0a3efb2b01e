// The binary frame message of docs/live-protocol.md (little-endian, every offset a multiple of 4).

export const FRAME_MAGIC = 0x464d4245; // bytes "EBMF"
export const FRAME_VERSION = 1;
const HEADER_BYTES = 24;

/**
 * Views into one binary frame message (no copies): positions (3N), collider poses (7C: position,
 * rotation w x y z) and the F per-vertex error fields (N each, NaN where not measured).
 */
export function parseFrame(buffer) {
  if (buffer.byteLength < HEADER_BYTES) throw new Error(`frame message of ${buffer.byteLength} bytes`);
  const head = new DataView(buffer, 0, HEADER_BYTES);
  const magic = head.getUint32(0, true);
  if (magic !== FRAME_MAGIC) throw new Error(`frame message magic 0x${magic.toString(16)}`);
  const version = head.getUint32(4, true);
  if (version !== FRAME_VERSION) throw new Error(`frame message version ${version}`);
  const frame = head.getUint32(8, true);
  const n = head.getUint32(12, true);
  const c = head.getUint32(16, true);
  const f = head.getUint32(20, true);
  const bytes = HEADER_BYTES + 4 * (3 * n + 7 * c + f * n);
  if (buffer.byteLength < bytes) throw new Error(`frame message of ${buffer.byteLength} bytes, ${bytes} expected`);
  // Float32Array views need a little-endian host; every browser the page targets is one.
  let offset = HEADER_BYTES;
  const positions = new Float32Array(buffer, offset, 3 * n);
  offset += 12 * n;
  const poses = new Float32Array(buffer, offset, 7 * c);
  offset += 28 * c;
  const fields = [];
  for (let k = 0; k < f; k++) {
    fields.push(new Float32Array(buffer, offset, n));
    offset += 4 * n;
  }
  return { frame, particles: n, colliders: c, positions, poses, fields };
}
