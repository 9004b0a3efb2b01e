"""Design-space sweeps on Dask: many variants of one scene, run on a LocalCluster or any cluster.

A sweep document (schemas/sweep.schema.json) names a base scene and parameters, each written at
JSON pointers into that scene, whose values combine into variants (product or zip). Each variant is
one Dask task that loads the variant scene into a World in its worker, runs it (frames, or
World.solve until settled or within tolerance) and returns its final scene, OBJ, per-frame metrics
and fabrication metrics; the client writes each variant's folder as its result arrives:

    DIR/v0003/scene.json      the variant scene (the base scene with this variant's values)
    DIR/v0003/final.json      the world after the run (what `embra run scene.json` writes, same bits)
    DIR/v0003/final.obj       the final shape
    DIR/v0003/metrics.jsonl   one record per frame (report and panel metrics)
    DIR/v0003/thumbnail.png   the final shape, coloured by the variant's worst metric
    DIR/v0003/result.json     parameters, outcome, frames, time, every fabrication metric (written last)
    DIR/results.jsonl, DIR/results.csv    one row per variant (appended as they finish, sorted at the end)
    DIR/contact_sheet.png     every variant's final shape ranked by its worst metric

From a shell: ``embra-sweep SWEEP.json [--scheduler ADDRESS] [--workers N] [--out DIR]`` (the wheel's
console script) or ``python3 -m embra.sweeps ...``; from Python: ``embra.sweep(path, out)``
(this module's sweep(), Sweep and SweepError are also embra's).

Nothing runs until the document is valid against its schema, its base scene is read and every
pointer names a value that exists in that scene (SweepError names the first that does not). A
variant whose scene the library refuses, or whose step fails, is recorded with its error and the
sweep goes on. A worker that dies mid-variant loses nothing: Dask runs the task again on another
worker, and as a variant's result depends only on its scene and run settings, it is the same bits.
Re-running into the same DIR skips every variant whose folder holds a result.json of the same
variant scene, run settings and library version.

The client needs dask.distributed (Debian: python3-distributed) and jsonschema (python3-jsonschema),
and matplotlib (python3-matplotlib) for the pictures; workers need only this package and libembra.
"""

import argparse
import copy
import csv
import hashlib
import io
import json
import math
import os
import shutil
import sys
import time

SCHEMA_NAME = "sweep.schema.json"

# The tolerance each panel metric is judged against (embra.h, embra_panel_metrics and
# embra_tolerances); the metrics without one (diagonal, conical, the welds' corner gap) are reported
# without a verdict, as embra_panel_mesh_get_metrics counts them against 0.
METRIC_TOLERANCE = {
    "planarity_top": "planarity",
    "planarity_bottom": "planarity",
    "corner_distance_top": "planarity_distance",
    "corner_distance_bottom": "planarity_distance",
    "thickness": "thickness",
    "miter": "miter",
}


MAX_VARIANTS = 1000000  # variants of one sweep: each is a task, a folder and a row


class SweepError(ValueError):
    """A sweep document that cannot run: its schema, its base scene or a pointer (named)."""


# --- the sweep document ------------------------------------------------------------------------
def schema_path():
    """The sweep schema: beside this module when installed, else the repository's schemas/."""
    here = os.path.dirname(os.path.abspath(__file__))
    for path in (os.path.join(here, SCHEMA_NAME),
                 os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(here))), "schemas", SCHEMA_NAME)):
        if os.path.isfile(path):
            return path
    raise SweepError(f"{SCHEMA_NAME} not found beside {here} nor in the repository's schemas/")


def _validate(doc):
    import jsonschema

    with open(schema_path()) as f:
        schema = json.load(f)
    validator = jsonschema.Draft7Validator(schema)
    errors = sorted(validator.iter_errors(doc), key=lambda e: list(e.absolute_path))
    if errors:
        e = errors[0]
        where = "/" + "/".join(str(p) for p in e.absolute_path)
        raise SweepError(f"sweep document {where}: {e.message}")


def _pointer_tokens(pointer):
    return [t.replace("~1", "/").replace("~0", "~") for t in pointer.split("/")[1:]]


