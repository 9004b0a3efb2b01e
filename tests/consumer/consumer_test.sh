#!/usr/bin/env bash
# `cmake --install` into a fresh prefix, then builds and runs a small host against what was
# installed: with find_package(embra) (CMake) and with pkg-config; and, when given their tools,
# the installed Python package and C# assembly, with nothing pointing at the build tree.
# usage: consumer_test.sh BUILD_DIR WORK_DIR C_COMPILER [PYTHON] [MCS]
set -euo pipefail
build=${1:?usage: consumer_test.sh BUILD_DIR WORK_DIR C_COMPILER [PYTHON] [MCS]}
work=${2:?}
cc=${3:?}
python=${4:-}
mcs=${5:-}
unset EMBRA_LIBRARY LD_LIBRARY_PATH
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work"
mkdir -p "$work"
prefix="$work/prefix"

cmake --install "$build" --prefix "$prefix" >"$work/install.log"
libdir=$(dirname "$(find "$prefix" -name 'libembra.so' | head -1)")
for f in include/embra/embra.h include/embra/embra_export.h include/embra/embra_version.h; do
  [[ -f "$prefix/$f" ]] || { echo "FAIL: not installed: $f"; exit 1; }
done
[[ -f "$libdir/cmake/embra/embraConfig.cmake" && -f "$libdir/pkgconfig/embra.pc" ]] ||
  { echo "FAIL: no CMake package or pkg-config file under $libdir"; exit 1; }
soname=$(readelf -d "$libdir/libembra.so" | sed -n 's/.*(SONAME).*\[\(.*\)\].*/\1/p')
[[ -e "$libdir/$soname" ]] || { echo "FAIL: the SONAME link $soname is not installed"; exit 1; }
echo "ok:   installed header, $soname, CMake package and pkg-config file under $prefix"

# 1. CMake: find_package(embra) from the installed prefix only.
cmake -S "$here" -B "$work/cmake-build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_C_COMPILER="$cc" >"$work/cmake.log"
cmake --build "$work/cmake-build" >>"$work/cmake.log"
"$work/cmake-build/embra_consumer" | tee "$work/cmake-run.log"
grep -q "consumer ok" "$work/cmake-run.log"
echo "ok:   find_package(embra) consumer built and ran"

# 2. pkg-config, with the installed (relocatable) .pc file, its flags alone (they carry the run path:
#    the consumer runs with no LD_LIBRARY_PATH).
export PKG_CONFIG_PATH="$libdir/pkgconfig"
read -r -a flags <<<"$(pkg-config --cflags --libs embra)"
"$cc" -std=c99 -Wall -Wextra -Wpedantic -Werror -o "$work/pc-consumer" "$here/consumer.c" "${flags[@]}" -lm
"$work/pc-consumer" | tee "$work/pc-run.log"
grep -q "consumer ok" "$work/pc-run.log"
[[ "$(pkg-config --modversion embra)" == "$(sed -n 's/.*EMBRA_VERSION_STRING "\(.*\)"/\1/p' "$prefix/include/embra/embra_version.h")" ]] ||
  { echo "FAIL: pkg-config version differs from embra_version.h"; exit 1; }
echo "ok:   pkg-config consumer built and ran"

# 3. The installed command runs from the prefix, moved elsewhere too (its run path is relative).
"$prefix/bin/embra" version | tee "$work/cli-run.log"
grep -q "^embra .*(ABI [0-9]*)" "$work/cli-run.log" || { echo "FAIL: the installed embra did not run"; exit 1; }
cp -a "$prefix" "$work/moved"
"$work/moved/bin/embra" version >/dev/null || { echo "FAIL: the installed embra did not run from a moved prefix"; exit 1; }
echo "ok:   installed embra ran (and from a moved prefix) with no LD_LIBRARY_PATH"

# 4. Python: the installed package finds the installed library by itself.
if [[ -n "$python" ]]; then
  PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$libdir/python3/dist-packages" "$python" "$here/consumer.py" |
    tee "$work/py-run.log"
  grep -q "from $libdir/libembra.so" "$work/py-run.log" || { echo "FAIL: Python did not load the installed library"; exit 1; }
  grep -q "consumer ok" "$work/py-run.log"
  echo "ok:   Python consumer ran on the installed package"
fi

# 5. C#: compiled against the installed Embra.Net.dll, which finds libembra.so beside itself.
if [[ -n "$mcs" ]]; then
  "$mcs" -nologo -warnaserror+ -r:"$libdir/Embra.Net.dll" -out:"$work/Consumer.exe" "$here/Consumer.cs"
  MONO_PATH="$libdir" mono "$work/Consumer.exe" | tee "$work/cs-run.log"
  grep -q "consumer ok" "$work/cs-run.log"
  echo "ok:   C# consumer ran on the installed assembly"
fi
echo "consumer test ok"
