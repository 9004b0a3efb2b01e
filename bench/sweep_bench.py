#!/usr/bin/python3
"""Sweep benchmark: a 32-variant sweep of examples/poq_drape.json on a LocalCluster of 1 and of 2
workers (speed-up), and the scheduler's overhead per task.

    EMBRA_LIBRARY=build/libembra.so /usr/bin/python3 bench/sweep_bench.py [--frames 120] [--repeats 2]

The sweep: 4 post draw-ins x 8 panel thicknesses, `frames` frames each, metrics kept, no
thumbnails (they are drawn in the client, which a sweep's speed-up is not about). Per worker count it
prints the wall time of the sweep on a running cluster (the cluster's start apart), the sum of the
variants' own times in their workers (wall, and CPU: on a machine whose cores other work shares,
the CPU time falls below the wall time and the speed-up with it), and the overhead per task:
(wall x workers - sum) / 32, the time a worker is not running a variant (scheduling, moving the
scene and results, writing the folders).
Then the bare scheduler: a round trip of 32 tasks that do nothing, per task. Repeats alternate the
worker counts (1, 2, 1, 2, ...) so that a busy machine weighs on both alike; the best of each is
printed.
"""

import argparse
import json
import os
import statistics
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "host_adapters", "python"))
os.environ["PYTHONPATH"] = os.pathsep.join([os.path.join(ROOT, "host_adapters", "python")] +
                                           [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])

import embra  # noqa: E402


def document(frames):
    with open(os.path.join(ROOT, "examples", "sweeps", "poq_drape.json")) as f:
        doc = json.load(f)
    doc["scene"] = os.path.join(ROOT, "examples", "poq_drape.json")
    doc["parameters"][0]["values"] = [0.04, 0.07, 0.1, 0.13]
    doc["parameters"][1].pop("values", None)
    doc["parameters"][1]["range"] = {"from": 0.005, "to": 0.04, "count": 8}
    doc["run"] = {"frames": frames}
    doc["keep"] = {"thumbnail": False}
    return doc


def noop(i):
    return i


def main():
    from distributed import Client, LocalCluster

    p = argparse.ArgumentParser()
    p.add_argument("--frames", type=int, default=120)
    p.add_argument("--repeats", type=int, default=2)
    a = p.parse_args()
    doc = document(a.frames)
    clusters = {}
    for n in (1, 2):
        t0 = time.perf_counter()
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address="127.0.0.1:0")
        client = Client(cluster)
        client.submit(noop, -1, pure=False).result()  # every worker up
        clusters[n] = (cluster, client, time.perf_counter() - t0)
    runs = {1: [], 2: []}
    noops = {1: [], 2: []}
    for _ in range(a.repeats):
        for n in (1, 2):
            _, client, _ = clusters[n]
            with tempfile.TemporaryDirectory() as out:
                t0 = time.perf_counter()
                rows = embra.sweep(doc, out, client=client, progress=None)
                wall = time.perf_counter() - t0
            assert len(rows) == 32 and all(r["status"] == "ok" for r in rows), rows
            runs[n].append((wall, sum(r["seconds"] for r in rows), sum(r["cpu_seconds"] for r in rows)))
            t0 = time.perf_counter()
            futures = [client.submit(noop, i, pure=False) for i in range(32)]
            client.gather(futures)
            noops[n].append(time.perf_counter() - t0)
    print(f"embra {embra.version_string()}, {os.cpu_count()} cores, 32 variants of {a.frames} frames, "
          f"best of {a.repeats}")
    best = {}
    for n in (1, 2):
        wall, busy, cpu = min(runs[n])
        best[n] = wall
        print(f"{n} worker{'s' if n > 1 else ' '}: sweep {wall:7.2f} s wall, variants {busy:7.2f} s in workers "
              f"({cpu:.2f} s CPU: {cpu / busy:.0%} of their wall time), "
              f"overhead {(wall * n - busy) / 32 * 1000:6.1f} ms per task; cluster start {clusters[n][2]:.2f} s; "
              f"32 no-op tasks {min(noops[n]) / 32 * 1000:.2f} ms per task "
              f"(all runs: {', '.join(f'{r[0]:.2f}' for r in runs[n])} s)")
    print(f"speed-up 1 -> 2 workers: {best[1] / best[2]:.2f} "
          f"(median runs: {statistics.median(r[0] for r in runs[1]) / statistics.median(r[0] for r in runs[2]):.2f})")
    for cluster, client, _ in clusters.values():
        client.close()
        cluster.close()


if __name__ == "__main__":
    main()
