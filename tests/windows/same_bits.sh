#!/usr/bin/env bash
# Runs each example scene for the same frames with the Linux build's `embra` and with `embra.exe`
# under wine64 and compares their final.json byte for byte: the same scene and settings must give
# the same bits on both, except where the C libraries round a libm function differently (glibc and
# mingw-w64's runtime disagree by 1 ulp now and then; tests/windows/libm_probe.c measures where).
#
# usage: same_bits.sh LINUX_EMBRA WINE_SH WINEPREFIX EMBRA_EXE PROBE_EXE EXAMPLES WORK FRAMES SAME...
#   FRAMES  at most this many frames of each example (fewer when the scene has fewer)
#   SAME    the examples (file names without .json) that must give identical bytes: those whose runs
#           reach no libm result the two libraries round differently (measured; docs/decisions.md).
#           A listed example that differs fails the test; an unlisted one is compared and reported.
set -euo pipefail
linux=${1:?} wine=${2:?} prefix=${3:?} exe=${4:?} probe=${5:?} examples=${6:?} work=${7:?} cap=${8:?}
shift 8
same=("$@")
rm -rf "$work"
mkdir -p "$work"

# The C libraries: the same probe built for each.
cc -O2 -o "$work/libm_probe" "$(dirname "$0")/libm_probe.c" -lm
"$work/libm_probe" >"$work/libm_linux.txt"
"$wine" "$prefix" "$probe" | tr -d '\r' >"$work/libm_windows.txt"
echo "libm: results that differ between glibc and the Windows build's C runtime (of 100000 each):"
paste -d' ' "$work/libm_linux.txt" "$work/libm_windows.txt" | awk '
  { n[$1]++; if ($3 != $6) d[$1]++ }
  END { for (f in n) printf "  %-6s %6d\n", f, d[f] + 0 }' | sort

failures=0
printf '%-22s %6s  %s\n' example frames "final.json, Linux vs Windows"
for scene in "$examples"/*.json; do
  name=$(basename "$scene" .json)
  frames=$(python3 -c 'import json, sys; print(min(int(json.load(open(sys.argv[1])).get("frames", 0)), int(sys.argv[2])))' \
           "$scene" "$cap")
  "$linux" run "$scene" --frames "$frames" --out "$work/linux/$name" >/dev/null
  "$wine" "$prefix" "$exe" run "$scene" --frames "$frames" --out "$work/windows/$name" >/dev/null
  listed=0
  for s in "${same[@]}"; do [[ "$s" == "$name" ]] && listed=1; done
  if cmp -s "$work/linux/$name/final.json" "$work/windows/$name/final.json"; then
    verdict="identical bytes"
    [[ $listed -eq 1 ]] || verdict="$verdict (not listed as identical: list it)"
  else
    # Which numbers differ, and by how much: the state after a libm result rounded differently.
    verdict=$(python3 - "$work/linux/$name/final.json" "$work/windows/$name/final.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
count, worst, where = 0, 0.0, ""
def walk(x, y, path):
    global count, worst, where
    if isinstance(x, dict) and isinstance(y, dict) and x.keys() == y.keys():
        for k in x: walk(x[k], y[k], path + "/" + k)
    elif isinstance(x, list) and isinstance(y, list) and len(x) == len(y):
        for i, (p, q) in enumerate(zip(x, y)): walk(p, q, path + "/" + str(i))
    elif x != y:
        count += 1
        d = abs(x - y) if isinstance(x, (int, float)) and isinstance(y, (int, float)) else float("inf")
        if d > worst or not where: worst, where = d, path
walk(a, b, "")
print(f"differ: {count} numbers, largest difference {worst:.3g} at {where}")
PY
)
    [[ $listed -eq 1 ]] && { verdict="FAIL: $verdict"; failures=$((failures + 1)); }
  fi
  printf '%-22s %6s  %s\n' "$name" "$frames" "$verdict"
done
if [[ $failures -gt 0 ]]; then
  echo "$failures example(s) listed as identical differ between Linux and Windows"
  exit 1
fi
echo "every example listed as identical is"
