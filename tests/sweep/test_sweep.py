"""Design-space sweeps on Dask (embra.sweeps), checked against the `embra` command.

Environment (tests/sweep/CMakeLists.txt): EMBRA_LIBRARY, EMBRA_CLI, EMBRA_SOURCE_DIR. Run by hand
from a build with Debian's /usr/bin/python3 (python3-distributed):

    EMBRA_LIBRARY=build/libembra.so EMBRA_CLI=build/host_adapters/cli/embra EMBRA_SOURCE_DIR=$PWD \
      /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/sweep

The sweep is examples/sweeps/poq_drape.json (3 x 3: post draw-in and panel thickness) at FRAMES
frames: the posts are drawn in over frames 0 to 30, so the variants differ by then.
"""

import copy
import json
import os
import signal
import subprocess
import sys
import threading
import time

import pytest

SOURCE = os.environ["EMBRA_SOURCE_DIR"]
# Workers are separate processes: they find the package through PYTHONPATH (and libembra through
# EMBRA_LIBRARY), as a cluster's workers find an installed package.
PACKAGE_DIR = os.path.join(SOURCE, "host_adapters", "python")
_inherited = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
os.environ["PYTHONPATH"] = os.pathsep.join([PACKAGE_DIR] + _inherited)
sys.path.insert(0, PACKAGE_DIR)

import embra  # noqa: E402
from embra import sweeps  # noqa: E402

FRAMES = 60
EXAMPLE = os.path.join(SOURCE, "examples", "sweeps", "poq_drape.json")


def example_sweep(frames=FRAMES):
    with open(EXAMPLE) as f:
        doc = json.load(f)
    doc["scene"] = os.path.join(SOURCE, "examples", "sweeps", doc["scene"])
    doc["run"] = {"frames": frames}
    return doc


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address="127.0.0.1:0")
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


def variant_scene(draw_in, thickness):
    """The variant as the sweep document describes it, built here from the base scene by hand: each
    post's x at frame 30 is x0 * (1 - draw_in) written as scale * draw_in + offset with scale -x0
    and offset x0 (x0 its frame-0 x, +-1.6), and the panel mesh's thickness."""
    with open(os.path.join(SOURCE, "examples", "poq_drape.json")) as f:
        scene = json.load(f)
    for action in scene["actions"][:4]:
        assert action["type"] == "pin_target"
        x0 = action["keys"][0]["value"][0]
        action["keys"][1]["value"][0] = -x0 * draw_in + x0
    scene["panel_meshes"][0]["thickness"] = thickness
    return scene


@pytest.fixture(scope="module")
def cli_runs(tmp_path_factory):
    """`embra run VARIANT --frames FRAMES` of each of the 9 variants: {(draw_in, thickness): out dir}."""
    root = tmp_path_factory.mktemp("cli")
    runs = {}
    for d in (0.05, 0.1, 0.15):
        for t in (0.005, 0.01, 0.02):
            name = f"d{d}_t{t}"
            scene = root / f"{name}.json"
            scene.write_text(json.dumps(variant_scene(d, t)))
            out = root / name
            subprocess.run([os.environ["EMBRA_CLI"], "run", str(scene), "--frames", str(FRAMES), "--out", str(out)],
                           check=True, stdout=subprocess.DEVNULL)
            runs[(d, t)] = out
    return runs


def read(path):
    with open(path, "rb") as f:
        return f.read()


