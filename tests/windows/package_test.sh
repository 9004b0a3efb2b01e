#!/usr/bin/env bash
# The Windows zip of scripts/package.sh, unpacked into a folder of its own: embra.exe runs from its
# bin folder with nothing but the zip's embra.dll and Windows' own DLLs (it validates and runs an
# example), the DLL imports nothing else, and the Python package carries embra.dll.
#
# usage: package_test.sh WINE_SH WINEPREFIX WINDOWS_BUILD WORK
set -euo pipefail
wine=${1:?} prefix=${2:?} build=${3:?} work=${4:?}
root=$(cd "$(dirname "$0")/../.." && pwd)
rm -rf "$work"
mkdir -p "$work"
zip=$(EMBRA_PACKAGE_OUT="$work" EMBRA_WINDOWS_BUILD="$build" bash "$root/scripts/package.sh" windows)
(cd "$work" && python3 -m zipfile -e "$zip" unpacked)
d=$(echo "$work"/unpacked/embra-*-windows-x86_64)
for f in bin/embra.dll bin/embra.exe lib/libembra.dll.a include/embra/embra.h include/embra/embra_export.h \
         include/embra/embra_version.h python/embra/__init__.py python/embra/embra.dll examples/poq_drape.json; do
  [[ -f "$d/$f" ]] || { echo "FAIL: the zip has no $f"; exit 1; }
done
imports=$(x86_64-w64-mingw32-objdump -p "$d/bin/embra.dll" | sed -n 's/^\s*DLL Name: //p' | sort | tr '\n' ' ')
[[ "$imports" == "KERNEL32.dll msvcrt.dll " ]] || { echo "FAIL: embra.dll imports $imports"; exit 1; }
echo "ok:   embra.dll imports only $imports"
"$wine" "$prefix" "$d/bin/embra.exe" validate "$d/examples/poq_drape.json" | tr -d '\r'
"$wine" "$prefix" "$d/bin/embra.exe" run "$d/examples/hanging_chain.json" --frames 10 --out "$work/run" >/dev/null
[[ -f "$work/run/final.json" ]] || { echo "FAIL: embra.exe from the zip wrote no final.json"; exit 1; }
echo "the Windows zip ok"
