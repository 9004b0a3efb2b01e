#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs the Gaudi tent (the paper's figure 6)
# through the C ABI, printing convergence and writing OBJ files to out/tent/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh >/dev/null
./build/host_adapters/cli/embra demo tent --out out/tent "$@"
