#!/usr/bin/env bash
# The `embra` command's contract: exit codes, and the tent demo's output checked against what it
# promises (vertex and face counts, finite coordinates, the hard-pinned corners exactly at their
# targets: 90% of the unit triangle's corners, at z = 0).
set -u
embra="$1"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passed=0
failed=0
ok() { passed=$((passed + 1)); }
bad() { echo "FAIL: $*"; failed=$((failed + 1)); }

"$embra" version >/dev/null && ok || bad "embra version exits non-zero"
"$embra" >/dev/null 2>&1; [ $? -eq 1 ] && ok || bad "no arguments must exit 1 (usage)"
"$embra" demo tent --frames >/dev/null 2>&1; [ $? -eq 1 ] && ok || bad "a flag without value must exit 1"
"$embra" demo tent --n 1 >/dev/null 2>&1; [ $? -eq 1 ] && ok || bad "--n 1 must exit 1"
"$embra" demo tent --out /proc/embra-cannot-write >/dev/null 2>&1; [ $? -eq 2 ] && ok || bad "an unwritable --out must exit 2"
# A usage error names what is wrong before the usage.
"$embra" demo tent --frames abc 2>&1 | head -1 | grep -q "^embra: --frames: expected a whole number from 0 to 100000000, got 'abc'$" \
  && ok || bad "--frames abc is not named"
"$embra" run scene.json --fram 3 2>&1 | head -1 | grep -q "^embra: unknown option '--fram' for run" && ok || bad "--fram is not named"
"$embra" frobnicate 2>&1 | head -1 | grep -q "^embra: unknown command 'frobnicate'" && ok || bad "an unknown command is not named"
"$embra" help | grep -q "^Exit codes:" && ok || bad "embra help must print the help on stdout"
# `embra sweep` is the command embra-sweep from PATH, its arguments passed as they are.
mkdir -p "$tmp/bin" "$tmp/nobin"
printf '#!/bin/sh\nprintf "%%s|" "$0" "$@"; exit 7\n' >"$tmp/bin/embra-sweep"
chmod +x "$tmp/bin/embra-sweep"
out=$(PATH="$tmp/bin" "$embra" sweep "a b.json" --workers 2 --out o)
[ $? -eq 7 ] && [ "$out" = "$tmp/bin/embra-sweep|a b.json|--workers|2|--out|o|" ] && ok ||
  bad "embra sweep must run embra-sweep with its arguments: '$out'"
PATH="$tmp/nobin" "$embra" sweep x.json >/dev/null 2>"$tmp/err"; [ $? -eq 1 ] && ok || bad "embra sweep without embra-sweep must exit 1"
grep -q "^embra: sweep runs the command embra-sweep (No such file or directory)" "$tmp/err" && ok ||
  bad "embra sweep without embra-sweep must say what to install: $(cat "$tmp/err")"

rows=10
"$embra" demo tent --frames 90 --every 30 --n $rows --out "$tmp/tent" >"$tmp/log" 2>&1 && ok || bad "demo tent failed: $(cat "$tmp/log")"
for f in frame_00030.obj frame_00060.obj frame_00090.obj final.obj; do
  [ -s "$tmp/tent/$f" ] && ok || bad "missing $f"
done
# (rows+1)(rows+2)/2 vertices, rows^2 faces, all finite; corners 0, rows, last row at 0.9 x start.
awk -v rows=$rows '
  /^v / { n++; x[n-1]=$2; y[n-1]=$3; z[n-1]=$4
          for (k = 2; k <= 4; k++) if ($k != $k + 0 || $k ~ /nan|inf/) bad = 1 }
  /^f / { f++ }
  END {
    nv = (rows + 1) * (rows + 2) / 2
    if (n != nv || f != rows * rows) { print "counts " n " " f; exit 1 }
    if (bad) { print "non-finite coordinate"; exit 1 }
    h = sqrt(3) / 2
    cx[0] = -0.5; cy[0] = -h / 3; cx[1] = 0.5; cy[1] = -h / 3; cx[2] = 0; cy[2] = 2 * h / 3
    idx[0] = 0; idx[1] = rows; idx[2] = nv - 1
    for (k = 0; k < 3; k++) {
      i = idx[k]; dx = x[i] - 0.9 * cx[k]; dy = y[i] - 0.9 * cy[k]
      d = sqrt(dx * dx + dy * dy + z[i] * z[i])
      if (d > 1e-12) { print "corner " k " is " d " m from its pin target"; exit 1 }
    }
    top = -1; for (i = 0; i < n; i++) if (z[i] > top) top = z[i]
    if (top <= 0) { print "reversed gravity must lift the membrane, apex " top; exit 1 }
  }' "$tmp/tent/final.obj" && ok || bad "final.obj does not match the tent's geometry"

