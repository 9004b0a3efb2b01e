#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs the paper's section 4.1 experiment from
# examples/poq_drape.json through the `embra` command: a Planar Offset Quad mesh of 4 x 4 panels
# draped over a sphere that then moves, a progress bar, a summary and the table of fabrication
# metrics against their tolerances; in out/poq_drape/ the final scene (final.json), per-frame
# metrics (metrics.jsonl), OBJ frames and the panels' cut lists (panels_N.json, panels_N.csv).
# (The Gaudi tent of figure 6, the previous main job: embra run examples/gaudi_tent.json.)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh >/dev/null
./build/host_adapters/cli/embra run examples/poq_drape.json --out out/poq_drape --every 100 "$@"
