#!/usr/bin/env bash
# The solver's kernel sets (scalar, 2-wide SSE2, 4-wide AVX2; chosen at run time, EMBRA_KERNELS
# forces one) compute the same bits: a draped cloth (distance and dihedral kernels), a pinned cloth
# (chain, dihedral and automatic tether kernels), a welded panel mesh and one with its corners shared
# (distance, planarity and plane-offset kernels, island by island) stepped with each set end in
# byte-identical final.json files. So do the panel meshes with their islands' rows projected one at
# a time by the pass kernels (EMBRA_ISLANDS=rows), and the welded mesh with its rows in their passes
# instead of islands (EMBRA_ISLANDS=off: a welded panel's rows touch no other panel's; shared
# corners' panels, coloured, take their rows in another order than the passes). The shared mesh
# (examples/large/poq_drape_16.json) projects its rows in single precision ("precision": "single":
# 1, 8 and 4 floats a block in the three sets), whose bits are its own: it is checked across the
# kernel sets as it is, and against the pass kernels with its precision set to "full".
#
# usage: kernels_same_bits.sh EMBRA_CLI SOURCE_DIR WORK_DIR
set -u
cli=$1 source=$2 work=$3
mkdir -p "$work"
full16=$work/poq_drape_16_full.json
sed 's/"precision": "single"/"precision": "full"/' "$source/examples/large/poq_drape_16.json" >"$full16"
if ! grep -q '"precision": "full"' "$full16"; then echo "FAIL: poq_drape_16.json no longer says its precision"; exit 1; fi
fail=0
for scene in examples/cloth_drape.json:60 tests/scenes/kernels/pinned_cloth.json:90 examples/poq_drape.json:120 \
  examples/large/poq_drape_16.json:40 "$full16":40; do
  path=${scene%%:*} frames=${scene##*:} name=$(basename "${scene%%:*}" .json)
  [ "${path#/}" = "$path" ] && path=$source/$path
  first=""
  for set in scalar vec2 avx2 rows passes; do
    if [ "$set" = avx2 ] && ! grep -q avx2 /proc/cpuinfo; then continue; fi
    if [ "$set" = passes ] && [ "${name#poq_drape_16}" != "$name" ]; then continue; fi  # shared corners
    if [ "$set" = rows ] && [ "$name" = poq_drape_16 ]; then continue; fi               # single precision
    kernels=$set islands=on
    if [ "$set" = rows ]; then kernels="" islands=rows; fi
    if [ "$set" = passes ]; then kernels="" islands=off; fi
    out=$work/$name.$set
    rm -rf "$out"  # the work folder stays between runs; `embra run` refuses a non-empty --out
    if ! EMBRA_KERNELS=$kernels EMBRA_ISLANDS=$islands "$cli" run "$path" --frames "$frames" --out "$out" --every 100000 >"$out.log" 2>&1; then
      echo "FAIL $name with $set kernels: embra run exited non-zero"; cat "$out.log"; fail=1; continue
    fi
    sum=$(sha256sum "$out/final.json" | cut -d' ' -f1)
    echo "$name $set $sum"
    if [ -z "$first" ]; then first=$sum; elif [ "$sum" != "$first" ]; then
      echo "FAIL $name: the $set kernels give different bits"; fail=1
    fi
  done
done
exit $fail