# --until: why the stepping stopped. A 1 m pendulum let go 0.1 rad from the vertical with no
# damping never comes to rest: exit 4, oscillating with the small-angle period
# 2 pi sqrt(1 / 9.81) (1 + 0.1^2 / 16) = 2.0073 s, to 1 %. A damped 8-link chain between two pins
# comes to rest: exit 0. An unknown --until value is a usage error.
"$embra" run "$tmp/none.json" --until forever >/dev/null 2>&1; [ $? -eq 1 ] && ok || bad "--until forever must exit 1"
# An unsettled run names what fights: a cable's top held by two soft pins 1 m apart, each in its own
# group, swinging (no damping): the two pins first, then the pair of groups, 500 N apart.
cat >"$tmp/fight.json" <<'JSON'
{"format": "embra-scene", "version": 1, "name": "fight", "frames": 120,
 "groups": [{"name": "left", "order": 1}, {"name": "right", "order": 2}],
 "bodies": [{"name": "cable", "mesh": {"vertices": [[0, 0, 0], [0, 0, -0.1], [0, 0, -0.2], [0, 0, -0.3]]}, "generate": []}],
 "constraints": [{"kind": "distance", "particles": [[0, 1], [1, 2], [2, 3]]}],
 "pins": [{"name": "a", "particle": {"body": "cable", "vertex": 0}, "target": [-0.5, 0, 0], "compliance": 0.001, "group": "left"},
          {"name": "b", "particle": {"body": "cable", "vertex": 0}, "target": [0.5, 0, 0], "compliance": 0.001, "group": "right"}]}
JSON
"$embra" run "$tmp/fight.json" --out "$tmp/fight" >"$tmp/log" 2>&1 && ok || bad "the fight scene must run: $(cat "$tmp/log")"
grep -q "^fighting  *pin [0-9]* on particle 0 of group" "$tmp/log" && ok || bad "no fighting pin named: $(cat "$tmp/log")"
grep -q "^groups fighting  *groups 2 and 3 pull against each other: 4\.9[0-9]*e+02 N\|^groups fighting  *groups 2 and 3 pull against each other: 5\.0[0-9]*e+02 N" "$tmp/log" \
  && ok || bad "the two groups are not named first at about 500 N: $(cat "$tmp/log")"
cat >"$tmp/pendulum.json" <<'JSON'
{"format": "embra-scene", "version": 1, "name": "pendulum",
 "bodies": [{"name": "p", "mesh": {"vertices": [[0, 0, 0], [0.09983341664682815, 0, -0.9950041652780258]],
             "masses": [0, 1]}, "generate": []}],
 "constraints": [{"kind": "distance", "particles": [[0, 1]]}]}
JSON
"$embra" run "$tmp/pendulum.json" --until settled --frames 900 --out "$tmp/pendulum" >"$tmp/log" 2>&1
[ $? -eq 4 ] && ok || bad "a swinging pendulum must exit 4 under --until: $(cat "$tmp/log")"
period=$(sed -n 's/.*oscillating with a period of \([0-9.]*\) s.*/\1/p' "$tmp/log")
awk -v p="$period" 'BEGIN { e = 2 * 3.141592653589793 * sqrt(1 / 9.81) * (1 + 0.01 / 16); exit !(p != "" && (p - e < 0.01 * e) && (e - p < 0.01 * e)) }' \
  && ok || bad "pendulum period '$period' s, expected 2.0073 s to 1 %: $(cat "$tmp/log")"
