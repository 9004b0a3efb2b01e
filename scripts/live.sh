#!/usr/bin/env bash
# The live view: installs what is missing, builds the library and the page, and serves a scene with
# embra-live on http://127.0.0.1:8710/ (loopback only). Stop it with Ctrl-C.
#   bash scripts/live.sh [SCENE.json] [embra-live options: --port P, --save-dir DIR, ...]
# (default scene: examples/poq_drape.json; saved designs and exports go to out/live/)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh >/dev/null
(cd host_adapters/web && npm run --silent build >/dev/null)
scene="${1:-examples/poq_drape.json}"
[ $# -gt 0 ] && shift
mkdir -p out/live
EMBRA_LIBRARY="$PWD/build/libembra.so" exec node host_adapters/node/live/embra-live.js "$scene" --save-dir out/live "$@"
