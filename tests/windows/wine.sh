#!/usr/bin/env bash
# Runs a Windows program under Debian's wine64, headless: the cross-build's ctest runs every test
# program through it (CMAKE_CROSSCOMPILING_EMULATOR, cmake/mingw-w64-x86_64.cmake).
#
# usage: wine.sh PREFIX PROGRAM.exe [ARGS...]
#   PREFIX  the wine prefix (a folder inside the build folder), made on first use.
# Exits with the program's exit code; 125 (and why, on stderr) when wine cannot start.
set -euo pipefail
prefix=${1:?usage: wine.sh PREFIX PROGRAM.exe [ARGS...]}
shift
wine=$(command -v wine64 || true)
[[ -n "$wine" ]] || wine=/usr/lib/wine/wine64  # Debian's wine64 without the wine package's wrapper
if [[ ! -x "$wine" ]]; then
  echo "wine.sh: no wine64 (Debian package wine64; scripts/deps.sh installs it)" >&2
  exit 125
fi
# UTF-8 arguments and file names whatever the locale of the caller.
export WINEPREFIX=$prefix WINEDEBUG=-all WINEARCH=win64 LC_ALL=C.UTF-8
# No Mono or Gecko installer (their prompt would wait for a display), no display at all.
export WINEDLLOVERRIDES="mscoree,mshtml=" DISPLAY=
unset WAYLAND_DISPLAY
if [[ ! -f "$prefix/system.reg" ]]; then
  # The first use makes the prefix (about 10 s); parallel tests wait for it instead of racing.
  mkdir -p "$prefix"
  (
    flock 9
    if [[ ! -f "$prefix/system.reg" ]]; then
      "$wine" wineboot --init >/dev/null 2>&1 || true
      "$(dirname "$wine")/wineserver" -w 2>/dev/null || wineserver -w 2>/dev/null || true
    fi
  ) 9>"$prefix.lock"
  if [[ ! -f "$prefix/system.reg" ]]; then
    echo "wine.sh: wine64 could not make a prefix in $prefix" >&2
    exit 125
  fi
fi
exec "$wine" "$@"