def _resolve(doc, pointer):
    """(container, key) of the value `pointer` names in doc; KeyError naming what is missing."""
    node = doc
    tokens = _pointer_tokens(pointer)
    for depth, token in enumerate(tokens):
        where = "/" + "/".join(tokens[:depth]) if depth else "the document's root"
        if isinstance(node, dict):
            if token not in node:
                raise KeyError(f"{where} has no member '{token}'")
            key = token
        elif isinstance(node, list):
            if not (token.isdigit() and (token == "0" or not token.startswith("0"))):
                raise KeyError(f"{where} is an array: '{token}' is not an index")
            key = int(token)
            if key >= len(node):
                raise KeyError(f"{where} has {len(node)} elements, no index {key}")
        else:
            raise KeyError(f"{where} is a {type(node).__name__}, not an object or array")
        if depth == len(tokens) - 1:
            return node, key
        node = node[key]
    raise KeyError("the pointer names the whole document")


def _values(param):
    if "values" in param:
        return list(param["values"])
    r = param["range"]
    n, a, b = r["count"], r["from"], r["to"]
    return [a] if n == 1 else [a + i * (b - a) / (n - 1) for i in range(n)]


def _written(target, value):
    if isinstance(target, str):
        return target, value
    scale, offset = target.get("scale", 1), target.get("offset", 0)
    if "scale" not in target and "offset" not in target:
        return target["pointer"], value
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SweepError(f"{target['pointer']}: scale and offset need numeric values, got {json.dumps(value)}")
    return target["pointer"], scale * value + offset


class Sweep:
    """A validated sweep: the document, its base scene (parsed) and the variants it makes.

    variants: a list of (index, name, {parameter name: value}). variant_scene(i) is the text of
    variant i's scene: the base scene with the values written at their pointers."""

    def __init__(self, doc, base_dir="."):
        _validate(doc)
        self.doc = doc
        self.name = doc.get("name", "sweep")
        scene_path = doc["scene"]
        if not os.path.isabs(scene_path):
            scene_path = os.path.join(base_dir, scene_path)
        self.scene_path = os.path.abspath(scene_path)
        self.scene_dir = os.path.dirname(self.scene_path)
        try:
            with open(self.scene_path, "rb") as f:
                self.scene = json.loads(f.read())
        except (OSError, ValueError) as e:
            raise SweepError(f"scene {doc['scene']}: {e}") from None
        self.parameters = doc["parameters"]
        names = [p["name"] for p in self.parameters]
        for n in names:
            if names.count(n) > 1:
                raise SweepError(f"parameters: the name '{n}' is used twice")
        for p in self.parameters:
            for t in p["targets"]:
                pointer = t if isinstance(t, str) else t["pointer"]
                try:
                    _resolve(self.scene, pointer)
                except KeyError as e:
                    raise SweepError(f"parameter '{p['name']}': the pointer {pointer} does not resolve in "
                                     f"{doc['scene']}: {e.args[0]}") from None
        value_lists = [_values(p) for p in self.parameters]
        count = len(value_lists[0]) if doc.get("combine", "product") == "zip" else math.prod(map(len, value_lists))
        if count > MAX_VARIANTS:
            raise SweepError(f"{count} variants: a sweep has at most {MAX_VARIANTS} (split it, or use fewer values)")
        combos = []
        if doc.get("combine", "product") == "zip":
            counts = {len(v) for v in value_lists}
            if len(counts) != 1:
                raise SweepError("combine zip: every parameter needs as many values (" +
                                 ", ".join(f"{p['name']}: {len(v)}" for p, v in zip(self.parameters, value_lists)) +
                                 ")")
            combos = [list(c) for c in zip(*value_lists)]
        else:
            combos = [[]]
            for values in value_lists:
                combos = [c + [v] for c in combos for v in values]
        width = max(4, len(str(len(combos) - 1)))
        self.variants = [(i, f"v{i:0{width}d}", dict(zip(names, c))) for i, c in enumerate(combos)]
        for p in self.parameters:  # scale/offset on a non-number: refused before anything runs
            for t in p["targets"]:
                for v in _values(p):
                    _written(t, v)
        self.run = dict(doc.get("run", {}))
        self.keep = {"metrics": True, "final_scene": True, "obj": True, "thumbnail": True}
        self.keep.update(doc.get("keep", {}))

    @classmethod
    def load(cls, path):
        try:
            with open(path, "rb") as f:
                doc = json.loads(f.read())
        except (OSError, ValueError) as e:
            raise SweepError(f"{path}: {e}") from None
        return cls(doc, os.path.dirname(os.path.abspath(path)))

    def variant_scene(self, index):
        _, _, values = self.variants[index]
        scene = copy.deepcopy(self.scene)
        for p in self.parameters:
            for t in p["targets"]:
                pointer, value = _written(t, values[p["name"]])
                container, key = _resolve(scene, pointer)
                container[key] = value
        return json.dumps(scene, indent=1) + "\n"


