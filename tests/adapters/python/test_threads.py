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
