#!/usr/bin/env bash
# Prints the SHA-256 of every example's final.json after 100 frames (examples/*.json and
# examples/large/*.json), one line per example: the check that a change which must not change
# behaviour (a refactor) did not. Run it before and after, and compare:
#
#   scripts/example_hashes.sh [BUILD_DIR] > before.txt     (BUILD_DIR default: build)
#   ... change, rebuild ...
#   scripts/example_hashes.sh [BUILD_DIR] | diff before.txt -
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
embra="$build/host_adapters/cli/embra"
[ -x "$embra" ] || { echo "example_hashes.sh: no $embra (build first)" >&2; exit 2; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for scene in examples/*.json examples/large/*.json; do
  name="${scene#examples/}"
  out="$work/${name//\//_}"
  "$embra" run "$scene" --frames 100 --every 1000000 --out "$out" >/dev/null
  printf '%s  %s\n' "$(sha256sum <"$out/final.json" | cut -d' ' -f1)" "$name"
done
