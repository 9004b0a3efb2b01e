#!/usr/bin/env bash
# Writes into OUT_DIR three scenes whose names are far longer than the schema's 128 characters:
# 30,000 (a group's name), 100,000 (a body's name, a space at its end) and 1,000,000 characters
# (a key of a body's vertex_sets). A name of about 30,000 characters once overflowed the stack in
# std::regex while the schema's pattern was checked; each must be refused with a message.
# Generated at test time into the build folder (1.1 MB together).
set -euo pipefail
out="$1"
mkdir -p "$out"
name() { head -c "$1" /dev/zero | tr '\0' 'a'; }
write() {
  local file="$out/$1"
  shift
  printf '%s\n' "$*" >"$file.part"
  mv "$file.part" "$file"
}
body='"mesh": {"vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "triangles": [[0, 1, 2]]}'
write long_name_30000_group.json \
  "{\"format\": \"embra-scene\", \"version\": 1, \"groups\": [{\"name\": \"$(name 30000)\"}]}"
write long_name_100000_body.json \
  "{\"format\": \"embra-scene\", \"version\": 1, \"bodies\": [{\"name\": \"$(name 99999) \", $body}]}"
write long_name_1000000_vertex_set.json \
  "{\"format\": \"embra-scene\", \"version\": 1, \"bodies\": [{\"name\": \"sail\", $body, \"vertex_sets\": {\"$(name 1000000)\": [0]}}]}"
