"""Two worlds stepped at once from two Python threads give what they give one after the other."""

import struct
import threading

import embra
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