cat >"$tmp/chain.json" <<'JSON'
{"format": "embra-scene", "version": 1, "name": "chain", "solver": {"damping": 4.0},
 "bodies": [{"name": "c", "mesh": {"vertices": [[0, 0, 0], [0.1, 0, 0], [0.2, 0, 0], [0.3, 0, 0], [0.4, 0, 0],
             [0.5, 0, 0], [0.6, 0, 0], [0.7, 0, 0], [0.8, 0, 0]]}, "generate": []}],
 "constraints": [{"kind": "distance", "particles": [[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 6], [6, 7], [7, 8]],
                  "rest": [0.12, 0.12, 0.12, 0.12, 0.12, 0.12, 0.12, 0.12]}],
 "pins": [{"name": "a", "particle": {"body": "c", "vertex": 0}}, {"name": "b", "particle": {"body": "c", "vertex": 8}}]}
JSON
"$embra" run "$tmp/chain.json" --until tolerance --out "$tmp/chain" >"$tmp/log" 2>&1 && ok || bad "a damped chain must come to rest: $(cat "$tmp/log")"
grep -q "at rest and within tolerance after" "$tmp/log" && ok || bad "the chain's reason is missing: $(cat "$tmp/log")"
[ -s "$tmp/chain/final.json" ] && [ "$(wc -l <"$tmp/chain/metrics.jsonl")" -eq 1 ] && ok || bad "--until writes final.json and one metrics record"
# The same chain with its right pin moved in over frames 0-150: at rest before frame 150 does not
# count (the scene's actions are part of the problem), so it stops at frame 160 or later.
sed 's/"pins": \[/"actions": [{"type": "pin_target", "pin": "b", "keys": [{"frame": 0, "value": [0.8, 0, 0]}, {"frame": 150, "value": [0.7, 0, 0]}]}], "pins": [/' \
  "$tmp/chain.json" >"$tmp/chain_moved.json"
"$embra" run "$tmp/chain_moved.json" --until settled --out "$tmp/chain_moved" >"$tmp/log" 2>&1 && ok || bad "the moved chain must come to rest: $(cat "$tmp/log")"
after=$(sed -n 's/.*at rest and within tolerance after \([0-9]*\) frames.*/\1/p' "$tmp/log")
[ -n "$after" ] && [ "$after" -ge 160 ] && ok || bad "at rest before the last action's frame counted: after '$after' frames"

# An output folder that holds anything is not written into unless --force: the chain's folder from
# above is refused (exit 1, the folder and the way out named, its final.json untouched), taken with
# --force; an empty folder is taken as it is; demo tent does the same.
before=$(sha256sum <"$tmp/chain/final.json")
"$embra" run "$tmp/chain.json" --frames 5 --out "$tmp/chain" >"$tmp/log" 2>&1; rc=$?
[ $rc -eq 1 ] && ok || bad "a non-empty --out must exit 1, not $rc"
grep -q "^embra: $tmp/chain is not empty: pass --force to write into it" "$tmp/log" && ok || bad "the refusal does not say why: $(cat "$tmp/log")"
[ "$(sha256sum <"$tmp/chain/final.json")" = "$before" ] && ok || bad "a refused run changed final.json"
"$embra" run "$tmp/chain.json" --frames 5 --out "$tmp/chain" --force >"$tmp/log" 2>&1 && ok || bad "--force must write into the folder: $(cat "$tmp/log")"
[ "$(wc -l <"$tmp/chain/metrics.jsonl")" -eq 5 ] && ok || bad "--force must replace metrics.jsonl"
mkdir "$tmp/empty"
"$embra" run "$tmp/chain.json" --frames 1 --out "$tmp/empty" >"$tmp/log" 2>&1 && [ -s "$tmp/empty/final.json" ] && ok || bad "an empty folder must be taken: $(cat "$tmp/log")"
"$embra" demo tent --frames 1 --n 2 --out "$tmp/tent" >/dev/null 2>&1; [ $? -eq 1 ] && ok || bad "demo tent into a non-empty folder must exit 1"
"$embra" demo tent --frames 1 --n 2 --out "$tmp/tent" --force >/dev/null 2>&1 && ok || bad "demo tent --force must run"
"$embra" help | grep -q "^--force" && ok || bad "embra help must explain --force"

