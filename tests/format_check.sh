#!/usr/bin/env bash
# Fails when a C or C++ source of the project is not clang-format'ed (.clang-format at the root).
set -u
cd "$(dirname "$0")/.."
command -v clang-format >/dev/null || { echo "clang-format not installed"; exit 1; }
files=$(git ls-files '*.c' '*.h' '*.cpp' '*.hpp' 2>/dev/null || find core capi host_adapters tests bench -name '*.[ch]' -o -name '*.[ch]pp')
clang-format --dry-run --Werror $files && echo "$(echo "$files" | wc -w) files formatted"
