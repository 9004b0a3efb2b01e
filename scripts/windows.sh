#!/usr/bin/env bash
# Cross-builds embra for x86-64 Windows in build-windows/ with Debian's mingw-w64 (embra.dll and its
# import library libembra.dll.a, embra.exe, the C-ABI test programs; cmake/mingw-w64-x86_64.cmake)
# and runs its tests under Debian's wine64 (headless, the wine prefix build-windows/wine): the C-ABI
# tests, `embra.exe validate` on every example, UTF-8 names, and `embra.exe run` on every example
# against the Linux build's `embra` (build/, when built: scripts/build.sh) byte for byte.
#
# usage: scripts/windows.sh [--build-only]
# Without wine64 able to start, the tests are skipped and the script says why.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
bash scripts/deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
linux_embra=$PWD/build/host_adapters/cli/embra
[[ -x "$linux_embra" ]] || linux_embra=""
cmake -S . -B build-windows -DCMAKE_TOOLCHAIN_FILE=cmake/mingw-w64-x86_64.cmake -DCMAKE_BUILD_TYPE=Release \
  -DEMBRA_WERROR=ON -DEMBRA_BUILD_BENCH=OFF -DEMBRA_BUILD_DOTNET=OFF -DEMBRA_LINUX_EMBRA="$linux_embra" >/dev/null
cmake --build build-windows -j "$jobs"
echo "embra: Windows cross-build took $((SECONDS - start)) s" >&2
[[ "${1:-}" == "--build-only" ]] && exit 0

# wine64 must start (it makes its prefix on first use, about 20 s); if it cannot, say so and skip.
prefix=$PWD/build-windows/wine
if ! bash tests/windows/wine.sh "$prefix" build-windows/bin/embra.exe version >build-windows/wine-start.log 2>&1 \
  </dev/null; then
  echo "embra: SKIPPED the Windows tests: wine64 cannot start here: $(cat build-windows/wine-start.log)" >&2
  exit 0
fi
[[ -n "$linux_embra" ]] || echo "embra: no Linux build (build/): windows.same_bits is not run" >&2
# One wineserver for the whole run (it would otherwise start again for each program, about 3 s
# each), and wine's own background programs started by a first program whose output goes to a file:
# started by a test, they would hold its output pipe open as long as the server lives.
server=$(command -v wineserver || echo /usr/lib/wine/wineserver)
WINEPREFIX=$prefix "$server" -w
WINEPREFIX=$prefix "$server" -p
trap 'WINEPREFIX=$prefix "$server" -k 2>/dev/null || true' EXIT
bash tests/windows/wine.sh "$prefix" build-windows/bin/embra.exe version >>build-windows/wine-start.log 2>&1 </dev/null
tests=$SECONDS
# The heavy 32 x 32 drape (two minutes natively) is left to the Linux build.
ctest --test-dir build-windows --output-on-failure -j "$jobs" -LE heavy
echo "embra: Windows tests under wine took $((SECONDS - tests)) s" >&2