# --- one variant, in a worker --------------------------------------------------------------------
def _panel_bodies(world):
    from .errors import InvalidArgumentError

    bodies = []
    for b in world.bodies():
        try:
            world.panel_count(b)
        except InvalidArgumentError:
            continue
        bodies.append(b)
    return bodies


def fabrication_metrics(world, bodies=None):
    """Every panel metric over every panel mesh (the largest over meshes), each judged metric with
    whether it is within its tolerance target, and the worst (value / target). None without a
    panel mesh."""
    from ._capi import MetricSummary

    bodies = _panel_bodies(world) if bodies is None else bodies
    if not bodies:
        return None
    tol = world.tolerances
    names = [n for n, t in type(world.panel_metrics(bodies[0]))._fields_ if t is MetricSummary]
    out = {"within_tolerance": True, "worst_metric": None, "worst_ratio": 0.0}
    for n in names + ["corner_gap"]:
        out[f"{n}_max"] = 0.0
        if n in METRIC_TOLERANCE:
            out[f"{n}_within"] = True
    for b in bodies:
        m = world.panel_metrics(b)
        out["within_tolerance"] = out["within_tolerance"] and m.within_tolerance == 1
        for n in names:
            s = getattr(m, n)
            out[f"{n}_max"] = max(out[f"{n}_max"], s.max)
            if n in METRIC_TOLERANCE:
                out[f"{n}_within"] = out[f"{n}_within"] and s.within_target == s.count
        out["corner_gap_max"] = max(out["corner_gap_max"], world.corner_gap(b).max)
    for n, t in METRIC_TOLERANCE.items():
        target = getattr(tol, t).target
        v = out[f"{n}_max"]
        # a target of 0 met only by 0: any error above it ranks as the largest ratio JSON can hold
        ratio = v / target if target > 0 else (sys.float_info.max if v > 0 else 0.0)
        if out["worst_metric"] is None or ratio > out["worst_ratio"]:
            out["worst_metric"], out["worst_ratio"] = n, ratio
    return out


def _frame_record(world, bodies):
    r = world.report()
    rec = {"frame": r.frame, "time": r.time, "residual_max": r.residual_max, "residual_rms": r.residual_rms,
           "kinetic_energy": r.kinetic_energy, "max_speed": r.max_speed, "contacts": r.contact_count,
           "settled": r.settled == 1}
    m = fabrication_metrics(world, bodies)
    if m is not None:
        rec.update(m)
    return rec


