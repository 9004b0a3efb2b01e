#!/usr/bin/env bash
# The main job: installs what is missing, builds (saying how far the build is), and runs the paper's
# section 4.1 experiment from examples/poq_drape.json through the `embra` command: a Planar Offset
# Quad mesh of 4 x 4 panels draped over a sphere that then moves, a progress bar, a summary and the
# table of fabrication metrics against their tolerances; in out/poq_drape/ (replaced at every run)
# the final scene (final.json), per-frame metrics (metrics.jsonl), OBJ frames and the panels' cut
# lists (panels_N.json, panels_N.csv).
# (The Gaudi tent of figure 6, the previous main job: embra run examples/gaudi_tent.json.)
set -euo pipefail
cd "$(dirname "$0")/.."
log=$(mktemp)
trap 'rm -f "$log"' EXIT
echo "demo: building embra in build/ (a first build takes several minutes on 2 cores)" >&2
start=$SECONDS
if ! bash scripts/build.sh 2>&1 | bash scripts/build_progress.sh "$log"; then
  echo "demo: the build failed; its last lines:" >&2
  tail -n 30 "$log" >&2
  exit 1
fi
echo "demo: built in $((SECONDS - start)) s; running examples/poq_drape.json" >&2
./build/host_adapters/cli/embra run examples/poq_drape.json --out out/poq_drape --every 100 --force "$@"
