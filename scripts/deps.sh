#!/usr/bin/env bash
# Installs what embra needs to build and test, from Debian's packages only.
# As root it runs apt-get; otherwise it names the missing packages and stops.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libeigen3-dev libccd-dev nlohmann-json3-dev libvalijson-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  clang-format binutils
  clang-14 libclang-rt-14-dev llvm-14
  python3-jsonschema
  python3-pytest python3-numpy python3-matplotlib
  python3-distributed python3-dask
  mono-mcs nunit-console libnunit-cil-dev
  abigail-tools
  chromium
  # The Windows cross-build and its tests (scripts/windows.sh): the -posix compilers of
  # g++-mingw-w64-x86-64 only (the toolchain file's; the -win32 ones would add 180 MB), and wine64.
  g++-mingw-w64-x86-64-posix wine64
)
# Node.js and npm: the Node adapter, embra-live and the page. Any Node >= 18 will do; Debian 12's
# nodejs is 18. A machine with Node from elsewhere (nodesource ships npm inside its nodejs) keeps it.
command -v node >/dev/null 2>&1 || packages+=(nodejs)
command -v npm >/dev/null 2>&1 || packages+=(npm)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -eq 0 ]; then
    echo "embra: installing ${missing[*]}" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
  else
    echo "embra: missing Debian packages: ${missing[*]}" >&2
    echo "embra: install them with: sudo apt-get install ${missing[*]}" >&2
    exit 1
  fi
fi

# npm packages, exactly as locked (package-lock.json), into each package's node_modules; skipped
# when node_modules was installed from the same lock (a stamp of its sha256).
root="$(cd "$(dirname "$0")/.." && pwd)"
for dir in host_adapters/node host_adapters/web; do
  sum=$(sha256sum "$root/$dir/package-lock.json" | cut -d' ' -f1)
  stamp="$root/$dir/node_modules/.embra-lock-sha256"
  if [ "$(cat "$stamp" 2>/dev/null)" != "$sum" ]; then
    echo "embra: npm ci in $dir" >&2
    (cd "$root/$dir" && npm ci --no-audit --no-fund --loglevel=error >&2)
    echo "$sum" >"$stamp"
  fi
done
