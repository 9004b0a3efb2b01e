#!/usr/bin/env bash
# Writes OUT: a 100 MB scene that nests 50,000,000 arrays deep inside the free-form "tolerances"
# object (valid JSON, valid against the schema, far deeper than the 64 levels embra parses).
# Generated at test time into the build folder: too large to commit.
set -euo pipefail
out="$1"
n=50000000
mkdir -p "$(dirname "$out")"
tmp="$out.part"
{
  printf '{"format": "embra-scene", "version": 1, "tolerances": {"x": '
  head -c "$n" /dev/zero | tr '\0' '['
  head -c "$n" /dev/zero | tr '\0' ']'
  printf '}}\n'
} >"$tmp"
mv "$tmp" "$out"