# Schema errors in words, each at its JSON pointer: an unknown key with the nearest known one, a
# value of the wrong type with what was expected and what was found.
sed 's/"solver": {"damping": 4.0}/"solver": {"damping": 4.0, "gravty": [0, 0, -9.81]}/' "$tmp/chain.json" >"$tmp/typo.json"
"$embra" validate "$tmp/typo.json" >"$tmp/log" 2>&1; rc=$?
[ $rc -eq 2 ] && grep -q "^embra: $tmp/typo.json: embra_world_load_file: /solver: unknown key 'gravty' (did you mean 'gravity'?)$" "$tmp/log" \
  && ok || bad "an unknown key must be named with the nearest known one (exit $rc): $(cat "$tmp/log")"
sed 's/"generate": \[\]}/"generate": [], "material": {"mass": "heavy"}}/' "$tmp/chain.json" >"$tmp/mass.json"
"$embra" validate "$tmp/mass.json" >"$tmp/log" 2>&1; rc=$?
[ $rc -eq 2 ] && grep -q "/bodies/0/material/mass: expected a number, got a string$" "$tmp/log" \
  && ok || bad "a string for a number must be named as such (exit $rc): $(cat "$tmp/log")"
sed 's/"name": "chain"/"name": "chain", "frames": [3]/' "$tmp/chain.json" >"$tmp/frames.json"
"$embra" validate "$tmp/frames.json" >"$tmp/log" 2>&1; rc=$?
[ $rc -eq 2 ] && grep -q ": /frames: expected a whole number, got an array$" "$tmp/log" \
  && ok || bad "an array for an integer must be named as such (exit $rc): $(cat "$tmp/log")"

# A hanging net (edges, no triangles) writes its links as OBJ `l` lines: the scene's 220 edges,
# 1-based, no faces, beside its 121 vertices.
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
"$embra" run "$source_dir/examples/hanging_net.json" --frames 10 --out "$tmp/net" >"$tmp/log" 2>&1 && ok || bad "the net must run: $(cat "$tmp/log")"
sed 's/.*"edges": \[\(.*\)\]}, "material".*/\1/' "$source_dir/examples/hanging_net.json" | grep -o '\[[0-9]*, [0-9]*\]' |
  awk -F'[][, ]+' '{ print "l " $2 + 1 " " $3 + 1 }' | sort >"$tmp/net_edges"
grep '^l ' "$tmp/net/final.obj" | sort >"$tmp/net_lines"
[ "$(wc -l <"$tmp/net_edges")" -eq 220 ] && cmp -s "$tmp/net_edges" "$tmp/net_lines" && ok || bad "the net's l lines are not its edges"
[ "$(grep -c '^v ' "$tmp/net/final.obj")" -eq 121 ] && ! grep -q '^f ' "$tmp/net/final.obj" && ok || bad "the net's OBJ must hold 121 vertices, no faces"

# scripts/build_progress.sh (what demo.sh shows while it builds): off a terminal, one line per tenth
# of the build; deps.sh's lines and errors pass through; the log keeps everything.
printf '%s\n' "embra: installing libfoo" "[  1%] Building CXX object a.o" "[  5%] Building CXX object b.o" \
  "[ 12%] Building CXX object c.o" "[ 12%] Linking CXX static library d.a" "x.cpp:1:2: error: boom" \
  "[100%] Built target embra" >"$tmp/build_out"
bash "$source_dir/scripts/build_progress.sh" "$tmp/build_log" <"$tmp/build_out" 2>"$tmp/progress" >/dev/null
printf '%s\n' "embra: installing libfoo" "build: 1% (Building CXX object a.o)" "build: 12% (Building CXX object c.o)" \
  "x.cpp:1:2: error: boom" "build: 100% (Built target embra)" >"$tmp/progress_expected"
cmp -s "$tmp/progress" "$tmp/progress_expected" && ok || bad "build progress: $(cat "$tmp/progress")"
cmp -s "$tmp/build_out" "$tmp/build_log" && ok || bad "the build log must keep every line"

