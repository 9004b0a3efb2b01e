#!/usr/bin/env bash
# Runs every example with the form-finding preset and `--until tolerance` and prints why each
# stopped: the README's scene table, "with the preset" column. Each scene's `solver` is replaced by
# {"preset": "form_finding"} keeping its gravity, tethers, self-collision and settle speed (a copy
# beside the scene, so that the OBJ files it names resolve, removed afterwards).
#   bash scripts/preset_outcomes.sh [EXAMPLE.json ...]     (default: examples/*.json examples/large/*.json)
set -euo pipefail
cd "$(dirname "$0")/.."
embra=build/host_adapters/cli/embra
[ -x "$embra" ] || { echo "build first: bash scripts/build.sh" >&2; exit 1; }
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(examples/*.json examples/large/*.json)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .json)
  copy="$(dirname "$scene")/.preset_$name.json"
  python3 - "$scene" "$copy" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
own = scene.get("solver", {})
solver = {"preset": "form_finding"}
for key in ("gravity", "tethers", "self_collision", "settle_speed"):
    if key in own:
        solver[key] = own[key]
scene["solver"] = solver
json.dump(scene, open(sys.argv[2], "w"))
PY
  start=$SECONDS
  line=$(timeout 300 "$embra" run "$copy" --until tolerance --out "$out/$name" --force 2>&1 | grep -E '^stopped|failed|error|non-finite' | head -n 1 || true)
  rm -f "$copy"
  echo "$name: ${line:-no verdict within 300 s} ($((SECONDS - start)) s)"
done
