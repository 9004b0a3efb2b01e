#!/usr/bin/env bash
# Installs what embra needs to build and test, from Debian's packages only.
# As root it runs apt-get; otherwise it names the missing packages and stops.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libeigen3-dev libccd-dev nlohmann-json3-dev libvalijson-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  clang-format binutils
  python3-jsonschema
  python3-pytest python3-numpy
  mono-mcs nunit-console libnunit-cil-dev
  abigail-tools
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

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