def run_variant(task):
    """Runs one variant (a Dask task; any process with this package and libembra). task: index,
    name, key, scene (text), base_dir, run, keep. Returns a dict: status "ok" or "error" (with
    error), settled, outcome, frames, seconds, the final scene, OBJ and metrics as kept, and the
    fabrication metrics. A refused scene or a failed step is an "error" result, never an exception."""
    import socket

    from . import World

    t0, cpu0 = time.perf_counter(), time.process_time()
    out = {"index": task["index"], "name": task["name"], "key": task["key"], "status": "ok", "error": None,
           "settled": None, "outcome": None, "frames": 0, "worker": f"{socket.gethostname()}:{os.getpid()}"}
    run, keep = task["run"], task["keep"]
    world = None
    records = []
    try:
        world = World.load_json(task["scene"], task["base_dir"])
        bodies = _panel_bodies(world)
        start = world.report().frame
        try:
            if "until" in run:
                solved = world.solve(until=run["until"], max_frames=run.get("max_frames"),
                                     hold_frames=run.get("hold_frames"))
                out["settled"], out["outcome"] = solved.settled, solved.outcome
                if keep["metrics"]:
                    records.append(_frame_record(world, bodies))
            else:
                frames = run["frames"] if "frames" in run else world.scene_frames()
                for _ in range(frames):
                    world.step(1)
                    if keep["metrics"]:
                        records.append(_frame_record(world, bodies))
                out["settled"] = world.report().settled == 1
                out["outcome"] = "settled" if out["settled"] else "moving"
        except Exception as e:  # a failed step: the world is as before that frame; keep what there is
            out["status"], out["error"] = "error", f"{type(e).__name__}: {e}"
        out["frames"] = world.report().frame - start
        out["metrics"] = fabrication_metrics(world, bodies)
        if keep["final_scene"]:
            out["final_json"] = world.save_json()
        if keep["obj"] or keep["thumbnail"]:
            out["final_obj"] = world.export_obj()
    except Exception as e:  # the scene was refused (schema, a bad value: nothing ran), or reading back failed
        out["status"], out["error"] = "error", f"{type(e).__name__}: {e}"
        out["metrics"] = None
    finally:
        if world is not None:
            world.close()
    if keep["metrics"]:
        out["metrics_jsonl"] = "".join(json.dumps(r) + "\n" for r in records)
    out["seconds"] = time.perf_counter() - t0
    out["cpu_seconds"] = time.process_time() - cpu0  # below seconds when the machine's cores are shared
    return out


# --- the client: results as they arrive ----------------------------------------------------------
def _key(sweep, index, scene_text, version):
    h = hashlib.sha256()
    for part in (scene_text, json.dumps(sweep.run, sort_keys=True), sweep.scene_dir, version):
        h.update(part.encode())
        h.update(b"\0")
    return h.hexdigest()


def _row(sweep, result, values):
    """The flat record of results.jsonl / results.csv."""
    row = {"index": result["index"], "name": result["name"]}
    row.update(values)
    for k in ("status", "error", "settled", "outcome", "frames", "seconds", "cpu_seconds", "worker"):
        row[k] = result.get(k)
    m = result.get("metrics") or {}
    for k, v in m.items():
        row[k] = v
    return row


def _columns(sweep, rows):
    cols = ["index", "name"] + [p["name"] for p in sweep.parameters]
    cols += ["status", "error", "settled", "outcome", "frames", "seconds", "cpu_seconds", "worker"]
    for r in rows:
        for k in r:
            if k not in cols:
                cols.append(k)
    return cols


def _csv_value(v):
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, (int, str)):
        return v
    return json.dumps(v)


def _write_tables(out, sweep, rows):
    rows = sorted(rows, key=lambda r: r["index"])
    cols = _columns(sweep, rows)
    for name, write in (("results.jsonl", lambda f: f.writelines(json.dumps(r) + "\n" for r in rows)),
                        ("results.csv", lambda f: _csv_rows(f, cols, rows))):
        tmp = os.path.join(out, f".{name}.tmp")
        with open(tmp, "w", newline="") as f:
            write(f)
        os.replace(tmp, os.path.join(out, name))


def _csv_rows(f, cols, rows):
    w = csv.writer(f)
    w.writerow(cols)
    for r in rows:
        w.writerow([_csv_value(r.get(c)) for c in cols])


def _write_variant(out, sweep, scene_text, result, values):
    """The variant's folder, written whole under a temporary name and renamed: a folder with a
    result.json is complete. (The worker's figures: seconds of wall time, cpu_seconds of its
    process's CPU time over the run.)"""
    final = os.path.join(out, result["name"])
    tmp = final + ".partial"
    shutil.rmtree(tmp, ignore_errors=True)
    os.makedirs(tmp)
    with open(os.path.join(tmp, "scene.json"), "w") as f:
        f.write(scene_text)
    if "final_json" in result:
        with open(os.path.join(tmp, "final.json"), "w") as f:
            f.write(result["final_json"])
    if sweep.keep["obj"] and "final_obj" in result:
        with open(os.path.join(tmp, "final.obj"), "w") as f:
            f.write(result["final_obj"])
    if "metrics_jsonl" in result:
        with open(os.path.join(tmp, "metrics.jsonl"), "w") as f:
            f.write(result["metrics_jsonl"])
    if sweep.keep["thumbnail"] and "final_obj" in result:
        render_png(os.path.join(tmp, "thumbnail.png"), [(result, values, result["final_obj"])], columns=1)
    record = {k: v for k, v in result.items() if k not in ("final_json", "final_obj", "metrics_jsonl")}
    record["parameters"] = values
    with open(os.path.join(tmp, "result.json"), "w") as f:
        json.dump(record, f, indent=1)
        f.write("\n")
    if os.path.exists(final):
        shutil.rmtree(final)
    os.replace(tmp, final)
    return record