def check_against_cli(out, rows, cli_runs):
    assert len(rows) == 9
    seen = set()
    for row in rows:
        key = (row["draw_in"], row["thickness"])
        seen.add(key)
        folder = os.path.join(out, row["name"])
        assert row["status"] == "ok", row["error"]
        assert row["frames"] == FRAMES
        # the variant scene the sweep wrote is the scene built by hand, value for value
        assert json.loads(read(os.path.join(folder, "scene.json"))) == variant_scene(*key)
        # the world after the run: the same bytes as `embra run` of that variant
        assert read(os.path.join(folder, "final.json")) == read(cli_runs[key] / "final.json"), key
        # the fabrication metrics of the last frame: the command's own record (%.17g: exact)
        with open(cli_runs[key] / "metrics.jsonl") as f:
            last = json.loads(f.read().splitlines()[-1])
        assert last["frame"] == FRAMES
        assert row["planarity_top_max"] == last["planarity_top_max"]
        assert row["planarity_bottom_max"] == last["planarity_bottom_max"]
        assert max(row["corner_distance_top_max"], row["corner_distance_bottom_max"]) == last["corner_distance_max"]
        assert row["thickness_max"] == last["thickness_error_max"]
        assert row["miter_max"] == last["miter_error_max"]
        assert row["conical_max"] == last["conical_defect_max"]
        assert row["corner_gap_max"] == last["corner_gap_max"]
        assert row["within_tolerance"] == last["within_tolerance"]
        assert row["settled"] == last["settled"]
    assert seen == set(cli_runs)


def test_same_bits_as_embra_run(client, cli_runs, tmp_path):
    out = tmp_path / "sweep"
    streamed = []
    rows = embra.sweep(example_sweep(), str(out), client=client, progress=None,
                       on_result=lambda record: streamed.append((record["name"], (out / record["name"]).is_dir())))
    check_against_cli(str(out), rows, cli_runs)
    # each variant was handed over once, its folder already written
    assert sorted(streamed) == [(f"v{i:04d}", True) for i in range(9)]
    # the tables hold one row per variant, in variant order, with both parameters
    with open(out / "results.jsonl") as f:
        table = [json.loads(line) for line in f]
    assert [r["name"] for r in table] == [f"v{i:04d}" for i in range(9)]
    assert [(r["draw_in"], r["thickness"]) for r in table] == [(d, t) for d in (0.05, 0.1, 0.15)
                                                                for t in (0.005, 0.01, 0.02)]
    header = (out / "results.csv").read_text().splitlines()[0].split(",")
    assert header[:6] == ["index", "name", "draw_in", "thickness", "status", "error"]
    assert "worst_ratio" in header and "miter_within" in header
    assert len((out / "results.csv").read_text().splitlines()) == 10
    # the pictures are PNG files
    for path in [out / "contact_sheet.png"] + [out / r["name"] / "thumbnail.png" for r in table]:
        assert read(path)[:8] == b"\x89PNG\r\n\x1a\n"

    # Re-running into the same folder runs nothing: no client is made (the scheduler address given
    # cannot be reached) and every file of every variant is as it was.
    before = {p: os.stat(p).st_mtime_ns for p in (out / r["name"] / "final.json" for r in table)}
    again = embra.sweep(example_sweep(), str(out), scheduler="tcp://127.0.0.1:9", progress=None)
    assert [r["name"] for r in again] == [r["name"] for r in rows]
    assert {p: os.stat(p).st_mtime_ns for p in before} == before


def test_killed_worker_loses_nothing(client, cli_runs, tmp_path):
    killed = {}

    def task_states(dask_scheduler):
        return {k: ts.state for k, ts in dask_scheduler.tasks.items() if str(k).startswith("embra-variant-")}

    def kill_one():
        # once a variant is done and another is in progress on a worker, that worker is ended by
        # SIGKILL: its nanny starts another, the scheduler runs its tasks again elsewhere
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            states = client.run_on_scheduler(task_states)
            busy = [(a, keys) for a, keys in client.processing().items() if keys]
            if busy and "memory" in states.values():
                addr, keys = busy[0]
                pid = client.run(os.getpid, workers=[addr])[addr]
                killed.update(pid=pid, tasks=list(keys))
                os.kill(pid, signal.SIGKILL)
                return
            if states and all(s in ("memory", "released", "forgotten") for s in states.values()) and len(states) == 9:
                return  # all done before a kill: the test fails below
            time.sleep(0.005)

    out = tmp_path / "sweep"
    killer = threading.Thread(target=kill_one)
    killer.start()
    try:
        rows = embra.sweep(example_sweep(), str(out), client=client, progress=None)
    finally:
        killer.join()
    assert killed and killed["tasks"], "no variant was in progress on a worker after the first had finished"
    check_against_cli(str(out), rows, cli_runs)
    # what the killed worker had in hand was run again by another process
    lost = [r for r in rows if any(k.startswith(f"embra-variant-{r['name']}-") for k in killed["tasks"])]
    assert lost and any(not r["worker"].endswith(f":{killed['pid']}") for r in lost)
    # the killed process is gone and the cluster has two workers again
    deadline = time.monotonic() + 60
    while len(client.scheduler_info()["workers"]) < 2 and time.monotonic() < deadline:
        time.sleep(0.2)
    pids = client.run(os.getpid)
    assert len(pids) == 2 and killed["pid"] not in pids.values()


