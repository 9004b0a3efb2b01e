#!/usr/bin/env bash
# Runs every test: installs what is missing, builds (warnings as errors) and runs ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
jobs=$(nproc 2>/dev/null || echo 2)
ctest --test-dir build --output-on-failure -j "$jobs"
