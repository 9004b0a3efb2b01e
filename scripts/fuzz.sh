#!/usr/bin/env bash
# Fuzzes one libFuzzer target of tests/fuzz for as long as asked, one process (-jobs=1), building
# it first if needed (scripts/sanitize.sh fuzz-build: clang, address + undefined behaviour, in
# build-fuzz). The corpus grows in a work folder outside the repository and is kept between runs;
# after a finding the run starts again, until the time is up or 10 findings were collected.
#
#   scripts/fuzz.sh TARGET MINUTES        TARGET: fuzz_scene or fuzz_capi
#
#   EMBRA_FUZZ_WORK   the work folder (default ~/.cache/embra-fuzz):
#                       TARGET/corpus     the corpus (the target's seeds are added at every start)
#                       TARGET/findings   inputs that crashed, failed a check, leaked or timed out
#                       TARGET/log        libFuzzer's output
#
# A finding replays with `build-fuzz/tests/fuzz/TARGET FILE` (EMBRA_FUZZ_TRACE=1 prints every call);
# once fixed, commit it to tests/fuzz/regressions/TARGET/ and the test command replays it.
set -euo pipefail
cd "$(dirname "$0")/.."
target="${1:-}" minutes="${2:-}"
case "$target" in
  fuzz_scene | fuzz_capi) ;;
  *)
    sed -n '2,16p' "$0" >&2
    exit 2
    ;;
esac
if ! [[ "$minutes" =~ ^[0-9]+$ ]] || [ "$minutes" -lt 1 ]; then
  echo "fuzz.sh: MINUTES must be a whole number >= 1" >&2
  exit 2
fi

bash scripts/sanitize.sh fuzz-build
build="${EMBRA_SANITIZE_BUILD_ROOT:-.}/build-fuzz"
binary="$build/tests/fuzz/$target"
dict=""
[ "$target" = fuzz_scene ] && dict="$build/tests/fuzz/scene.dict"

work="${EMBRA_FUZZ_WORK:-${XDG_CACHE_HOME:-$HOME/.cache}/embra-fuzz}/$target"
mkdir -p "$work/corpus" "$work/findings"
bash tests/fuzz/fuzz_run.sh seeds "$target" "$PWD" "$work/corpus"
log="$work/log"
: >"$log"

findings_before=$(find "$work/findings" -type f | wc -l)
deadline=$((SECONDS + 60 * minutes))
while [ $SECONDS -lt $deadline ]; do
  found=$(($(find "$work/findings" -type f | wc -l) - findings_before))
  [ "$found" -lt 10 ] || break
  echo "fuzz.sh: $target for $((deadline - SECONDS)) s more, corpus $work/corpus" >&2
  set +e
  bash tests/fuzz/fuzz_run.sh fuzz "$binary" "$work/corpus" "$work/findings" $((deadline - SECONDS)) $dict >>"$log" 2>&1
  rc=$?
  set -e
  [ $rc -eq 0 ] && break
  echo "fuzz.sh: finding (libFuzzer exited $rc): $(grep -E 'ERROR|FAILED|runtime error' "$log" | tail -1)" >&2
done

found=$(($(find "$work/findings" -type f | wc -l) - findings_before))
runs=$(awk '/stat::number_of_executed_units:/ { n += $2 } END { print n + 0 }' "$log")
echo "fuzz.sh: $target fuzzed $minutes min: $runs runs, corpus $(find "$work/corpus" -type f | wc -l) inputs," \
  "$found new findings"
if [ "$found" -gt 0 ]; then
  echo "fuzz.sh: findings in $work/findings (log: $log):"
  ls -t "$work/findings" | head -n "$found" | sed "s|^|  $work/findings/|"
  echo "fuzz.sh: replay one with: $binary FILE   (EMBRA_FUZZ_TRACE=1 prints the calls)"
  exit 1
fi
