#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs the paper's Gaudi tent (figure 6) from
# examples/gaudi_tent.json through the `embra` command: a progress bar, a summary, and in
# out/gaudi_tent/ the final scene (final.json), per-frame metrics (metrics.jsonl) and OBJ frames.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh >/dev/null
./build/host_adapters/cli/embra run examples/gaudi_tent.json --out out/gaudi_tent --every 100 "$@"
