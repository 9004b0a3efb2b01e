#!/usr/bin/env bash
# Checks libembra.so's dynamic symbol table and SONAME, or embra.dll's export table and name:
#   1. every exported (defined, dynamic) symbol starts with embra_, apart from the linker's own
#      bookkeeping symbols listed in IGNORED below;
#   2. every function embra.h declares with EMBRA_API is exported, and every exported embra_
#      symbol is declared in embra.h (no private helper leaks out, no declared function is missing);
#   3. the SONAME is libembra.so.<EMBRA_ABI_VERSION> (a DLL: its export table names it embra.dll).
#
# usage: check_exports.sh <path/to/libembra.so or embra.dll> <path/to/embra.h> <abi_version>
set -euo pipefail

lib=${1:?usage: check_exports.sh LIB HEADER ABI_VERSION}
header=${2:?usage: check_exports.sh LIB HEADER ABI_VERSION}
abi=${3:?usage: check_exports.sh LIB HEADER ABI_VERSION}

# Linker-defined symbols that may appear in a shared object's dynamic table; not part of the API.
IGNORED=(_init _fini _edata _end __bss_start __end__ _etext __data_start __dso_handle _DYNAMIC
         _GLOBAL_OFFSET_TABLE_ __TMC_END__ __GNU_EH_FRAME_HDR)

failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
pass() { echo "ok:   $*"; }

[[ -f "$lib" ]] || { echo "FAIL: no library at $lib"; exit 1; }
[[ -f "$header" ]] || { echo "FAIL: no header at $header"; exit 1; }

dll=0
[[ "$lib" == *.dll ]] && dll=1
if [[ $dll -eq 1 ]]; then
  # The export table as `objdump -p` prints it: "\t[   N] name" under "[Ordinal/Name Pointer] Table".
  objdump=$(command -v x86_64-w64-mingw32-objdump || command -v objdump)
  mapfile -t exported < <("$objdump" -p "$lib" |
                          sed -n '/\[Ordinal\/Name Pointer\] Table/,/^$/p' | sed -n 's/^\s*\[ *[0-9]*\] //p' | sort -u)
  [[ ${#exported[@]} -gt 0 ]] || fail "$objdump -p $lib listed no exports"
else
  # Names only (strip versions such as @@GLIBC_...); `nm -D --defined-only` prints "addr type name".
  mapfile -t exported < <(nm -D --defined-only "$lib" | awk 'NF >= 3 { print $3 }' | sed 's/@.*//' | sort -u)
  [[ ${#exported[@]} -gt 0 ]] || fail "nm -D --defined-only $lib printed no symbols"
fi

is_ignored() {
  local s=$1 i
  for i in "${IGNORED[@]}"; do [[ "$s" == "$i" ]] && return 0; done
  return 1
}

api=()
for s in "${exported[@]}"; do
  if is_ignored "$s"; then
    echo "      ignored linker symbol: $s"
  elif [[ "$s" == embra_* ]]; then
    api+=("$s")
  else
    fail "exported symbol does not start with embra_: $s"
  fi
done
pass "${#api[@]} exported embra_ symbols"

# Functions declared in the header: "EMBRA_API <type> embra_name(" (possibly across lines).
mapfile -t declared < <(tr '\n' ' ' < "$header" | grep -o 'EMBRA_API[^;(]*(' |
                        grep -o 'embra_[A-Za-z0-9_]*[[:space:]]*($' | sed 's/[[:space:]]*($//' | sort -u)
[[ ${#declared[@]} -gt 0 ]] || fail "found no EMBRA_API declarations in $header"
pass "${#declared[@]} EMBRA_API functions declared in embra.h"

missing=$(comm -23 <(printf '%s\n' "${declared[@]}") <(printf '%s\n' "${api[@]}"))
extra=$(comm -13 <(printf '%s\n' "${declared[@]}") <(printf '%s\n' "${api[@]}"))
[[ -z "$missing" ]] || fail "declared in embra.h but not exported: $(echo $missing)"
[[ -z "$extra" ]] || fail "exported but not declared in embra.h: $(echo $extra)"
[[ -z "$missing" && -z "$extra" ]] && pass "exports and header declarations match"

if [[ $dll -eq 1 ]]; then
  # A DLL has no SONAME: hosts load it by its file name, which its export table repeats.
  name=$("$objdump" -p "$lib" | sed -n 's/^Name[[:space:]]*[0-9a-f]* //p' | head -1)
  if [[ "$name" == "embra.dll" ]]; then
    pass "the export table names embra.dll"
  else
    fail "the export table names '${name}', expected embra.dll"
  fi
elif soname=$(readelf -d "$lib" | sed -n 's/.*(SONAME).*\[\(.*\)\].*/\1/p') && [[ "$soname" == "libembra.so.$abi" ]]; then
  pass "SONAME is $soname"
else
  fail "SONAME is '${soname}', expected libembra.so.$abi"
fi

if [[ $failures -eq 0 ]]; then
  echo "exports ok"
  exit 0
fi
echo "$failures failure(s)"
exit 1
