"""The scene schemas checked by an independent validator: Debian's python3-jsonschema.

Run with Debian's /usr/bin/python3 (where apt's python3-jsonschema installs):

  check_schemas.py --root REPO --embra EMBRA --work DIR [--generated DIR] [--api-scene FILE] SCENE.json...

1. Every schemas/*.schema.json is a valid draft-07 schema (Draft7Validator.check_schema).
2. Every SCENE (the examples and tests/scenes/valid) is valid against scene.schema.json, and its
   "tolerances", when present, against tolerances.schema.json; so is FILE (the scene the C-ABI
   round-trip test saved from a world built through the C ABI).
3. The invalid corpus (tests/scenes/invalid, manifest README.md) agrees with its classes: "syntax"
   files are not JSON to a strict parser, "schema" files parse and are rejected, "semantic" and
   "depth" files parse and are accepted (only embra's loader can refuse them). Rows whose file is
   not in the folder are in the --generated folder (written at test time), except the 100 MB
   nesting, which Python is not asked to parse.
4. `embra run` output: every line of metrics.jsonl is valid against metrics.schema.json, and
   final.json against scene.schema.json, for every SCENE (after 0 and after 30 frames).

Prints "N passed, N failed" last; exits non-zero on any failure.
"""

import argparse
import glob
import json
import os
import shutil
import subprocess
import sys

import jsonschema

passed = 0
failed = 0


def check(ok, what):
    global passed, failed
    if ok:
        passed += 1
    else:
        failed += 1
        print("FAIL: " + what)
    return ok


def refuse_constant(name):
    raise ValueError("not JSON: " + name)


def strict_load(data):
    """RFC 8259 JSON from bytes: strict UTF-8, no NaN/Infinity, nothing after the value."""
    return json.loads(data.decode("utf-8", errors="strict"), parse_constant=refuse_constant)


def first_error(validator, doc):
    errors = sorted(validator.iter_errors(doc), key=lambda e: list(e.absolute_path))
    if not errors:
        return None
    e = errors[0]
    return "/" + "/".join(str(p) for p in e.absolute_path) + ": " + e.message[:200]


