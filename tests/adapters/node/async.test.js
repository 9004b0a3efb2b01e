'use strict';
// World.stepAsync runs frames on koffi's worker threads: the frames step() would step, bit for bit;
// while one runs, every other call on the World is refused by C with LockedError and changes nothing,
// cancel() stops it with CancelledError and the world as before the frame, and close() cancels it and
// destroys the world when the worker returns.

const assert = require('node:assert/strict');
const test = require('node:test');

const { embra, assertSameBits, snapshot } = require('./helpers');

/** A pinned n x n cloth with the most passes a step may take (substeps x iterations = the maximum). */
function cloth(n, settings = { substeps: 1000, iterations: embra.capi.MAX_PASSES_PER_STEP / 1000 }) {
  const xyz = [];
  const tri = [];
  for (let i = 0; i < n; i++) for (let j = 0; j < n; j++) xyz.push([0.05 * j, 0.05 * i, 0]);
  for (let i = 0; i + 1 < n; i++) {
    for (let j = 0; j + 1 < n; j++) {
      const v = i * n + j;
      tri.push([v, v + 1, v + n + 1], [v, v + n + 1, v + n]);
    }
  }
  const w = new embra.World(settings);
  w.createBody(xyz, { triangles: tri, mass: 0.1 });
  w.createPin(0, xyz[0]);
  w.createPin(n - 1, xyz[n - 1]);
  return w;
}

/** Settles to 'settled' once `promise` does, so a wait loop can stop instead of spinning forever. */
function watch(promise) {
  const state = { settled: false };
  promise.then(() => { state.settled = true; }, () => { state.settled = true; });
  return state;
}

/** Waits (letting the event loop run) until a call on `w` is refused with LockedError; returns it. */
async function untilLocked(w, state) {
  for (;;) {
    try {
      w.counts();
    } catch (e) {
      if (e instanceof embra.LockedError) return e;
      throw e;
    }
    assert.ok(!state.settled, 'the asynchronous step ended before a call found the world in use');
    await new Promise((resolve) => setImmediate(resolve));
  }
}

test('stepAsync steps the frames step() steps, bit for bit, and its calls take turns', async () => {
  const settings = { substeps: 8, iterations: 4 };
  const a = cloth(8, settings);
  const b = cloth(8, settings);
  a.step(6);
  await Promise.all([b.stepAsync(3), b.stepAsync(3)]); // the second waits for the first
  assert.equal(b.report().frame, 6);
  assertSameBits(b.positions(), a.positions(), 'positions after 6 frames');
  assertSameBits(b.velocities(), a.velocities(), 'velocities after 6 frames');
  await b.stepAsync(0);
  assert.throws(() => b.stepAsync(-1), RangeError);
  a.close();
  b.close();
});

test('while a frame runs on a worker, other calls get LockedError and change nothing; cancel() stops it',
  async () => {
    const w = cloth(24);
    const before = snapshot(w);
    const gravity = w.solver.gravity;
    const stepping = w.stepAsync();
    const state = watch(stepping);
    const locked = await untilLocked(w, state);
    assert.equal(locked.status, embra.capi.ERROR_LOCKED);
    assert.equal(locked.statusName, 'EMBRA_ERROR_LOCKED');
    assert.match(locked.message, /^embra_world_get_counts: .*in use by a call in progress/);
    assert.equal(locked.message, embra.lastErrorMessage()); // the C message of this thread, verbatim
    assert.throws(() => w.setGravity([0, 0, 1]), embra.LockedError);
    assert.throws(() => w.step(), embra.LockedError);
    assert.throws(() => w.saveJson(), embra.LockedError);
    w.cancel(); // the one call C takes while another is in progress
    await assert.rejects(stepping, (e) => {
      assert.ok(e instanceof embra.CancelledError, `${e.name}: ${e.message}`);
      assert.equal(e.status, embra.capi.ERROR_CANCELLED);
      assert.equal(e.statusName, 'EMBRA_ERROR_CANCELLED');
      assert.match(e.message, /^embra_world_step .*EMBRA_ERROR_CANCELLED by World\.cancel\(\).*as before the frame/);
      return true;
    });
    assert.deepEqual(snapshot(w), before); // as before the frame: the refused calls changed nothing either
    assert.deepEqual(w.solver.gravity, gravity);
    assert.equal(w.report().frame, 0);
    w.setSolver({ substeps: 2, iterations: 1 }); // the request was consumed: the world steps on
    await w.stepAsync(2);
    assert.equal(w.report().frame, 2);
    w.close();
  });

test('a cancel request made between steps stops the next frame', async () => {
  const w = cloth(4, { substeps: 2, iterations: 1 });
  const before = snapshot(w);
  w.cancel();
  assert.throws(() => w.step(), (e) => e instanceof embra.CancelledError && /^embra_world_step: /.test(e.message));
  assert.deepEqual(snapshot(w), before);
  w.cancel();
  await assert.rejects(w.stepAsync(3), embra.CancelledError);
  assert.deepEqual(snapshot(w), before);
  await w.stepAsync(2);
  assert.equal(w.report().frame, 2);
  w.close();
  assert.throws(() => w.cancel(), (e) => e instanceof embra.InvalidArgumentError &&
    /^embra_world_cancel: world is NULL.*closed/.test(e.message));
});

test('a frame that goes non-finite on a worker rejects with NumericalError naming where', async () => {
  const w = new embra.World();
  w.createBody([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], { triangles: [[0, 1, 2], [0, 2, 3]], mass: 1.0 });
  await w.stepAsync(3);
  w.setVelocities([[embra.capi.MAX_ABS_VALUE, 0, 0]], 1);
  const before = snapshot(w);
  await assert.rejects(w.stepAsync(5), (e) => {
    assert.ok(e instanceof embra.NumericalError, `${e.name}: ${e.message}`);
    const { frame, particle } = w.warning();
    assert.equal(frame, 3);
    assert.ok(particle >= 0);
    assert.ok(e.message.includes(`particle ${particle} in frame ${frame}`), e.message);
    return true;
  });
  assert.deepEqual(snapshot(w), before);
  w.close();
});

test('close() during a frame on a worker cancels it; the world goes when the worker returns', async () => {
  const w = cloth(24);
  const stepping = w.stepAsync(3);
  await untilLocked(w, watch(stepping));
  w.close();
  assert.ok(w.closed);
  assert.throws(() => w.counts(), (e) => e instanceof embra.InvalidArgumentError && /closed/.test(e.message));
  await assert.rejects(stepping, (e) => e instanceof embra.CancelledError && /closed meanwhile/.test(e.message));
  await assert.rejects(w.stepAsync(), (e) => e instanceof embra.InvalidArgumentError &&
    /^embra_world_step: world is NULL.*closed/.test(e.message));
  w.close(); // idempotent
});