def test_invalid_pointer_fails_before_anything_runs(tmp_path):
    class NoClient:
        def submit(self, *a, **k):
            raise AssertionError("a task was submitted")

    doc = example_sweep()
    doc["parameters"][0]["targets"][2] = {"pointer": "/actions/7/keys/1/value/0", "scale": 1.6, "offset": -1.6}
    out = tmp_path / "sweep"
    with pytest.raises(embra.SweepError) as e:
        embra.sweep(doc, str(out), client=NoClient(), progress=None)
    assert "/actions/7/keys/1/value/0" in str(e.value) and "draw_in" in str(e.value)
    assert "has 5 elements, no index 7" in str(e.value)
    assert not out.exists()

    doc = example_sweep()
    doc["parameters"][1]["targets"] = ["/panel_meshes/0/thicknes"]
    with pytest.raises(embra.SweepError, match="/panel_meshes/0/thicknes .*no member 'thicknes'"):
        embra.sweep(doc, str(out), client=NoClient(), progress=None)
    assert not out.exists()

    # the document itself is checked against schemas/sweep.schema.json first
    doc = example_sweep()
    doc["combine"] = "cross"
    with pytest.raises(embra.SweepError, match="/combine"):
        embra.sweep(doc, str(out), client=NoClient(), progress=None)
    doc = example_sweep()
    doc["run"] = {"frames": 10, "until": "settled"}  # one or the other
    with pytest.raises(embra.SweepError, match="/run"):
        embra.sweep(doc, str(out), client=NoClient(), progress=None)
    doc = example_sweep()
    doc["parameters"][1]["targets"] = ["panel_meshes/0/thickness"]  # not a JSON pointer
    with pytest.raises(embra.SweepError, match="/parameters/1/targets/0"):
        embra.sweep(doc, str(out), client=NoClient(), progress=None)
    assert not out.exists()

    # the command says the same and exits 2
    bad = tmp_path / "bad.sweep.json"
    doc = example_sweep()
    doc["parameters"][1]["targets"] = ["/panel_meshes/1/thickness"]
    bad.write_text(json.dumps(doc))
    p = subprocess.run([sys.executable, "-m", "embra.sweeps", str(bad), "--out", str(out)], capture_output=True,
                       text=True)
    assert p.returncode == 2 and "/panel_meshes/1/thickness" in p.stderr and "has 1 elements" in p.stderr
    assert not out.exists()


def test_failing_variant_is_recorded_and_the_sweep_goes_on(client, tmp_path):
    doc = example_sweep(frames=5)
    doc["parameters"] = [{"name": "thickness", "targets": ["/panel_meshes/0/thickness"], "values": [0.01, -0.01, 0.02]}]
    doc["keep"] = {"thumbnail": False}
    out = tmp_path / "sweep"
    rows = embra.sweep(doc, str(out), client=client, progress=None)
    assert [r["status"] for r in rows] == ["ok", "error", "ok"]
    assert "SchemaError" in rows[1]["error"] and "thickness" in rows[1]["error"]
    assert rows[1]["frames"] == 0
    assert [r["frames"] for r in rows] == [5, 0, 5]
    record = json.loads((out / "v0001" / "result.json").read_text())
    assert record["status"] == "error" and record["parameters"] == {"thickness": -0.01}
    assert not (out / "v0001" / "final.json").exists()
    assert (out / "v0002" / "final.json").exists()


