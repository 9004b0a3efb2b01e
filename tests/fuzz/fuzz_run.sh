#!/usr/bin/env bash
# Runs a libFuzzer target of tests/fuzz, for ctest and for scripts/fuzz.sh. The seed folders of each
# target are named here and nowhere else.
#
#   fuzz_run.sh replay BINARY TARGET ROOT
#       every committed input of tests/fuzz/regressions/TARGET (and the target's committed seeds),
#       each run once: fails on any crash, sanitizer report or failed check.
#   fuzz_run.sh short BINARY TARGET ROOT WORK RUNS [DICT]
#       a fresh corpus in WORK/corpus from the target's seeds, then RUNS mutations with seed 1. The
#       mutations are seeded, but which inputs are kept follows the coverage they reach, and that
#       varies a little from run to run (allocation addresses decide some sorts' paths), so two runs
#       may try different inputs. A finding is written to WORK/ and printed last, gzip | base64.
#   fuzz_run.sh seeds TARGET ROOT DIR
#       copies the target's seeds into DIR (names prefixed by their folder, so none collide).
#   fuzz_run.sh fuzz BINARY CORPUS FINDINGS SECONDS [DICT]
#       fuzzes for SECONDS from CORPUS, adding to it; a finding is written to FINDINGS/ and stops
#       the run (scripts/fuzz.sh starts it again).
#
# ROOT is the source tree. Seeds: fuzz_scene takes the examples (examples/*.json, examples/large/),
# the test scenes (tests/scenes/valid, tests/scenes/invalid) and its regressions; fuzz_capi its
# committed seeds (tests/fuzz/seeds/fuzz_capi) and its regressions.
set -euo pipefail

# The options every run takes: no input may take a minute or 2 GB. An input under a minute is within
# the bound (the targets' work limit keeps most far under it), so slow units are not reported.
LIBFUZZER_OPTIONS=(-timeout=60 -report_slow_units=60 -rss_limit_mb=2048 -print_final_stats=1)
export ASAN_OPTIONS="${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"

seed_dirs() {  # TARGET ROOT
  case "$1" in
    fuzz_scene)
      echo "$2/examples" "$2/examples/large" "$2/tests/scenes/valid" "$2/tests/scenes/invalid" \
        "$2/tests/fuzz/regressions/fuzz_scene"
      ;;
    fuzz_capi) echo "$2/tests/fuzz/seeds/fuzz_capi" "$2/tests/fuzz/regressions/fuzz_capi" ;;
    *)
      echo "fuzz_run.sh: unknown target $1" >&2
      exit 2
      ;;
  esac
}

# The input files of the folders (not their subfolders; no README or OBJ files), sorted.
inputs_of() {
  local dir
  for dir in "$@"; do
    [ -d "$dir" ] || continue
    find "$dir" -maxdepth 1 -type f ! -name 'README*' ! -name '*.obj' -print
  done | LC_ALL=C sort
}

copy_seeds() {  # TARGET ROOT DIR
  local root="$2" out="$3" file rel
  mkdir -p "$out"
  # shellcheck disable=SC2046
  inputs_of $(seed_dirs "$1" "$root") | while read -r file; do
    rel="${file#"$root"/}"
    cp "$file" "$out/${rel//\//_}"
  done
}

mode="${1:-}"
case "$mode" in
  replay)
    binary="$2" target="$3" root="$4"
    mapfile -t files < <(inputs_of "$root/tests/fuzz/regressions/$target" \
      $([ "$target" = fuzz_capi ] && echo "$root/tests/fuzz/seeds/fuzz_capi"))
    if [ ${#files[@]} -eq 0 ]; then
      echo "fuzz_run.sh: no regression inputs for $target"
      exit 0
    fi
    echo "fuzz_run.sh: replaying ${#files[@]} inputs through $target"
    # Given files, libFuzzer runs each once and stops at the first failure.
    exec "$binary" "${LIBFUZZER_OPTIONS[@]}" "${files[@]}"
    ;;
  short)
    binary="$2" target="$3" root="$4" work="$5" runs="$6" dict="${7:-}"
    rm -rf "$work"
    mkdir -p "$work/corpus"
    copy_seeds "$target" "$root" "$work/corpus"
    echo "fuzz_run.sh: $target, $(find "$work/corpus" -type f | wc -l) seeds, $runs runs with seed 1"
    args=("${LIBFUZZER_OPTIONS[@]}" -runs="$runs" -seed=1 -artifact_prefix="$work/")
    [ -n "$dict" ] && args+=(-dict="$dict")
    set +e
    "$binary" "${args[@]}" "$work/corpus" 2>&1 | tee "$work/log"
    rc=${PIPESTATUS[0]}
    set -e
    [ "$rc" -eq 0 ] && exit 0
    # A finding in a fresh clone's build folder is gone with it: print what failed and the input
    # itself (gzip, base64), last, where a shortened log still shows it. To replay:
    #   base64 -d <<'EOF' | gunzip > finding; build-fuzz/tests/fuzz/TARGET finding
    echo "fuzz_run.sh: $target failed (libFuzzer exited $rc):"
    grep -E 'FAILED|ERROR|runtime error|SUMMARY' "$work/log" | head -5 || true
    for finding in "$work"/crash-* "$work"/leak-* "$work"/timeout-* "$work"/oom-*; do
      [ -f "$finding" ] || continue
      echo "fuzz_run.sh: the input $(basename "$finding") ($(wc -c <"$finding") bytes), gzip | base64:"
      gzip -9c "$finding" | base64 -w 100
    done
    exit "$rc"
    ;;
  seeds)
    copy_seeds "$2" "$3" "$4"
    ;;
  fuzz)
    binary="$2" corpus="$3" findings="$4" seconds="$5" dict="${6:-}"
    mkdir -p "$corpus" "$findings"
    args=("${LIBFUZZER_OPTIONS[@]}" -max_total_time="$seconds" -artifact_prefix="$findings/")
    [ -n "$dict" ] && args+=(-dict="$dict")
    exec "$binary" "${args[@]}" "$corpus"
    ;;
  *)
    sed -n '2,20p' "$0" >&2
    exit 2
    ;;
esac
