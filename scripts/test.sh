#!/usr/bin/env bash
# Runs every test: installs what is missing, builds (warnings as errors) and runs ctest, then the
# tests under the sanitizers and the fuzz targets' regressions and short runs (scripts/sanitize.sh:
# AddressSanitizer + UndefinedBehaviorSanitizer, libFuzzer, ThreadSanitizer, each with clang in its
# own build folder), then the Windows cross-build and its tests under wine64 (scripts/windows.sh). Each
# stage prints how long it took.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
bash scripts/build.sh
jobs=$(nproc 2>/dev/null || echo 2)
ctest --test-dir build --output-on-failure -j "$jobs"
echo "embra: build and tests took $((SECONDS - start)) s" >&2
bash scripts/sanitize.sh
bash scripts/windows.sh
echo "embra: all tests took $((SECONDS - start)) s" >&2