def _done(out, name, key):
    try:
        with open(os.path.join(out, name, "result.json")) as f:
            record = json.load(f)
    except (OSError, ValueError):
        return None
    return record if record.get("key") == key else None


class _Progress:
    def __init__(self, total, stream):
        self.total, self.stream, self.t0 = total, stream, time.perf_counter()
        self.done = self.failed = self.skipped = 0
        self.tty = hasattr(stream, "isatty") and stream.isatty()

    def update(self, result=None, skipped=False):
        if result is not None:
            self.done += 1
            self.failed += result["status"] != "ok"
            self.skipped += skipped
        if self.stream is None:
            return
        elapsed = time.perf_counter() - self.t0
        ran = self.done - self.skipped
        left = self.total - self.done
        eta = f", ~{elapsed / ran * left:.0f} s left" if ran and left else ""
        width = 30
        bar = "#" * (width * self.done // max(self.total, 1))
        line = (f"embra-sweep [{bar:<{width}}] {self.done}/{self.total} ({self.failed} failed, {self.skipped} "
                f"skipped) {elapsed:.1f} s{eta}")
        if self.tty:
            self.stream.write("\r\033[K" + line + ("\n" if left == 0 else ""))
        else:
            self.stream.write(line + "\n")
        self.stream.flush()


def sweep(document, out="sweep_out", *, scheduler=None, workers=None, client=None, progress=sys.stderr,
          on_result=None, base_dir="."):
    """Runs a sweep and returns its rows (one dict per variant, in variant order).

    document: a sweep file's path, or the parsed document (its scene relative to `base_dir`).
    out: the results folder (made if missing; variants already done there are skipped).
    scheduler: a Dask scheduler address ("tcp://host:8786"); else client: a distributed.Client;
    else a LocalCluster of `workers` worker processes (default: one per core) of one thread each.
    progress: a stream for the progress line, or None. on_result(record): called in the client as
    each variant's folder has been written (the record also written to its result.json)."""
    from . import version_string

    sw = Sweep.load(document) if isinstance(document, (str, os.PathLike)) else Sweep(document, base_dir)
    os.makedirs(out, exist_ok=True)
    version = version_string()
    texts = [sw.variant_scene(i) for i, _, _ in sw.variants]
    keys = [_key(sw, i, texts[i], version) for i, _, _ in sw.variants]
    bar = _Progress(len(sw.variants), progress)
    rows, records, objs = [], {}, {}
    todo = []
    for (i, name, values), text, key in zip(sw.variants, texts, keys):
        record = _done(out, name, key)
        if record is None:
            todo.append(i)
            continue
        records[i] = record
        rows.append(_row(sw, record, values))
        bar.update(record, skipped=True)
    _write_tables(out, sw, rows)
    if todo:
        own_cluster = own_client = None
        try:
            if client is None:
                from distributed import Client, LocalCluster

                if scheduler:
                    client = own_client = Client(scheduler)
                else:
                    n = workers or os.cpu_count() or 1
                    # one single-threaded process per variant at a time; the scheduler's web page on a
                    # free port of this machine only (not 8787 on every interface)
                    own_cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                               dashboard_address="127.0.0.1:0")
                    client = own_client = Client(own_cluster)
            _run(sw, out, client, todo, texts, keys, rows, records, objs, bar, on_result)
        finally:
            if own_client is not None:
                own_client.close()
            if own_cluster is not None:
                own_cluster.close()
    _write_tables(out, sw, rows)
    if sw.keep["thumbnail"]:
        sheet = [(records[i], sw.variants[i][2], objs.get(i) or _obj_text(out, records[i]["name"]))
                 for i in sorted(records)]
        if sheet:
            render_png(os.path.join(out, "contact_sheet.png"), rank(sheet), title=sw.name)
    return sorted(rows, key=lambda r: r["index"])


