#!/usr/bin/env bash
# Configures and builds embra in build/ (Release, warnings as errors). Used by demo.sh and test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DEMBRA_WERROR=ON >/dev/null
cmake --build build -j "$jobs"