def test_zip_and_range(tmp_path):
    doc = example_sweep()
    doc["combine"] = "zip"
    doc["parameters"][0].pop("values")
    doc["parameters"][0]["range"] = {"from": 0.0, "to": 0.2, "count": 5}
    doc["parameters"][1]["values"] = [0.01, 0.012, 0.014, 0.016, 0.018]
    sw = sweeps.Sweep(doc)
    assert [n for _, n, _ in sw.variants] == [f"v{i:04d}" for i in range(5)]
    assert [v["thickness"] for _, _, v in sw.variants] == [0.01, 0.012, 0.014, 0.016, 0.018]
    assert [v["draw_in"] for _, _, v in sw.variants] == [0.0, 0.05, 0.1, 0.15000000000000002, 0.2]
    scene = json.loads(sw.variant_scene(2))
    assert scene["actions"][0]["keys"][1]["value"][0] == 1.6 * 0.1 - 1.6
    assert scene["actions"][1]["keys"][1]["value"][0] == -1.6 * 0.1 + 1.6
    assert scene["panel_meshes"][0]["thickness"] == 0.014
    doc["parameters"][1]["values"] = [0.01]
    with pytest.raises(embra.SweepError, match="zip"):
        sweeps.Sweep(doc)
    # a grid too large to hold is refused before it is made: 1000^3 variants
    doc["combine"] = "product"
    doc["parameters"] = [{"name": f"p{i}", "targets": ["/solver/settle_speed"],
                          "range": {"from": 0.001, "to": 0.002, "count": 1000}} for i in range(3)]
    with pytest.raises(embra.SweepError, match="1000000000 variants: a sweep has at most 1000000"):
        sweeps.Sweep(doc)


def test_until_settled_same_bits_as_embra_run_until(client, tmp_path):
    """run {"until": "settled"}: World.solve in the worker, `embra run --until settled` in C (both
    embra_world_solve with the same frame budget): the same frames and the same final.json bytes."""
    doc = example_sweep()
    doc["combine"] = "zip"
    doc["parameters"][0]["values"] = [0.05, 0.1]
    doc["parameters"][1]["values"] = [0.01, 0.02]
    doc["run"] = {"until": "settled", "max_frames": 400}
    doc["keep"] = {"thumbnail": False}
    out = tmp_path / "sweep"
    rows = embra.sweep(doc, str(out), client=client, progress=None)
    for row, (d, t) in zip(rows, [(0.05, 0.01), (0.1, 0.02)]):
        scene = tmp_path / f"{row['name']}.json"
        scene.write_text(json.dumps(variant_scene(d, t)))
        ref = tmp_path / f"{row['name']}_cli"
        p = subprocess.run([os.environ["EMBRA_CLI"], "run", str(scene), "--until", "settled", "--frames", "400",
                            "--out", str(ref)], stdout=subprocess.PIPE, text=True)
        assert p.returncode in (0, 4), p.stdout
        assert row["status"] == "ok" and row["settled"] is (p.returncode == 0)
        # the scene's last action key is at frame 180: at rest before it does not count
        assert 180 < row["frames"] <= 400
        assert read(out / row["name"] / "final.json") == read(ref / "final.json")
        with open(ref / "metrics.jsonl") as f:
            assert json.loads(f.read().splitlines()[-1])["frame"] == row["frames"]


def test_the_schema_is_draft_07_and_the_example_follows_it():
    import jsonschema

    with open(os.path.join(SOURCE, "schemas", "sweep.schema.json")) as f:
        schema = json.load(f)
    jsonschema.Draft7Validator.check_schema(schema)  # a valid draft-07 schema itself
    repository_schema = os.path.join(SOURCE, "schemas", "sweep.schema.json")
    assert os.path.realpath(sweeps.schema_path()) == os.path.realpath(repository_schema)
    with open(EXAMPLE) as f:
        jsonschema.Draft7Validator(schema).validate(json.load(f))
    assert len(sweeps.Sweep.load(EXAMPLE).variants) == 9
