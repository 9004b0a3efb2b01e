#!/usr/bin/env bash
# Times this checkout's benchmark against an older commit's, side by side: this shared machine's
# speed drifts by up to 40 % within an hour, so only runs interleaved in time compare fairly.
#
# usage: bash scripts/bench_compare.sh COMMIT [FILTER] [RUNS]
#   COMMIT  the commit to compare with (built in a temporary git worktree, removed afterwards)
#   FILTER  a --benchmark_filter, selecting one benchmark or several (default BM_Cloth/128)
#   RUNS    runs of each binary, alternating (default 6)
# Prints, for each benchmark the filter selects, each binary's figures, sorted: its ms_per_frame or
# ms_per_substep counter, or else its real time in ms.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 1 ]; then
  echo "usage: bash scripts/bench_compare.sh COMMIT [FILTER] [RUNS]" >&2
  exit 2
fi
commit=$(git rev-parse --verify "$1^{commit}")
filter=${2:-BM_Cloth/128}
runs=${3:-6}
case $runs in '' | *[!0-9]*) echo "RUNS must be a positive integer" >&2; exit 2 ;; esac
jobs=$(nproc 2>/dev/null || echo 2)

bash scripts/build.sh >/dev/null
old=$(mktemp -d) a=$(mktemp) b=$(mktemp)
trap 'rm -f "$a" "$b"; git worktree remove --force "$old" >/dev/null 2>&1 || rm -rf "$old"' EXIT
git worktree add --detach "$old" "$commit" >/dev/null 2>&1
cmake -S "$old" -B "$old/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$old/build" --target embra_bench -j "$jobs" >/dev/null

# One run of each selected benchmark: "name figure" lines.
measure() {
  "$1" --benchmark_filter="$filter" --benchmark_format=json 2>/dev/null | python3 -c '
import json, sys
units = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}
for b in json.load(sys.stdin)["benchmarks"]:
    ms = b.get("ms_per_frame", b.get("ms_per_substep"))
    if ms is None:
        ms = b["real_time"] * units[b["time_unit"]]
    print(b["name"], ms)
'
}
for _ in $(seq "$runs"); do
  measure "$old/build/bench/embra_bench" >>"$a"
  measure build/bench/embra_bench >>"$b"
done
if [ ! -s "$a" ] || [ ! -s "$b" ]; then
  echo "no benchmark selected by '$filter'" >&2
  exit 1
fi
echo "$filter, $runs runs each, alternating (ms, sorted):"
python3 - "$a" "$b" "${commit:0:7}" <<'PY'
import sys
def read(path):
    runs = {}
    for line in open(path):
        name, ms = line.rsplit(" ", 1)
        runs.setdefault(name, []).append(float(ms))
    return runs
old, new = read(sys.argv[1]), read(sys.argv[2])
for name in new:
    print(name)
    for label, runs in ((sys.argv[3] + ":  ", old), ("this tree:", new)):
        print("  " + label, " ".join(f"{v:.4g}" for v in sorted(runs.get(name, []))))
PY
