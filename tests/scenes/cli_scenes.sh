#!/usr/bin/env bash
# The `embra` command on JSON scenes.
#
#   cli_scenes.sh EMBRA INVALID_DIR GENERATED_DIR WORK_DIR SCENE.json...
#
# 1. Every invalid scene of the manifest (INVALID_DIR/README.md; rows whose file is not in
#    INVALID_DIR are in GENERATED_DIR): `embra validate` and `embra run` exit 2 within 60 s (no
#    signal, no hang), print the row's pointer and fragment on stderr, and `run` writes no
#    final.json. The manifest lists exactly the folder's files.
# 2. Every valid SCENE: `validate` exits 0; `run --frames 0` then running its final.json gives a
#    byte-identical final.json; 100 frames from the scene and from that final.json end in identical
#    final.json and final.obj; 50 frames, then 50 from that final.json, end identical to 100;
#    --every and --threads; a run without --frames steps the scene's own "frames".
# 3. Usage errors exit 1, unreadable input exits 2.
# 4. An OBJ path leading out of the scene's folder is refused unless --allow-outside-paths; `help`
#    says so; special files stay refused either way.
set -u
embra="$1"
invalid_dir="$2"
generated_dir="$3"
work="$4"
shift 4
rm -rf "$work"
mkdir -p "$work"
passed=0
failed=0
ok() { passed=$((passed + 1)); }
bad() {
  echo "FAIL: $*"
  failed=$((failed + 1))
}
# run_embra LOG ARGS...: runs embra with a 240 s limit (a hang is a failure; the slowest run, 100
# frames of the shrink wrap on 2 threads, took over 60 s with the 2 cores shared by other builds),
# stdout and stderr to LOG.out / LOG.err; sets rc (124: the limit was reached, and says so).
run_embra() {
  local log="$1"
  shift
  timeout 240 "$embra" "$@" >"$log.out" 2>"$log.err"
  rc=$?
  [ "$rc" -ne 124 ] || echo "embra $* did not finish within 240 s" >>"$log.err"
}

# --- 1. the invalid corpus -----------------------------------------------------------------------
manifest="$invalid_dir/README.md"
listed="$work/listed.txt"
# Rows: | `file` | class | `pointer` | `fragment` |
grep '^| `' "$manifest" | sed 's/^| `\([^`]*\)`.*/\1/' | sort >"$listed"
(cd "$invalid_dir" && ls -1 -- *.json | sort) >"$work/present.txt"
unlisted=$(comm -13 "$listed" "$work/present.txt")
[ -z "$unlisted" ] && ok || bad "files not in the manifest: $unlisted"
committed=$(wc -l <"$work/present.txt")
[ "$committed" -ge 40 ] && ok || bad "only $committed invalid scenes"

rows=0
while IFS= read -r row; do
  file=$(printf '%s' "$row" | cut -d'`' -f2)
  pointer=$(printf '%s' "$row" | cut -d'`' -f4)
  fragment=$(printf '%s' "$row" | cut -d'`' -f6)
  path="$invalid_dir/$file"
  [ -f "$path" ] || path="$generated_dir/$file"
  if [ ! -f "$path" ]; then
    bad "$file: listed in the manifest but in neither $invalid_dir nor $generated_dir"
    continue
  fi
  rows=$((rows + 1))
  log="$work/invalid_${file%.json}"
  run_embra "$log.validate" validate "$path"
  if [ "$rc" -eq 2 ]; then ok; else bad "$file: validate exited $rc, not 2: $(head -c 300 "$log.validate.err")"; fi
  out="$work/run_${file%.json}"
  run_embra "$log.run" run "$path" --frames 3 --out "$out"
  if [ "$rc" -eq 2 ]; then ok; else bad "$file: run exited $rc, not 2: $(head -c 300 "$log.run.err")"; fi
  [ ! -e "$out/final.json" ] && ok || bad "$file: run wrote $out/final.json"
  for step in validate run; do
    err="$log.$step.err"
    grep -qF -- "$pointer: " "$err" && ok || bad "$file: $step's stderr does not name '$pointer': $(head -c 300 "$err")"
    grep -qF -- "$fragment" "$err" && ok || bad "$file: $step's stderr lacks '$fragment': $(head -c 300 "$err")"
  done
done < <(grep '^| `' "$manifest")
echo "$rows invalid scenes refused by validate and run"

