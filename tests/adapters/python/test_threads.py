"""Two worlds stepped at once from two Python threads give what they give one after the other; one
world shared by threads takes turns in the World, is refused (LOCKED) by C when called around it,
and a long step is stopped by cancel() from another thread."""

import ctypes
import struct
import threading

import pytest

import embra
from embra import _capi
from embra.errors import error_for
from tent import flat, run_tent


def cloth(seed, frames=60, grid=8):
    xyz = [(0.1 * j, 0.1 * i, 0.05 * seed) for i in range(grid) for j in range(grid)]
    tri = []
    for i in range(grid - 1):
        for j in range(grid - 1):
            v = i * grid + j
            tri += [(v, v + 1, v + grid + 1), (v, v + grid + 1, v + grid)]
    with embra.World(iterations=2) as w:
        body = w.create_body(xyz, triangles=tri, mass=0.1 * (seed + 1))
        w.create_pin(body.first, xyz[0])
        w.create_pin(body.first + grid - 1, xyz[grid - 1])
        for _ in range(frames):
            w.step()
            # a refusal on this thread carries this thread's message, not the other's
            try:
                w.create_pin(10_000 + seed, (0, 0, 0))
            except embra.InvalidArgumentError as e:
                assert str(10_000 + seed) in str(e)
        return struct.pack(f"<{3 * grid * grid}d", *flat(w.positions()))


