"""Where the package looks for libembra on each platform (embra._capi._candidates): $EMBRA_LIBRARY
alone when set; else beside the package, its folder, an installed prefix's library folder (and on
Windows its bin folder, where cmake --install puts a DLL), each by the platform's file name."""

import os

from embra import _capi


def layout(tmp_path, files):
    """A prefix tmp/prefix with the package at lib/python3/dist-packages/embra and `files` made."""
    here = tmp_path / "prefix" / "lib" / "python3" / "dist-packages" / "embra"
    here.mkdir(parents=True)
    for f in files:
        (tmp_path / "prefix" / f).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / "prefix" / f).write_bytes(b"")
    return str(here)


def found(platform, here, environ=None):
    return [p for p in _capi._candidates(platform, here, environ or {}) if os.path.isabs(p)]


def test_the_environment_variable_alone():
    assert list(_capi._candidates("win32", "/nowhere", {"EMBRA_LIBRARY": r"C:\embra\embra.dll"})) == [
        r"C:\embra\embra.dll"]


def test_windows_finds_embra_dll_beside_the_package_first(tmp_path):
    here = layout(tmp_path, ["lib/python3/dist-packages/embra/embra.dll", "bin/embra.dll",
                             "lib/python3/dist-packages/embra/libembra.so.%d" % _capi.ABI_VERSION])
    paths = found("win32", here)
    assert paths[0] == os.path.join(here, "embra.dll")
    assert os.path.join(str(tmp_path / "prefix" / "bin"), "embra.dll") in paths
    assert not any(p.endswith(".so.%d" % _capi.ABI_VERSION) for p in paths)  # not a Windows library


def test_windows_finds_the_dll_in_an_installed_prefix_bin(tmp_path):
    here = layout(tmp_path, ["bin/embra.dll"])
    assert found("win32", here)[0] == os.path.join(str(tmp_path / "prefix" / "bin"), "embra.dll")


def test_linux_finds_the_soname_beside_the_package_not_a_dll(tmp_path):
    here = layout(tmp_path, ["lib/python3/dist-packages/embra/embra.dll",
                             "lib/python3/dist-packages/embra/libembra.so.%d" % _capi.ABI_VERSION])
    paths = found("linux", here)
    assert paths[0] == os.path.join(here, "libembra.so.%d" % _capi.ABI_VERSION)
    assert not any(p.endswith(".dll") for p in paths)
