#!/usr/bin/env bash
# embra.exe with what Windows hosts hand it: a scene in a folder whose name is not ASCII, naming an
# OBJ file whose name is not ASCII either, with CRLF line ends in both files, and an output folder
# with such a name. It must load (validate), run, and reach the same bytes as the same scene with
# ASCII names and LF line ends.
#
# usage: utf8_paths.sh WINE_SH WINEPREFIX EMBRA_EXE SCENES WORK
#   SCENES  tests/scenes/valid (panel_obj.json and the OBJ it names, panel_fold.obj)
set -euo pipefail
wine=${1:?} prefix=${2:?} exe=${3:?} scenes=${4:?} work=${5:?}
rm -rf "$work"
dir="$work/façade Ωmega ✓"
mkdir -p "$dir"
cp "$scenes/panel_obj.json" "$scenes/panel_fold.obj" "$work/"
sed 's/"panel_fold.obj"/"plié ✓.obj"/; s/$/\r/' "$scenes/panel_obj.json" >"$dir/pañel ✓.json"
sed 's/$/\r/' "$scenes/panel_fold.obj" >"$dir/plié ✓.obj"
grep -q 'plié ✓.obj' "$dir/pañel ✓.json"

failures=0
check() {  # check WHAT COMMAND...
  local what=$1
  shift
  if "$@"; then echo "ok:   $what"; else echo "FAIL: $what"; failures=$((failures + 1)); fi
}
out=$("$wine" "$prefix" "$exe" validate "$dir/pañel ✓.json" | tr -d '\r')
echo "$out"
check "validate names the file as given" grep -q "pañel ✓.json: valid" <<<"$out"
"$wine" "$prefix" "$exe" run "$dir/pañel ✓.json" --out "$dir/out ✓" >/dev/null
"$wine" "$prefix" "$exe" run "$work/panel_obj.json" --out "$work/ascii" >/dev/null
check "run wrote final.json into the folder named out ✓" test -f "$dir/out ✓/final.json"
check "final.json the same bytes as the run with ASCII names and LF line ends" \
  cmp "$dir/out ✓/final.json" "$work/ascii/final.json"
# The files embra writes have LF line ends on every platform.
check "metrics.jsonl has LF line ends" test "$(grep -c $'\r' "$dir/out ✓/metrics.jsonl" || true)" -eq 0
if [[ $failures -gt 0 ]]; then
  echo "$failures failure(s)"
  exit 1
fi
echo "UTF-8 names and CRLF files ok"
