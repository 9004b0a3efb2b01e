#!/usr/bin/env bash
# Reads a build's output (scripts/build.sh: cmake's "[ 42%] Building ..." lines) on stdin and says
# on stderr how far it is: on a terminal one line rewritten at every percent, otherwise a line at
# every tenth ("build: 40% (Building CXX object ...)"); deps.sh's "embra: ..." lines and compiler
# errors pass through. The whole output is kept in the file named by $1 (for the caller to show when
# the build fails).
set -uo pipefail
log="${1:-/dev/null}"
: >"$log"
tty=0
[ -t 2 ] && tty=1
shown=-1
while IFS= read -r line; do
  printf '%s\n' "$line" >>"$log"
  if [[ $line =~ ^\[\ *([0-9]+)%\]\ (.*)$ ]]; then
    pct=$((10#${BASH_REMATCH[1]}))
    what=${BASH_REMATCH[2]}
    if [ $tty -eq 1 ]; then
      [ "$pct" -ne "$shown" ] && printf '\r\033[Kbuild: %3d%% %.60s' "$pct" "$what" >&2
      shown=$pct
    elif [ $((pct / 10)) -gt $((shown < 0 ? -1 : shown / 10)) ]; then
      printf 'build: %d%% (%s)\n' "$pct" "$what" >&2
      shown=$pct
    fi
  elif [[ $line == embra:* || $line == *error:* || $line == *Error* ]]; then
    [ $tty -eq 1 ] && [ "$shown" -ge 0 ] && printf '\r\033[K' >&2
    printf '%s\n' "$line" >&2
  fi
done
[ $tty -eq 1 ] && [ "$shown" -ge 0 ] && printf '\r\033[K' >&2
exit 0
