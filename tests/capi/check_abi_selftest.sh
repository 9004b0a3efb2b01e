#!/usr/bin/env bash
# Shows that capi/abi/check_abi.sh (with capi/abi/embra.abignore) accepts the compatible changes and
# refuses the incompatible ones, on a miniature of embra.h built in variants (abi_fixture/).
# The headers directory given to abidw/abidiff must be where the DWARF says the header is (here the
# fixture's own folder, for embra the source tree's capi/include): types declared elsewhere count as
# private and are filtered out.
# usage: check_abi_selftest.sh CC CHECK_ABI_SH WORK_DIR
set -uo pipefail
cc=${1:?usage: check_abi_selftest.sh CC CHECK_ABI_SH WORK_DIR}
check=${2:?}
work=${3:?}
src=$(cd "$(dirname "$0")/abi_fixture" && pwd)
mkdir -p "$work"
failures=0

build() {  # build VARIANT_DIR [-DFIXTURE_...]
  local dir="$work/$1"
  shift
  mkdir -p "$dir"
  "$cc" -std=c99 -g -O2 -fPIC -shared -fvisibility=hidden -Wl,-soname,libembra.so.0 "$@" -I"$src" \
    -o "$dir/libembra.so.0" "$src/embra_fixture.c" || { echo "FAIL: cannot build $dir"; exit 1; }
}

build base
abidw --headers-dir "$src" --drop-private-types --exported-interfaces-only \
  --suppressions "$(dirname "$check")/embra.abignore" --no-corpus-path --no-comp-dir-path --no-show-locs \
  --out-file "$work/base.abi" "$work/base/libembra.so.0" || { echo "FAIL: abidw"; exit 1; }

expect() {  # expect pass|fail VARIANT [-D...]
  local want=$1 name=$2
  shift 2
  build "$name" "$@"
  if bash "$check" "$work/base.abi" "$work/$name/libembra.so.0" >"$work/$name.log" 2>&1; then
    got=pass
  else
    got=fail
  fi
  if [[ "$got" == "$want" ]]; then
    echo "ok:   $name: expected $want, got $want ($(tail -1 "$work/$name.log"))"
  else
    echo "FAIL: $name: expected the check to $want, it did $got:"
    sed 's/^/      /' "$work/$name.log"
    failures=$((failures + 1))
  fi
}

expect pass unchanged
expect pass added -DFIXTURE_ADDED
expect pass private -DFIXTURE_PRIVATE
expect fail removed -DFIXTURE_REMOVED
expect fail grown_def -DFIXTURE_GROWN_DEF
expect fail parameter -DFIXTURE_PARAMETER
expect fail grown_report -DFIXTURE_GROWN_REPORT

# A library with another SONAME (a bumped ABI version) needs its own baseline.
"$cc" -std=c99 -g -fPIC -shared -fvisibility=hidden -Wl,-soname,libembra.so.1 -I"$src" -o "$work/libembra.so.1" \
  "$src/embra_fixture.c"
if bash "$check" "$work/base.abi" "$work/libembra.so.1" >"$work/soname.log" 2>&1; then
  echo "FAIL: a library with SONAME libembra.so.1 passed against the libembra.so.0 baseline"
  failures=$((failures + 1))
else
  echo "ok:   soname: refused ($(tail -1 "$work/soname.log"))"
fi

[[ $failures -eq 0 ]] && { echo "abi check self-test ok"; exit 0; }
echo "$failures failure(s)"
exit 1
