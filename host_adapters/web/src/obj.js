// The OBJ files `embra run` writes: every particle as a `v` line in world order, each body's
// triangles as `f` lines under `g body_<index>` (1-based, possibly v/vt/vn or negative indices).

/** Positions (3N floats) and triangles per body index (world particle indices, 0-based). */
export function parseObj(text) {
  const coords = [];
  const bodies = new Map();
  let current = 0;
  let faces = null;
  const facesOf = (index) => {
    if (!bodies.has(index)) bodies.set(index, []);
    return bodies.get(index);
  };
  for (const raw of text.split('\n')) {
    const line = raw.trim();
    if (line.startsWith('v ')) {
      const parts = line.split(/\s+/);
      coords.push(Number(parts[1]), Number(parts[2]), Number(parts[3]));
    } else if (line.startsWith('g ') || line.startsWith('o ')) {
      const match = /body_(\d+)/.exec(line);
      current = match ? Number(match[1]) : current;
      faces = null;
    } else if (line.startsWith('f ')) {
      faces = faces || facesOf(current);
      const count = coords.length / 3;
      const ids = line.split(/\s+/).slice(1).map((token) => {
        const k = parseInt(token, 10);
        return k < 0 ? count + k : k - 1;
      });
      for (let k = 1; k + 1 < ids.length; k++) faces.push(ids[0], ids[k], ids[k + 1]);
    }
  }
  return { positions: Float32Array.from(coords), bodies };
}

/** Only the positions (the topology of a replay folder's OBJs is the same in every frame). */
export function parseObjPositions(text, particles) {
  const out = new Float32Array(3 * particles);
  let n = 0;
  let start = 0;
  while (start < text.length) {
    let end = text.indexOf('\n', start);
    if (end < 0) end = text.length;
    if (text.charCodeAt(start) === 118 && text.charCodeAt(start + 1) === 32) { // "v "
      const parts = text.slice(start + 2, end).trim().split(/\s+/);
      if (n < particles) {
        out[3 * n] = Number(parts[0]);
        out[3 * n + 1] = Number(parts[1]);
        out[3 * n + 2] = Number(parts[2]);
      }
      n++;
    }
    start = end + 1;
  }
  if (n !== particles) throw new Error(`OBJ with ${n} vertices, ${particles} expected`);
  return out;
}