# --- 2. valid scenes round-trip through `embra run` ---------------------------------------------
i=0
for scene in "$@"; do
  i=$((i + 1))
  name=$(basename "$scene" .json)
  d="$work/valid_${i}_$name"
  mkdir -p "$d"
  run_embra "$d/validate" validate "$scene"
  [ "$rc" -eq 0 ] && grep -q "valid" "$d/validate.out" && ok || bad "$name: validate exited $rc: $(cat "$d/validate.err")"

  run_embra "$d/a" run "$scene" --frames 0 --out "$d/a"
  [ "$rc" -eq 0 ] && ok || bad "$name: run --frames 0 exited $rc: $(cat "$d/a.err")"
  [ -s "$d/a/final.json" ] && [ -f "$d/a/metrics.jsonl" ] && [ ! -s "$d/a/metrics.jsonl" ] && ok ||
    bad "$name: run --frames 0 must write final.json and an empty metrics.jsonl"
  run_embra "$d/b" run "$d/a/final.json" --frames 0 --out "$d/b"
  [ "$rc" -eq 0 ] && cmp -s "$d/a/final.json" "$d/b/final.json" && ok ||
    bad "$name: final.json of final.json differs (load -> save -> load -> save)"

  run_embra "$d/c" run "$scene" --frames 100 --out "$d/c"
  [ "$rc" -eq 0 ] && ok || bad "$name: run --frames 100 exited $rc: $(cat "$d/c.err")"
  [ "$(wc -l <"$d/c/metrics.jsonl")" -eq 100 ] && ok || bad "$name: metrics.jsonl must have 100 lines"
  run_embra "$d/d" run "$d/a/final.json" --frames 100 --out "$d/d"
  [ "$rc" -eq 0 ] && cmp -s "$d/c/final.json" "$d/d/final.json" && cmp -s "$d/c/final.obj" "$d/d/final.obj" && ok ||
    bad "$name: 100 frames from the saved scene differ from 100 frames from the scene"

  run_embra "$d/e" run "$scene" --frames 50 --out "$d/e"
  run_embra "$d/f" run "$d/e/final.json" --frames 50 --out "$d/f"
  [ "$rc" -eq 0 ] && cmp -s "$d/c/final.json" "$d/f/final.json" && cmp -s "$d/c/final.obj" "$d/f/final.obj" && ok ||
    bad "$name: 50 + 50 frames differ from 100 frames"
  head -n 1 "$d/f/metrics.jsonl" | grep -q '^{"frame":51,' && ok || bad "$name: a resumed run must count on from frame 51"

  run_embra "$d/g" run "$scene" --frames 100 --every 50 --threads 2 --out "$d/g"
  [ "$rc" -eq 0 ] && cmp -s "$d/c/final.json" "$d/g/final.json" && ok || bad "$name: --every/--threads change the result"
  [ -s "$d/g/frame_00050.obj" ] && cmp -s "$d/g/frame_00100.obj" "$d/g/final.obj" && [ ! -e "$d/g/frame_00099.obj" ] &&
    ok || bad "$name: --every 50 must write frame_00050.obj and frame_00100.obj (= final.obj) only"

  frames=$(grep -o '^  "frames": *[0-9]*' "$scene" | grep -o '[0-9]*$')
  if [ -n "$frames" ] && [ "$frames" -le 100 ]; then
    run_embra "$d/h" run "$scene" --out "$d/h"
    [ "$rc" -eq 0 ] && [ "$(wc -l <"$d/h/metrics.jsonl")" -eq "$frames" ] && ok ||
      bad "$name: a run without --frames must step the scene's $frames frames"
  fi
done
echo "$i valid scenes round-tripped through embra run"

# --- 3. usage and unreadable input ---------------------------------------------------------------
scene="$1"
expect() {
  local want="$1" what="$2"
  shift 2
  run_embra "$work/usage" "$@"
  [ "$rc" -eq "$want" ] && ok || bad "$what: exited $rc, not $want"
}
expect 1 "validate without a scene" validate
expect 1 "validate with two scenes" validate "$scene" "$scene"
expect 1 "run without a scene" run
expect 1 "run --frames -1" run "$scene" --frames -1 --out "$work/usage_out"
expect 1 "run --frames abc" run "$scene" --frames abc --out "$work/usage_out"
expect 1 "run --frames without a value" run "$scene" --frames
expect 1 "run --every 0" run "$scene" --every 0 --out "$work/usage_out"
expect 1 "run with an unknown option" run "$scene" --fast
[ ! -e "$work/usage_out/final.json" ] && ok || bad "a usage error wrote final.json"
expect 2 "validate a missing file" validate "$work/no-such-scene.json"
expect 2 "run a missing file" run "$work/no-such-scene.json" --out "$work/missing_out"
[ ! -e "$work/missing_out/final.json" ] && ok || bad "run of a missing file wrote final.json"
expect 2 "validate a folder" validate "$work"
expect 2 "run into an unwritable folder" run "$scene" --frames 0 --out /proc/embra-cannot-write

# --- 4. OBJ paths outside the scene's folder: refused unless --allow-outside-paths ----------------
expect 0 "help" help
grep -q -- "--allow-outside-paths" "$work/usage.out" && grep -q "relative to the scene file's folder" "$work/usage.out" &&
  ok || bad "help must explain --allow-outside-paths"
outside="$invalid_dir/obj_parent_path.json" # its OBJ is ../valid/quad.obj
expect 2 "validate an OBJ path outside the folder" validate "$outside"
expect 0 "validate it with --allow-outside-paths" validate "$outside" --allow-outside-paths
expect 1 "validate with an unknown flag" validate "$outside" --allow
expect 2 "run an OBJ path outside the folder" run "$outside" --frames 1 --out "$work/outside_refused"
[ ! -e "$work/outside_refused/final.json" ] && ok || bad "a refused OBJ path wrote final.json"
expect 0 "run it with --allow-outside-paths" run "$outside" --frames 1 --allow-outside-paths --out "$work/outside"
[ -s "$work/outside/final.json" ] && ok || bad "run --allow-outside-paths wrote no final.json"
expect 2 "validate /dev/zero as a scene with --allow-outside-paths" validate /dev/zero --allow-outside-paths
expect 2 "validate an OBJ of /dev/zero even when allowed" validate "$invalid_dir/obj_absolute_path.json" --allow-outside-paths
grep -q "is not a regular file" "$work/usage.err" && ok || bad "/dev/zero as an OBJ: $(cat "$work/usage.err")"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
