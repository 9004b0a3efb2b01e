#!/usr/bin/env bash
# What Windows hosts can hand embra.exe and embra.dll that is not a scene file, refused with exit 2
# and a message, never read: the device NUL, a folder, a missing file (each through
# embra_world_load_file and through the command's own reading, --allow-outside-paths); and the OBJ
# paths a scene may name in Windows' own forms: "sub\quad.obj" (backslashes) is read, while "NUL",
# "C:\...", "\..." (the current drive's root) and "..\..." are refused.
#
# usage: refusals.sh WINE_SH WINEPREFIX EMBRA_EXE SCENES WORK
#   SCENES  tests/scenes/valid (quad.obj: one quad)
set -euo pipefail
wine=${1:?} prefix=${2:?} exe=${3:?} scenes=${4:?} work=${5:?}
rm -rf "$work"
mkdir -p "$work/scenes/sub"
cp "$scenes/quad.obj" "$work/scenes/sub/quad.obj"
cp "$scenes/quad.obj" "$work/outside.obj"

failures=0
# expect RC TEXT ARGS...: embra.exe ARGS exits RC and prints TEXT (stdout and stderr together).
expect() {
  local rc=$1 text=$2 out got=0
  shift 2
  out=$("$wine" "$prefix" "$exe" "$@" 2>&1 </dev/null) || got=$?
  out=${out//$'\r'/}
  if [[ "$got" == "$rc" && "$out" == *"$text"* ]]; then
    echo "ok:   embra.exe $* -> $rc: $text"
  else
    echo "FAIL: embra.exe $*: exit $got, expected $rc with '$text'; printed: $out"
    failures=$((failures + 1))
  fi
}

for allow in "" --allow-outside-paths; do
  expect 2 "not a regular file" validate NUL $allow
  expect 2 "not a regular file" validate "$work/scenes" $allow
  expect 2 "missing.json: " validate "$work/scenes/missing.json" $allow
done

scene() {  # scene NAME OBJ-PATH: a scene in $work/scenes whose one body is the OBJ at OBJ-PATH
  python3 -c 'import json, sys; print(json.dumps({"format": "embra-scene", "version": 1, "bodies": [
      {"name": "sheet", "mesh": {"obj": sys.argv[1]}, "material": {"mass": 0.5}}]}))' "$2" >"$work/scenes/$1.json"
}
scene backslash 'sub\quad.obj'
scene device 'NUL'
scene drive 'C:\windows\win.ini'
scene root '\work\outside.obj'
scene parent '..\outside.obj'
expect 0 ": valid ($(grep -c '^v ' "$scenes/quad.obj") particles" validate "$work/scenes/backslash.json"
expect 2 "not a regular file" validate "$work/scenes/device.json"
expect 2 "an absolute path is refused" validate "$work/scenes/drive.json"
expect 2 "an absolute path is refused" validate "$work/scenes/root.json"
expect 2 "leads outside the scene's folder" validate "$work/scenes/parent.json"
if [[ $failures -gt 0 ]]; then
  echo "$failures failure(s)"
  exit 1
fi
echo "refusals ok"