def test_two_worlds_on_two_threads_equal_one_after_the_other():
    alone = [cloth(0), cloth(1)]
    together = [None, None]

    def run(i):
        together[i] = cloth(i)

    threads = [threading.Thread(target=run, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert together == alone
    assert alone[0] != alone[1]  # different scenes, so equality is not a coincidence


def test_two_tents_on_two_threads_equal_one_after_the_other():
    alone = struct.pack("<2583d", *run_tent(frames=20, rows=40))
    together = [None, None]

    def run(i):
        together[i] = struct.pack("<2583d", *run_tent(frames=20, rows=40))

    threads = [threading.Thread(target=run, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert together == [alone, alone]


def test_threads_sharing_one_world_take_turns():
    """Two threads stepping one World 30 frames each: 60 frames, the bits of 60 frames on one thread;
    closing it while a thread steps ends that thread's loop with the closed-world error, no crash."""
    def build():
        w = embra.World()
        w.create_body([(0.1 * i, 0.0, 0.0) for i in range(8)], edges=[(i, i + 1) for i in range(7)], mass=0.5)
        w.create_pin(0, (0.0, 0.0, 0.0))
        return w

    with build() as alone:
        alone.step(60)
        expected = struct.pack("<24d", *flat(alone.positions()))
    with build() as shared:
        threads = [threading.Thread(target=shared.step, args=(30,)) for _ in range(2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert shared.report().frame == 60
        assert struct.pack("<24d", *flat(shared.positions())) == expected

    w = build()
    outcome = []

    def step_until_closed():
        try:
            while True:
                w.step()
        except embra.InvalidArgumentError as e:
            outcome.append(str(e))

    t = threading.Thread(target=step_until_closed)
    t.start()
    while w.report().frame < 5:
        pass
    w.close()
    t.join()
    assert outcome and "world is NULL" in outcome[0] and "closed" in outcome[0]


def long_world(n=24):
    """A pinned n x n cloth stepped with the most passes a step may take (substeps x iterations =
    EMBRA_MAX_PASSES_PER_STEP): one frame takes seconds."""
    xyz = [(0.05 * j, 0.05 * i, 0.0) for i in range(n) for j in range(n)]
    tri = []
    for i in range(n - 1):
        for j in range(n - 1):
            v = i * n + j
            tri += [(v, v + 1, v + n + 1), (v, v + n + 1, v + n)]
    w = embra.World(substeps=1000, iterations=embra.MAX_PASSES_PER_STEP // 1000)
    w.create_body(xyz, triangles=tri, mass=0.1)
    w.create_pin(0, xyz[0])
    w.create_pin(n - 1, xyz[n - 1])
    return w


def held_by_another_call(w):
    """True when a call on w's embra_world* made around the World's lock is refused with LOCKED."""
    counts = _capi.WorldCounts()
    return _capi.lib.embra_world_get_counts(w._ptr, ctypes.byref(counts)) == _capi.ERROR_LOCKED


def test_cancel_from_another_thread_stops_a_long_step():
    """cancel() from the main thread while another thread is inside a long step: that step raises
    CancelledError and the world is as it was before the frame (saved scene, frame count). cancel()
    does not take the World's lock, or it would wait for the very step it is meant to stop."""
    with long_world() as w:
        before, frame = w.save_json(), w.report().frame
        outcome = []

        def step():
            while True:
                try:
                    w.step()
                    outcome.append("the step completed")
                    return
                except embra.LockedError:  # held_by_another_call's probe had the world just then
                    continue
                except embra.EmbraError as e:
                    outcome.append(e)
                    return

        t = threading.Thread(target=step)
        t.start()
        while not held_by_another_call(w):  # the step is in progress
            assert t.is_alive(), outcome
        w.cancel()
        t.join()
        assert len(outcome) == 1 and isinstance(outcome[0], embra.CancelledError), outcome
        e = outcome[0]
        assert e.status == _capi.ERROR_CANCELLED and e.status_name == "EMBRA_ERROR_CANCELLED"
        assert str(e).startswith("embra_world_step: ") and "cancel" in str(e)
        assert w.save_json() == before and w.report().frame == frame
        # the request was consumed by the step it stopped: the world steps on
        w.set_solver(substeps=2, iterations=1)
        w.step()
        assert w.report().frame == frame + 1
        assert w.save_json() != before


def test_a_cancel_request_made_between_steps_stops_the_next_one():
    with long_world(n=4) as w:
        before = w.save_json()
        w.cancel()
        with pytest.raises(embra.CancelledError, match="embra_world_step: "):
            w.step()
        assert w.save_json() == before and w.report().frame == 0
        w.set_solver(substeps=2, iterations=1)
        w.step(2)  # the request is gone
        assert w.report().frame == 2
    with embra.World() as closed:
        pass
    with pytest.raises(embra.InvalidArgumentError, match="embra_world_cancel: world is NULL.*closed"):
        closed.cancel()


def test_one_world_on_two_threads_around_the_world_lock_gets_locked_never_a_crash():
    """Raw C calls on one embra_world* from two threads (no World lock between them): while one
    thread steps, the other's calls are refused with LOCKED (LockedError with the C message on that
    thread) and change nothing; every status is OK or LOCKED, and the frame count is the number of
    steps that returned OK."""
    lib = _capi.lib
    n = 16
    xyz = [(0.05 * j, 0.05 * i, 0.0) for i in range(n) for j in range(n)]
    tri = [t for i in range(n - 1) for j in range(n - 1)
           for t in ((i * n + j, i * n + j + 1, (i + 1) * n + j + 1), (i * n + j, (i + 1) * n + j + 1, (i + 1) * n + j))]
    with embra.World(iterations=4) as w:
        w.create_body(xyz, triangles=tri, mass=0.1)
        w.create_pin(0, xyz[0])
        ptr = w._ptr
        step_statuses, other_statuses, locked_errors = [], [], []
        last_gravity = [tuple(w.solver.gravity)]
        done = threading.Event()

        def stepper():
            for _ in range(20000):
                step_statuses.append(lib.embra_world_step(ptr))
                if len(locked_errors) >= 20:
                    break
            done.set()

        def other():
            out = (ctypes.c_double * (3 * n * n))()
            i = 0
            while not done.is_set():
                i += 1
                g = (ctypes.c_double * 3)(0.0, 0.0, -float(i % 50))
                for status, gravity in ((lib.embra_world_set_gravity(ptr, g), tuple(g)),
                                        (lib.embra_world_get_positions(ptr, out, len(out), 0, n * n), None)):
                    other_statuses.append(status)
                    if status == _capi.OK and gravity is not None:
                        last_gravity.append(gravity)
                    elif status == _capi.ERROR_LOCKED:
                        locked_errors.append(error_for(status))  # this thread's message

        threads = [threading.Thread(target=stepper), threading.Thread(target=other)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert set(step_statuses) | set(other_statuses) <= {_capi.OK, _capi.ERROR_LOCKED}
        assert len(locked_errors) >= 20, f"only {len(locked_errors)} calls overlapped a step"
        for e in locked_errors:
            assert isinstance(e, embra.LockedError) and e.status_name == "EMBRA_ERROR_LOCKED"
            assert "in use by a call in progress" in str(e)
        assert w.report().frame == step_statuses.count(_capi.OK)
        assert tuple(w.solver.gravity) == last_gravity[-1]  # refused calls changed nothing
        w.step()  # and the world is whole
        assert all(abs(v) < 10 for v in flat(w.positions()))
