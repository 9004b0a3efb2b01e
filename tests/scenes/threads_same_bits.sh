#!/usr/bin/env bash
# The solver's result does not depend on its thread count: every example (examples/*.json and the
# large drapes of examples/large/) stepped on 1, 2, 3 and 8 threads (`embra run --threads T`) ends
# in byte-identical final.json files, and its metrics.jsonl (every frame's residuals, energy and
# speed, with the frame time taken out) is identical too.
#
# usage: threads_same_bits.sh EMBRA_CLI SOURCE_DIR WORK_DIR [FRAMES [LARGE_FRAMES]]
set -u
cli=$1 source=$2 work=$3 frames=${4:-100} large_frames=${5:-30}
mkdir -p "$work"
fail=0 count=0
for path in "$source"/examples/*.json "$source"/examples/large/*.json; do
  name=$(basename "$path" .json) n=$frames
  case "$path" in */large/*) n=$large_frames ;; esac
  first="" first_metrics=""
  for threads in 1 2 3 8; do
    out=$work/$name.t$threads
    rm -rf "$out"  # the work folder stays between runs; `embra run` refuses a non-empty --out
    if ! "$cli" run "$path" --frames "$n" --threads "$threads" --out "$out" --every 1000000 >"$out.log" 2>&1; then
      echo "FAIL $name on $threads threads: embra run exited non-zero"; cat "$out.log"; fail=1; continue
    fi
    sum=$(sha256sum <"$out/final.json" | cut -d' ' -f1)
    metrics=$(sed -E 's/"ms":[^,]*,//' "$out/metrics.jsonl" | sha256sum | cut -d' ' -f1)
    echo "$name ($n frames) $threads threads: final.json $sum, metrics $metrics"
    if [ -z "$first" ]; then
      first=$sum first_metrics=$metrics
    elif [ "$sum" != "$first" ] || [ "$metrics" != "$first_metrics" ]; then
      echo "FAIL $name: $threads threads give different bits from 1"; fail=1
    fi
  done
  count=$((count + 1))
done
[ "$count" -gt 0 ] || { echo "FAIL: no example found under $source/examples"; fail=1; }
echo "$count examples, 4 thread counts each"
exit $fail