# A link that breaks: `run` prints it (embra_world_get_broken) once, with its frame and strain. Two
# links of 1e-3 m/N under 1 kg each, the top one breaking past a strain of 0.12 (statically 0.098;
# the drop from rest overshoots it), the lower one (0.049 statically) never.
cat >"$tmp/tear.json" <<'JSON'
{"format": "embra-scene", "version": 1, "frames": 120, "solver": {"damping": 5.0, "tethers": 0},
 "bodies": [{"name": "chain", "mesh": {"vertices": [[0, 0, 0], [0, 0, -0.2], [0, 0, -0.4]],
   "edges": [[0, 1], [1, 2]], "masses": [0, 1, 1]}, "generate": []}],
 "constraints": [{"kind": "distance", "particles": [[0, 1], [1, 2]], "compliance": 1e-3, "rupture": 0.12}]}
JSON
"$embra" run "$tmp/tear.json" --out "$tmp/tear" >"$tmp/tear.log" 2>&1 && ok || bad "the tearing chain failed: $(cat "$tmp/tear.log")"
[ "$(grep -c '^broke ' "$tmp/tear.log")" -eq 1 ] && ok || bad "one link must break: $(grep broke "$tmp/tear.log")"
grep -Eq '^broke +distance 0 of group 0 \(particles 0 1\) in frame [0-9]+ at strain 0\.1[2-9]' "$tmp/tear.log" && ok ||
  bad "the top link must be named with its strain: $(grep broke "$tmp/tear.log")"
grep -q '"constraints": \[' "$tmp/tear/final.json" && [ "$(grep -c '"rupture"' "$tmp/tear/final.json")" -eq 1 ] && ok ||
  bad "final.json must keep the unbroken link and its rupture strain"

# forces.json carries the colliders' reactions: three loose particles (1, 1.5, 2 kg) at rest on a
# ground plane, one under a point load whose horizontal part friction holds; the plane's force is
# minus every weight and load (N, to 1e-9 relative), and "total" (pins + colliders) the same.
cat >"$tmp/floor.json" <<'JSON'
{"format": "embra-scene", "version": 1, "frames": 60,
 "solver": {"substeps": 4, "iterations": 20, "damping": 5.0, "tethers": 0, "realign_passes": 2},
 "bodies": [{"name": "p", "mesh": {"vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "masses": [1, 1.5, 2]},
             "generate": []}],
 "colliders": [{"name": "floor", "shape": "plane", "position": [0, 0, 0]}],
 "loads": [{"particle": 2, "force": [0.5, 0, -2]}]}
JSON
"$embra" run "$tmp/floor.json" --out "$tmp/floor" >"$tmp/log" 2>&1 && ok || bad "the floor scene must run: $(cat "$tmp/log")"
python3 - "$tmp/floor/forces.json" <<'PY' && ok || bad "forces.json: the floor's reaction is not minus the load"
import json, math, sys
f = json.load(open(sys.argv[1]))
load = [0.5, 0.0, -9.81 * 4.5 - 2.0]
c = f["colliders"]
assert len(c) == 1 and c[0]["collider"][0] == 0 and c[0]["contacts"] == 3, c
for key, v in (("force", c[0]["force"]), ("collider_sum", f["collider_sum"]), ("total", f["total"])):
    err = math.dist(v, [-x for x in load]) / math.hypot(*load)
    print(f"floor {key} + load: {err:.3g} of the load")
    assert err < 1e-9, (key, v)
assert f["units"]["moment"] == "N m" and f["reactions"] == []
PY

# The forces survive final.json (its state.forces): run again from it without stepping (--frames 0),
# the floor scene writes the same forces.json, byte for byte (every number printed to 17 digits).
"$embra" run "$tmp/floor/final.json" --frames 0 --out "$tmp/floor_again" >"$tmp/log" 2>&1 && ok ||
  bad "final.json must run: $(cat "$tmp/log")"
grep -q '"forces": {' "$tmp/floor/final.json" && cmp -s "$tmp/floor/forces.json" "$tmp/floor_again/forces.json" && ok ||
  bad "forces.json from final.json, not stepped, differs from the run's"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