def _run(sw, out, client, todo, texts, keys, rows, records, objs, bar, on_result):
    from distributed import as_completed

    futures = {}
    for i in todo:
        _, name, _ = sw.variants[i]
        task = {"index": i, "name": name, "key": keys[i], "scene": texts[i], "base_dir": sw.scene_dir,
                "run": sw.run, "keep": sw.keep}
        f = client.submit(run_variant, task, key=f"embra-variant-{name}-{keys[i][:16]}", pure=False)
        futures[f] = i
    jsonl = open(os.path.join(out, "results.jsonl"), "a")
    try:
        for f in as_completed(list(futures)):
            i = futures[f]
            _, name, values = sw.variants[i]
            try:
                result = f.result()
            except Exception as e:  # the task itself was lost (workers died too often): run it again later
                result = {"index": i, "name": name, "key": None, "status": "error",
                          "error": f"{type(e).__name__}: {e}", "frames": 0, "metrics": None}
                row = _row(sw, result, values)
                rows.append(row)
                bar.update(result)
                continue
            record = _write_variant(out, sw, texts[i], result, values)
            records[i] = record
            objs[i] = None if sw.keep["obj"] else result.get("final_obj")  # else read back for the sheet
            row = _row(sw, record, values)
            rows.append(row)
            jsonl.write(json.dumps(row) + "\n")
            jsonl.flush()
            bar.update(record)
            if on_result is not None:
                on_result(record)
    finally:
        jsonl.close()


# --- pictures ------------------------------------------------------------------------------------
def rank(items):
    """(record, values, ...) tuples best first: succeeded before failed, then by worst metric (value /
    target), then by index."""
    def key(item):
        r = item[0]
        m = r.get("metrics") or {}
        return (r["status"] != "ok", m.get("worst_ratio", math.inf), r["index"])

    return sorted(items, key=key)


def _read_obj(text):
    verts, faces = [], []
    for line in io.StringIO(text):
        p = line.split()
        if not p:
            continue
        if p[0] == "v":
            verts.append([float(c) for c in p[1:4]])
        elif p[0] == "f":
            faces.append([int(c.split("/")[0]) - 1 for c in p[1:]])
    return verts, faces


def _obj_text(out, name):
    try:
        with open(os.path.join(out, name, "final.obj")) as f:
            return f.read()
    except OSError:
        return None


