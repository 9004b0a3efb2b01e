#!/usr/bin/env bash
# Compares a freshly built libembra.so with the committed ABI baseline (abidiff, libabigail) and
# fails on any change a host compiled against the baseline would notice:
#   - a removed function (abidiff bit 8, ABI_INCOMPATIBLE_CHANGE);
#   - a changed signature, or a public struct whose size or layout changed (bit 4, ABI_CHANGE,
#     left once what is compatible is set aside: added functions and variables (--no-added-syms)
#     and the private layout of the opaque embra_world (embra.abignore));
#   - a tool error (bits 1 and 2).
# Appending a field to an embra_*_def struct IS reported, on purpose: embra_default_*_def() returns
# the struct by value, so a larger struct would be written past the return slot of a host compiled
# against the smaller one, and the library reads only its own def version (an older one is refused
# with EMBRA_ERROR_VERSION). Growing a def therefore means a new ABI version; see README.md here.
#
# Only types reachable from the exported functions are compared (--exported-interfaces-only); no
# headers directory is given to abidiff, because it would count every type of a baseline written
# without source locations as private and filter its changes out.
#
# usage: check_abi.sh BASELINE.abi LIBRARY [SUPPRESSIONS]
set -uo pipefail
baseline=${1:?usage: check_abi.sh BASELINE.abi LIBRARY [SUPPRESSIONS]}
lib=${2:?usage: check_abi.sh BASELINE.abi LIBRARY [SUPPRESSIONS]}
suppr=${3:-$(dirname "$0")/embra.abignore}

command -v abidiff >/dev/null || { echo "FAIL: abidiff not found (Debian package abigail-tools)"; exit 1; }
[[ -f "$baseline" ]] || { echo "FAIL: no ABI baseline at $baseline (see capi/abi/README.md)"; exit 1; }
[[ -f "$lib" ]] || { echo "FAIL: no library at $lib"; exit 1; }

# The baseline and the library must carry the same SONAME: a new ABI version needs its own baseline.
want=$(sed -n "1s/.*soname='\([^']*\)'.*/\1/p" "$baseline")
got=$(readelf -d "$lib" | sed -n 's/.*(SONAME).*\[\(.*\)\].*/\1/p')
if [[ "$want" != "$got" ]]; then
  echo "FAIL: baseline $baseline is for $want, the library is $got (run capi/abi/update_baseline.sh)"
  exit 1
fi

abidiff --no-added-syms --suppressions "$suppr" --exported-interfaces-only \
  --no-show-locs "$baseline" "$lib"
rc=$?
(( rc & 1 )) && { echo "FAIL: abidiff failed (exit $rc)"; exit 1; }
(( rc & 2 )) && { echo "FAIL: abidiff usage error (exit $rc)"; exit 1; }
(( rc & 8 )) && { echo "FAIL: incompatible ABI change against $baseline (removed symbols; exit $rc)"; exit 1; }
(( rc & 4 )) && { echo "FAIL: ABI change against $baseline (a changed type or signature; exit $rc)"; exit 1; }
echo "ABI compatible with $(basename "$baseline") ($got)"
exit 0