def manifest_rows(path):
    rows = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            if not line.startswith("| `"):
                continue
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            rows.append((cells[0].strip("`"), cells[1], cells[2].strip("`"), cells[3].strip("`")))
    return rows


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--root", required=True)
    parser.add_argument("--embra", required=True)
    parser.add_argument("--work", required=True)
    parser.add_argument("--api-scene")
    parser.add_argument("--generated")
    parser.add_argument("scenes", nargs="+")
    args = parser.parse_args()
    schemas_dir = os.path.join(args.root, "schemas")

    # 1. The schemas themselves.
    schemas = {}
    for path in sorted(glob.glob(os.path.join(schemas_dir, "*.schema.json"))):
        with open(path, "rb") as f:
            schema = strict_load(f.read())
        try:
            jsonschema.Draft7Validator.check_schema(schema)
            check(True, path)
        except jsonschema.exceptions.SchemaError as e:
            check(False, "%s is not a valid draft-07 schema: %s" % (path, e.message))
        check(schema.get("$schema") == "http://json-schema.org/draft-07/schema#", path + " declares draft-07")
        schemas[os.path.basename(path)] = schema
    for name in ("scene.schema.json", "metrics.schema.json", "tolerances.schema.json"):
        if not check(name in schemas, "schemas/" + name + " exists"):
            return
    scene_v = jsonschema.Draft7Validator(schemas["scene.schema.json"])
    metrics_v = jsonschema.Draft7Validator(schemas["metrics.schema.json"])
    tolerances_v = jsonschema.Draft7Validator(schemas["tolerances.schema.json"])

    def check_scene(path, what):
        with open(path, "rb") as f:
            doc = strict_load(f.read())
        err = first_error(scene_v, doc)
        check(err is None, "%s %s is not valid against scene.schema.json: %s" % (what, path, err))
        if isinstance(doc, dict) and "tolerances" in doc:
            err = first_error(tolerances_v, doc["tolerances"])
            check(err is None, "%s %s: tolerances not valid against tolerances.schema.json: %s" % (what, path, err))

    # 2. Valid scenes.
    for path in args.scenes:
        check_scene(path, "scene")
    if args.api_scene:
        check_scene(args.api_scene, "the C-ABI world's saved scene")

    # 3. The invalid corpus.
    invalid_dir = os.path.join(args.root, "tests", "scenes", "invalid")
    rows = manifest_rows(os.path.join(invalid_dir, "README.md"))
    listed = {r[0] for r in rows}
    present = {os.path.basename(p) for p in glob.glob(os.path.join(invalid_dir, "*.json"))}
    check(present <= listed, "files missing from the manifest: %s" % sorted(present - listed))
    check(len(present) >= 40, "at least 40 invalid scenes (%d)" % len(present))
    counts = {}
    sys.setrecursionlimit(100000)  # the "depth" files nest thousands of levels
    for name, cls, pointer, fragment in rows:
        path = os.path.join(invalid_dir, name)
        if not os.path.exists(path) and args.generated:
            path = os.path.join(args.generated, name)
        if cls == "depth" and not os.path.exists(os.path.join(invalid_dir, name)):
            continue  # the generated 100 MB nesting: not parsed by Python
        if not check(os.path.exists(path), "%s is in neither the invalid folder nor --generated" % name):
            continue
        counts[cls] = counts.get(cls, 0) + 1
        with open(path, "rb") as f:
            data = f.read()
        try:
            doc = strict_load(data)
            parse_error = None
        except (ValueError, RecursionError) as e:  # JSONDecodeError and UnicodeDecodeError are ValueErrors
            doc, parse_error = None, str(e)[:120]
        if cls == "syntax":
            check(parse_error is not None, "%s (syntax): Python's strict parser accepts it" % name)
            continue
        if not check(parse_error is None, "%s (%s): Python cannot parse it: %s" % (name, cls, parse_error)):
            continue
        err = first_error(scene_v, doc)
        if cls == "schema":
            check(err is not None, "%s (schema): python jsonschema accepts it" % name)
        elif cls in ("semantic", "depth"):
            check(err is None, "%s (%s): python jsonschema rejects it: %s" % (name, cls, err))
        else:
            check(False, "%s: unknown class %r" % (name, cls))
    print("corpus classes: " + ", ".join("%s %d" % kv for kv in sorted(counts.items())))

    # 4. What `embra run` writes.
    os.makedirs(args.work, exist_ok=True)
    lines = 0
    for i, scene in enumerate(args.scenes):
        for frames in (0, 30):
            out = os.path.join(args.work, "run_%d_%s_%d" % (i, os.path.basename(scene)[:-5], frames))
            shutil.rmtree(out, ignore_errors=True)  # the work folder stays between runs; `run` refuses a non-empty --out
            r = subprocess.run([args.embra, "run", scene, "--frames", str(frames), "--out", out],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=120)
            if not check(r.returncode == 0, "embra run %s --frames %d exited %d: %s" %
                         (scene, frames, r.returncode, r.stderr.decode(errors="replace")[:300])):
                continue
            check_scene(os.path.join(out, "final.json"), "final.json of")
            with open(os.path.join(out, "metrics.jsonl"), "rb") as f:
                records = f.read().splitlines()
            check(len(records) == frames, "%s: metrics.jsonl has %d lines for %d frames" % (out, len(records), frames))
            for n, line in enumerate(records, 1):
                try:
                    record = strict_load(line)
                except ValueError as e:
                    check(False, "%s/metrics.jsonl line %d is not JSON: %s" % (out, n, e))
                    continue
                err = first_error(metrics_v, record)
                check(err is None, "%s/metrics.jsonl line %d: %s" % (out, n, err))
                lines += 1
    print("%d metrics records validated" % lines)


if __name__ == "__main__":
    main()
    print("%d passed, %d failed" % (passed, failed))
    sys.exit(1 if failed else 0)
