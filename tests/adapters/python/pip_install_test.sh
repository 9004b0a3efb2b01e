#!/usr/bin/env bash
# The README's Python install, exactly as a user runs it: a fresh `python3 -m venv`, the README's
# `pip install` line (no network: --no-index, --no-build-isolation), then the README's
# `python -c "import embra; ..."` line, run with no environment but PATH and HOME (no EMBRA_LIBRARY,
# LD_LIBRARY_PATH or PYTHONPATH): the world must step, with the library bundled in the venv.
#   pip_install_test.sh SOURCE_DIR LIBRARY_DIR
# LIBRARY_DIR: the folder of the libembra.so under test. When it is not SOURCE_DIR/build (where
# the package's build backend looks), the install step alone is told where it is (EMBRA_LIBRARY).
set -euo pipefail
src=$1 libdir=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passed=0 failed=0
ok() { passed=$((passed + 1)); }
bad() { echo "FAIL: $*"; failed=$((failed + 1)); }

# The README's three lines (its "Installed with pip" block), verbatim; `~` is HOME, here $tmp.
venv_line=$(grep -m1 '^python3 -m venv ' "$src/README.md")
pip_line=$(grep -m1 'pip install --no-build-isolation --no-index host_adapters/python' "$src/README.md")
run_line=$(grep -m1 'bin/python -c "import embra; w = embra.World()' "$src/README.md")
[ -n "$venv_line" ] && [ -n "$pip_line" ] && [ -n "$run_line" ] && ok || { echo "FAIL: the README's install lines are missing"; exit 1; }
venv=$(printf '%s' "$venv_line" | sed 's/^python3 -m venv //; s|^~|'"$tmp"'|')

clean=(env -i PATH=/usr/bin:/bin HOME="$tmp")
install_env=()
if [ "$(realpath "$libdir")" != "$(realpath -m "$src/build")" ]; then
  install_env=(EMBRA_LIBRARY="$(realpath "$libdir")/libembra.so")
fi
cd "$src"
touch "$tmp/stamp"
"${clean[@]}" bash -c "$venv_line" && ok || bad "$venv_line"
"${clean[@]}" "${install_env[@]}" bash -c "$pip_line" >"$tmp/pip.log" 2>&1 && ok ||
  bad "$pip_line: $(tail -n 20 "$tmp/pip.log")"
out=$("${clean[@]}" bash -c "$run_line" 2>&1) && ok || bad "$run_line: $out"
# One particle let go at z = 1 m falls for 60 frames of 1/60 s (the README prints its position):
# z = 1 - 9.81 * 1^2 / 2 to within the integrator's step (semi-implicit Euler: -3.91 m).
z=$(printf '%s' "$out" | grep -o -- '-3\.9[0-9]*' | head -1)
[ -n "$z" ] && ok || bad "the README's world did not fall as it should: $out"

# Where it came from: the copy of libembra inside the venv, and the package pip recorded.
check=$("${clean[@]}" "$venv/bin/python" -c '
import embra, os, sys
lib = os.path.realpath(embra.library_path)
print("lib", lib.startswith(os.path.realpath(sys.prefix) + os.sep), os.path.basename(lib))
print("abi", embra.abi_version() == embra.ABI_VERSION)
' 2>&1) || true
printf '%s\n' "$check" | grep -q "^lib True libembra.so.[0-9]*$" && ok || bad "libembra not loaded from the venv: $check"
printf '%s\n' "$check" | grep -q "^abi True$" && ok || bad "the bundled library's ABI is not the bindings': $check"
# The console script of [project.scripts] and the sweep schema it validates against, both in the venv.
"${clean[@]}" "$venv/bin/embra-sweep" --help 2>&1 | grep -q "^usage: embra-sweep SWEEP" && ok ||
  bad "the venv has no working embra-sweep command"
schema=$("${clean[@]}" "$venv/bin/python" -c 'import embra.sweeps as s, os, sys
print(os.path.realpath(s.schema_path()).startswith(os.path.realpath(sys.prefix) + os.sep))' 2>&1) || true
[ "$schema" = "True" ] && ok || bad "the sweep schema is not installed beside embra/sweeps.py: $schema"
version=$("${clean[@]}" "$venv/bin/python" -m pip show embra 2>/dev/null | sed -n 's/^Version: //p')
lib_version=$("${clean[@]}" "$venv/bin/python" -c 'import embra; print(embra.version_string())')
[ -n "$version" ] && [ "$version" = "$lib_version" ] && ok || bad "pip's version '$version' is not the library's '$lib_version'"
# Nothing written in the package's source folder but Python's caches of the build backend.
written=$(find "$src/host_adapters/python" -newer "$tmp/stamp" -not -type d -not -path "*/__pycache__/*")
[ -z "$written" ] && ok || bad "pip install wrote into the source folder: $written"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
