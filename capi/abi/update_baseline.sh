#!/usr/bin/env bash
# Writes the ABI baseline capi/abi/<SONAME>.abi from a built libembra.so, on purpose:
#   - same SONAME as the committed baseline: only compatible changes (added functions) are taken;
#     an incompatible change is refused, naming EMBRA_ABI_VERSION (CMakeLists.txt) to bump first;
#   - a new SONAME (EMBRA_ABI_VERSION was bumped): the new baseline replaces the old one.
# usage: bash capi/abi/update_baseline.sh build/libembra.so
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
lib=${1:?usage: update_baseline.sh path/to/libembra.so}
soname=$(readelf -d "$lib" | sed -n 's/.*(SONAME).*\[\(.*\)\].*/\1/p')
[[ -n "$soname" ]] || { echo "no SONAME in $lib"; exit 1; }
out="$here/$soname.abi"
if [[ -f "$out" ]] && ! bash "$here/check_abi.sh" "$out" "$lib" >/dev/null; then
  bash "$here/check_abi.sh" "$out" "$lib" || true
  echo "refused: $lib is incompatible with $out; bump EMBRA_ABI_VERSION in CMakeLists.txt (and the"
  echo "adapters' ABI_VERSION / AbiVersion), rebuild, and run this again"
  exit 1
fi
abidw --headers-dir "$here/../include" --drop-private-types --exported-interfaces-only \
  --suppressions "$here/embra.abignore" --no-corpus-path --no-comp-dir-path --no-show-locs \
  --out-file "$out.tmp" "$lib"
mv "$out.tmp" "$out"
for old in "$here"/libembra.so.*.abi; do
  [[ "$old" == "$out" ]] || { git -C "$here" rm -q --cached "$old" 2>/dev/null || true; rm -f "$old"; }
done
echo "wrote $out"
