"""A PEP 517 build backend for the package `embra`, with the standard library alone.

pip calls build_wheel (pip install, pip wheel) from pyproject.toml's [build-system]. The wheel holds
embra/*.py, the sweep schema (schemas/sweep.schema.json, for embra.sweeps) and the built library
as embra/libembra.so.<ABI>, where embra/_capi.py looks first, so an
installed `import embra` needs no environment variable. The library is the one named by the
config setting `library` (pip --config-settings library=PATH), else $EMBRA_LIBRARY, else the
repository's build (build/libembra.so.<ABI>, what scripts/build.sh makes). Nothing is downloaded
and nothing is written in the source folder.
"""

import base64
import ctypes
import hashlib
import os
import re
import sysconfig
import tomllib
import zipfile

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # host_adapters/python
PACKAGE = os.path.join(HERE, "embra")
REPOSITORY = os.path.dirname(os.path.dirname(HERE))


def _abi_version():
    with open(os.path.join(PACKAGE, "_capi_generated.py")) as f:
        match = re.search(r"^ABI_VERSION = (\d+)$", f.read(), re.M)
    if not match:
        raise RuntimeError("embra: no ABI_VERSION in embra/_capi_generated.py")
    return int(match.group(1))


def _library(config_settings):
    abi = _abi_version()
    given = (config_settings or {}).get("library") or os.environ.get("EMBRA_LIBRARY")
    path = given or os.path.join(REPOSITORY, "build", f"libembra.so.{abi}")
    if not os.path.isfile(path):
        raise RuntimeError(f"embra: no library at {path}: build it first (bash scripts/build.sh), or name it "
                           "with --config-settings library=PATH")
    lib = ctypes.CDLL(os.path.realpath(path))
    lib.embra_abi_version.restype = ctypes.c_int32
    lib.embra_version_string.restype = ctypes.c_char_p
    if lib.embra_abi_version() != abi:
        raise RuntimeError(f"embra: {path} has ABI {lib.embra_abi_version()}, these bindings {abi}: rebuild")
    return os.path.realpath(path), abi, lib.embra_version_string().decode()


def _project():
    with open(os.path.join(HERE, "pyproject.toml"), "rb") as f:
        return tomllib.load(f)["project"]


def _metadata(version):
    p = _project()
    lines = ["Metadata-Version: 2.1", f"Name: {p['name']}", f"Version: {version}", f"Summary: {p['description']}",
             f"Requires-Python: {p['requires-python']}"]
    for extra, requirements in p.get("optional-dependencies", {}).items():
        lines.append(f"Provides-Extra: {extra}")
        lines += [f'Requires-Dist: {r}; extra == "{extra}"' for r in requirements]
    with open(os.path.join(HERE, "README.md")) as f:
        return "\n".join(lines) + "\nDescription-Content-Type: text/markdown\n\n" + f.read()


def _tag():
    return "py3-none-" + re.sub(r"[^A-Za-z0-9]", "_", sysconfig.get_platform())


def _wheel_file():
    return f"Wheel-Version: 1.0\nGenerator: embra_backend\nRoot-Is-Purelib: false\nTag: {_tag()}\n"


def _entry_points():
    """[project.scripts] as the wheel's console scripts (embra-sweep)."""
    lines = ["[console_scripts]"] + [f"{name} = {target}" for name, target in _project().get("scripts", {}).items()]
    return "\n".join(lines) + "\n"


def _dist_info(version):
    return f"embra-{version}.dist-info"


def _write_dist_info(folder, version):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "METADATA"), "w") as f:
        f.write(_metadata(version))
    with open(os.path.join(folder, "WHEEL"), "w") as f:
        f.write(_wheel_file())
    with open(os.path.join(folder, "entry_points.txt"), "w") as f:
        f.write(_entry_points())


def get_requires_for_build_wheel(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    _, _, version = _library(config_settings)
    _write_dist_info(os.path.join(metadata_directory, _dist_info(version)), version)
    return _dist_info(version)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    library, abi, version = _library(config_settings)
    files = [(os.path.join(PACKAGE, name), f"embra/{name}") for name in sorted(os.listdir(PACKAGE))
             if name.endswith(".py")]
    files.append((os.path.join(REPOSITORY, "schemas", "sweep.schema.json"), "embra/sweep.schema.json"))
    files.append((library, f"embra/libembra.so.{abi}"))
    info = _dist_info(version)
    wheel_name = f"embra-{version}-{_tag()}.whl"
    record = []

    def add(z, arcname, data, mode=0o644):
        entry = zipfile.ZipInfo(arcname, date_time=(1980, 1, 1, 0, 0, 0))
        entry.external_attr = (0o100000 | mode) << 16
        entry.compress_type = zipfile.ZIP_DEFLATED
        z.writestr(entry, data)
        digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
        record.append(f"{arcname},sha256={digest},{len(data)}")

    os.makedirs(wheel_directory, exist_ok=True)
    with zipfile.ZipFile(os.path.join(wheel_directory, wheel_name), "w") as z:
        for source, arcname in files:
            with open(source, "rb") as f:
                add(z, arcname, f.read(), 0o755 if arcname.endswith(f".so.{abi}") else 0o644)
        add(z, f"{info}/METADATA", _metadata(version).encode())
        add(z, f"{info}/WHEEL", _wheel_file().encode())
        add(z, f"{info}/entry_points.txt", _entry_points().encode())
        record.append(f"{info}/RECORD,,")
        z.writestr(zipfile.ZipInfo(f"{info}/RECORD", date_time=(1980, 1, 1, 0, 0, 0)), "\n".join(record) + "\n")
    return wheel_name
