#!/usr/bin/env bash
# Times this checkout's benchmark against an older commit's, side by side: this shared machine's
# speed drifts by up to 40 % within an hour, so only runs interleaved in time compare fairly.
#
# usage: bash scripts/bench_compare.sh COMMIT [FILTER] [RUNS]
#   COMMIT  the commit to compare with (built in a temporary git worktree, removed afterwards)
#   FILTER  a --benchmark_filter selecting one benchmark (default BM_Cloth/128)
#   RUNS    runs of each binary, alternating (default 6)
# Prints each binary's ms_per_frame (or ms_per_substep) values, sorted.
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
old=$(mktemp -d)
trap 'git worktree remove --force "$old" >/dev/null 2>&1 || rm -rf "$old"' EXIT
git worktree add --detach "$old" "$commit" >/dev/null 2>&1
cmake -S "$old" -B "$old/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$old/build" --target embra_bench -j "$jobs" >/dev/null

# One figure per run: the benchmark's ms_per_frame or ms_per_substep counter.
measure() {
  "$1" --benchmark_filter="$filter" 2>/dev/null | sed -nE 's/.*ms_per_(frame|substep)=([0-9.]+).*/\2/p' | head -1
}
declare -a a b
for _ in $(seq "$runs"); do
  a+=("$(measure "$old/build/bench/embra_bench")")
  b+=("$(measure build/bench/embra_bench)")
done
if [ -z "${a[0]}" ] || [ -z "${b[0]}" ]; then
  echo "no ms_per_frame or ms_per_substep figure from '$filter'" >&2
  exit 1
fi
echo "$filter, $runs runs each, alternating (ms, sorted):"
echo "  ${commit:0:7}:   $(printf '%s\n' "${a[@]}" | sort -g | tr '\n' ' ')"
echo "  this tree: $(printf '%s\n' "${b[@]}" | sort -g | tr '\n' ' ')"
