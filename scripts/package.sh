#!/usr/bin/env bash
# Release artefacts in out/package/, from the builds scripts/build.sh (build/) and scripts/windows.sh
# (build-windows/) made:
#   embra-<version>-windows-x86_64.zip   bin/embra.dll, bin/embra.exe, lib/libembra.dll.a (import
#                                        library), include/embra/*.h, python/embra (the package with
#                                        embra.dll inside), examples/, README.md
#   embra-<version>-linux-x86_64.tar.gz  `cmake --install build` (lib/libembra.so*, bin/embra,
#                                        include/, the CMake and pkg-config files, the Python package,
#                                        Embra.Net.dll), examples/, README.md
# Debug information is stripped from the copies; nothing is built here. $EMBRA_PACKAGE_OUT,
# $EMBRA_WINDOWS_BUILD and $EMBRA_LINUX_BUILD name other folders (tests/windows/package_test.sh).
#
# usage: scripts/package.sh [windows|linux]...   (both when none is named)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
version=$(sed -n 's/^project(embra VERSION \([0-9.]*\).*/\1/p' CMakeLists.txt)
out=${EMBRA_PACKAGE_OUT:-$root/out/package}
win=${EMBRA_WINDOWS_BUILD:-build-windows}
linux=${EMBRA_LINUX_BUILD:-build}
mkdir -p "$out"
targets=("$@")
[[ ${#targets[@]} -gt 0 ]] || targets=(windows linux)

common() {  # common DIR: the examples and the README
  mkdir -p "$1/examples"
  cp -r examples/. "$1/examples/"
  cp README.md "$1/"
}

for target in "${targets[@]}"; do
  stage=$(mktemp -d)
  case "$target" in
    windows)
      [[ -f $win/bin/embra.dll ]] || { echo "embra: no $win/bin/embra.dll: run scripts/windows.sh --build-only" >&2; exit 1; }
      name=embra-$version-windows-x86_64
      d=$stage/$name
      mkdir -p "$d/bin" "$d/lib" "$d/include/embra" "$d/python"
      x86_64-w64-mingw32-strip --strip-debug -o "$d/bin/embra.dll" $win/bin/embra.dll
      x86_64-w64-mingw32-strip --strip-debug -o "$d/bin/embra.exe" $win/bin/embra.exe
      cp $win/libembra.dll.a "$d/lib/"
      cp capi/include/embra/embra.h capi/include/embra/embra_export.h $win/generated/embra/embra_version.h \
        "$d/include/embra/"
      cp -r host_adapters/python/embra "$d/python/"
      rm -rf "$d/python/embra/__pycache__"
      cp "$d/bin/embra.dll" "$d/python/embra/"  # where the package looks first
      cp -r host_adapters/python/examples "$d/python/"
      common "$d"
      rm -f "$out/$name.zip"
      (cd "$stage" && python3 -m zipfile -c "$out/$name.zip" "$name")
      echo "$out/$name.zip"
      ;;
    linux)
      [[ -f $linux/libembra.so ]] || { echo "embra: no $linux/libembra.so: run scripts/build.sh" >&2; exit 1; }
      name=embra-$version-linux-x86_64
      d=$stage/$name
      cmake --install "$linux" --prefix "$d" --strip >/dev/null
      common "$d"
      tar -C "$stage" -czf "$out/$name.tar.gz" --owner=0 --group=0 "$name"
      echo "$out/$name.tar.gz"
      ;;
    *)
      echo "usage: scripts/package.sh [windows|linux]..." >&2
      exit 1
      ;;
  esac
  rm -rf "$stage"
done