def render_png(path, items, columns=None, title=None):
    """Draws each (record, values, OBJ text or None) as its final shape, every face in the colour of the record's worst
    metric over its target (log scale: 1 and below at the scale's start, 100 and above at its end),
    labelled with its rank, name, values and worst metric; a failed variant as its error."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import cm, colors
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    n = len(items)
    columns = columns or min(n, max(1, math.ceil(math.sqrt(n))))
    rows = math.ceil(n / columns)
    single = n == 1
    fig = plt.figure(figsize=(2.6 * columns + (0 if single else 0.8), 2.8 * rows + (0.4 if title else 0)), dpi=100)
    cmap = matplotlib.colormaps["RdYlGn_r"]
    norm = colors.Normalize(vmin=0.0, vmax=2.0)  # log10(value / target)
    for k, (record, values, text) in enumerate(items):
        ax = fig.add_subplot(rows, columns, k + 1, projection="3d")
        ax.set_axis_off()
        m = record.get("metrics") or {}
        ratio = m.get("worst_ratio")
        label = ("" if single else f"#{k + 1} ") + record["name"]
        label += "".join(f"\n{a} = {_short(v)}" for a, v in values.items())
        if record["status"] != "ok":
            label += f"\nfailed: {record['error'][:60]}"
        if ratio is not None:
            label += f"\nworst {m['worst_metric']}: {ratio:.3g} x target"
        if text:
            verts, faces = _read_obj(text)
            if verts and faces:
                colour = cmap(norm(math.log10(max(ratio, 1.0)) if ratio is not None else 2.0))
                polys = [[verts[i] for i in f] for f in faces]
                poly = Poly3DCollection(polys, facecolor=[_shade(colour, p) for p in polys],
                                        edgecolor=(0, 0, 0, 0.25), linewidth=0.2)
                ax.add_collection3d(poly)
                xs, ys, zs = zip(*verts)
                extent = [max(a) - min(a) for a in (xs, ys, zs)]
                size = max(extent) or 1.0
                extent = [max(e, 0.05 * size) for e in extent]  # a flat shape keeps some depth
                for lim, a, e in ((ax.set_xlim, xs, extent[0]), (ax.set_ylim, ys, extent[1]),
                                  (ax.set_zlim, zs, extent[2])):
                    c = (max(a) + min(a)) / 2
                    lim(c - e / 2, c + e / 2)
                ax.set_box_aspect(extent, zoom=1.05)  # true proportions
                ax.view_init(elev=30, azim=-60)
        ax.set_title(label, fontsize=7)
    if title:
        fig.suptitle(f"{title}: ranked by worst fabrication metric (value / target)", fontsize=9)
    if single:
        fig.subplots_adjust(left=0.0, right=1.0, bottom=0.0, top=0.78)
    else:
        fig.subplots_adjust(left=0.01, right=0.9, bottom=0.01, top=0.88 if title else 0.93, wspace=0.02, hspace=0.3)
        cax = fig.add_axes([0.93, 0.15, 0.015, 0.7])
        bar = fig.colorbar(cm.ScalarMappable(norm=norm, cmap=cmap), cax=cax)
        bar.set_ticks([0, 1, 2])
        bar.set_ticklabels(["<= 1", "10", ">= 100"])
        bar.set_label("worst metric / target", fontsize=7)
        bar.ax.tick_params(labelsize=7)
    tmp = path + ".tmp.png"
    fig.savefig(tmp)
    plt.close(fig)
    os.replace(tmp, path)


def _shade(colour, poly):
    """colour lit by a light above and to the side: 0.45 + 0.55 |n . l| of the face's normal."""
    (ax, ay, az), (bx, by, bz), (cx, cy, cz) = poly[0], poly[1], poly[2]
    ux, uy, uz, vx, vy, vz = bx - ax, by - ay, bz - az, cx - ax, cy - ay, cz - az
    n = (uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx)
    length = math.sqrt(sum(c * c for c in n)) or 1.0
    light = (-0.4, -0.5, 0.768)
    f = 0.45 + 0.55 * abs(sum(a * b for a, b in zip(n, light))) / length
    return (colour[0] * f, colour[1] * f, colour[2] * f, 1.0)


def _short(v):
    return f"{v:.6g}" if isinstance(v, float) else json.dumps(v)


# --- the command ---------------------------------------------------------------------------------
def main(argv=None):
    p = argparse.ArgumentParser(
        prog="embra-sweep", usage="embra-sweep SWEEP.json [--scheduler ADDRESS] [--workers N] [--out DIR]",
        description="Runs a design-space sweep (schemas/sweep.schema.json) on Dask: a LocalCluster, or the "
        "scheduler given.")
    p.add_argument("sweep", help="the sweep document (JSON)")
    p.add_argument("--scheduler", help="a Dask scheduler's address, e.g. tcp://10.0.0.5:8786 (default: a LocalCluster)")
    p.add_argument("--workers", type=int, help="LocalCluster worker processes (default: one per core)")
    p.add_argument("--out", default="sweep_out", help="the results folder (default: sweep_out)")
    a = p.parse_args(argv)
    if a.workers is not None and a.workers < 1:
        p.error("--workers must be at least 1")
    try:
        rows = sweep(a.sweep, a.out, scheduler=a.scheduler, workers=a.workers)
    except SweepError as e:
        print(f"embra-sweep: {e}", file=sys.stderr)
        return 2
    failed = sum(r["status"] != "ok" for r in rows)
    written = [os.path.join(a.out, name) for name in ("results.csv", "contact_sheet.png")
               if os.path.isfile(os.path.join(a.out, name))]
    print(f"embra-sweep: {len(rows)} variants, {failed} failed: {', '.join(written)}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
