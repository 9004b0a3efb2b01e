#!/usr/bin/env bash
# Runs a goal-set example as a user would, then checks what `embra run` wrote:
#
#   run_check.sh EMBRA PYTHON EXAMPLES_DIR NAME WORK_DIR
#
# `embra run EXAMPLES_DIR/NAME.json --out WORK_DIR/NAME` (the scene's own frames), then
# check_goal_examples.py NAME WORK_DIR/NAME, whose exit code is the test's.
set -u
embra="$1" python="$2" examples="$3" name="$4" work="$5"
out="$work/$name"
rm -rf "$out"
mkdir -p "$work"
"$embra" run "$examples/$name.json" --out "$out" --every 1000000 >"$work/$name.log" 2>&1 || {
  echo "embra run $name failed:"
  cat "$work/$name.log"
  exit 1
}
"$python" "$(dirname "$0")/check_goal_examples.py" "$name" "$out"
