#!/usr/bin/env bash
# The tests under clang's sanitizers (scripts/test.sh runs this after the Release build's tests),
# each stage in its own build folder of the repository (gitignored), every report fatal:
#
#   asan  build-asan: AddressSanitizer + UndefinedBehaviorSanitizer (-fno-sanitize-recover=all):
#         the tests labelled capi, unit and scenes (tests/CMakeLists.txt says what the labels
#         mean), except those labelled heavy or abi and the long scene runs named below.
#   fuzz  build-fuzz: the libFuzzer targets of tests/fuzz (address + undefined behaviour): every
#         committed regression input, then a fixed number of runs from the seeds (ctest -L fuzz).
#   tsan  build-tsan: ThreadSanitizer: every test labelled threads.
#
# Usage: scripts/sanitize.sh [asan] [fuzz] [tsan]     (no argument: all three, in that order)
#        scripts/sanitize.sh fuzz-build                (only build the fuzz targets: scripts/fuzz.sh)
# Each stage prints how long it took. A finding prints the sanitizer's report and stops here.
# EMBRA_SANITIZE_BUILD_ROOT (default: the repository) is where the build folders go.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh

stages=("$@")
[ ${#stages[@]} -gt 0 ] || stages=(asan fuzz tsan)
jobs=$(nproc 2>/dev/null || echo 2)

# The scene tests that step every example hundreds of frames (scenes.cli, scenes.roundtrip and
# scenes.python_jsonschema, which needs roundtrip's output): minutes in a Release build, beyond
# their time limits under AddressSanitizer. Every example still goes through the loader, a few
# frames of stepping and a save and reload under address and undefined-behaviour checks in the
# fuzz stage (fuzz_scene's seeds).
asan_skip='^scenes\.(cli|roundtrip|python_jsonschema)$'

export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
export TSAN_OPTIONS="${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1}"
if [ -x /usr/lib/llvm-14/bin/llvm-symbolizer ]; then
  export ASAN_SYMBOLIZER_PATH=/usr/lib/llvm-14/bin/llvm-symbolizer
  export TSAN_OPTIONS="$TSAN_OPTIONS:external_symbolizer_path=/usr/lib/llvm-14/bin/llvm-symbolizer"
fi

launcher=()
if command -v ccache >/dev/null 2>&1; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi

root="${EMBRA_SANITIZE_BUILD_ROOT:-.}"

configure() {  # DIR SANITIZERS [CMAKE ARGUMENTS...]
  local dir=$1 sanitizers=$2
  shift 2
  CC=clang-14 CXX=clang++-14 cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DEMBRA_WERROR=ON \
    -DEMBRA_SANITIZE="$sanitizers" -DEMBRA_BUILD_BENCH=OFF -DEMBRA_BUILD_DOTNET=OFF "${launcher[@]}" "$@" >/dev/null
}

for stage in "${stages[@]}"; do
  start=$SECONDS
  echo "embra: sanitizer stage $stage" >&2
  case "$stage" in
    asan)
      configure "$root/build-asan" address,undefined
      cmake --build "$root/build-asan" -j "$jobs"
      ctest --test-dir "$root/build-asan" --output-on-failure -j "$jobs" -L '^(capi|unit|scenes)$' \
        -LE '^(heavy|abi)$' -E "$asan_skip"
      ;;
    fuzz | fuzz-build)
      configure "$root/build-fuzz" address,undefined -DEMBRA_BUILD_FUZZ=ON
      cmake --build "$root/build-fuzz" -j "$jobs" --target fuzz_scene fuzz_capi fuzz_scene_dict
      [ "$stage" = fuzz-build ] || ctest --test-dir "$root/build-fuzz" --output-on-failure -j "$jobs" -L '^fuzz$'
      ;;
    tsan)
      configure "$root/build-tsan" thread
      cmake --build "$root/build-tsan" -j "$jobs"
      ctest --test-dir "$root/build-tsan" --output-on-failure -j "$jobs" -L '^threads$' --no-tests=error
      ;;
    *)
      echo "sanitize.sh: unknown stage '$stage' (asan, fuzz or tsan)" >&2
      exit 2
      ;;
  esac
  echo "embra: sanitizer stage $stage took $((SECONDS - start)) s" >&2
done
