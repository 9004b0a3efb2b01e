// The OBJ files `embra run` writes: every particle as a `v` line in world order, each body's
// triangles as `f` lines and the edges of an edge-only body (a net) as `l` lines under
// `g body_<index>` (1-based, possibly v/vt/vn or negative indices).

/**
 * Positions (3N floats), triangles per body index and edges per body index (world particle
 * indices, 0-based; an `l` polyline of k points gives k - 1 edges, 2 indices each).
 */
export function parseObj(text) {
  const coords = [];
  const bodies = new Map();
  const edges = new Map();
  let current = 0;
  let faces = null;
  const listOf = (map, index) => {
    if (!map.has(index)) map.set(index, []);
    return map.get(index);
  };
  const facesOf = (index) => listOf(bodies, index);
  const ids = (line) => {
    const count = coords.length / 3;
    return line.split(/\s+/).slice(1).map((token) => {
      const k = parseInt(token, 10);
      return k < 0 ? count + k : k - 1;
    });
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
      const f = ids(line);
      for (let k = 1; k + 1 < f.length; k++) faces.push(f[0], f[k], f[k + 1]);
    } else if (line.startsWith('l ')) {
      const l = ids(line);
      const list = listOf(edges, current);
      for (let k = 0; k + 1 < l.length; k++) list.push(l[k], l[k + 1]);
    }
  }
  return { positions: Float32Array.from(coords), bodies, edges };
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
