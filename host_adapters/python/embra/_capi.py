"""The C ABI of libembra as ctypes sees it, loaded: the generated mirror and the library.

The structs, constants, enums and the table of prototypes are generated from
``capi/include/embra/embra.h`` into ``_capi_generated.py`` by ``scripts/gen_bindings.py`` (run it after
changing the header; the test ``bindings.fresh`` fails while a generated file is stale). This module
finds libembra and gives every prototype its ctypes types.
"""

import ctypes
import ctypes.util
import os
import sys

from ._capi_generated import *  # noqa: F401,F403 - the whole mirror is this module's interface
from ._capi_generated import ABI_VERSION, PROTOTYPES, _Id  # noqa: F401 - _Id: the id structs' base, used by world.py

LIBRARY_ENV = "EMBRA_LIBRARY"


def _library_names(platform):
    """The file names libembra has on `platform` (sys.platform), the usual first."""
    if platform.startswith("linux"):
        return [f"libembra.so.{ABI_VERSION}", "libembra.so"]
    if platform == "win32":
        return ["embra.dll"]
    if platform == "darwin":
        return [f"libembra.{ABI_VERSION}.dylib", "libembra.dylib"]
    return ["libembra.so"]


def _candidates(platform=sys.platform, here=None, environ=os.environ):
    """Where libembra is looked for, in order: $EMBRA_LIBRARY, next to this package, the system."""
    env = environ.get(LIBRARY_ENV)
    if env:
        yield env
        return
    here = here or os.path.dirname(os.path.abspath(__file__))
    names = _library_names(platform)
    # beside the package (or its folder); then the library folder of an installed prefix, which
    # holds the package in lib/python3/dist-packages/embra (cmake --install), and on Windows the
    # prefix's bin folder, where a DLL is installed
    prefix_lib = os.path.normpath(os.path.join(here, "..", "..", ".."))
    folders = [here, os.path.dirname(here), prefix_lib]
    if platform == "win32":
        folders.append(os.path.join(os.path.dirname(prefix_lib), "bin"))
    for folder in folders:
        for name in names:
            path = os.path.join(folder, name)
            if os.path.exists(path):
                yield path
    # the system: on Windows find_library searches PATH (which LoadLibrary by name no longer does
    # for Python's ctypes), elsewhere the loader's cache
    found = ctypes.util.find_library("embra")
    if found:
        yield found
    yield names[0]  # let the dynamic loader search LD_LIBRARY_PATH and the cache


def _load():
    tried = []
    for path in _candidates():
        try:
            lib = ctypes.CDLL(path)  # CDLL releases the GIL for every call: worlds step in parallel
        except OSError as e:
            tried.append(f"{path}: {e}")
            continue
        for name, (restype, argtypes) in PROTOTYPES.items():
            fn = getattr(lib, name)  # AttributeError names a missing symbol: a library older than these bindings
            fn.restype = restype
            fn.argtypes = argtypes
        return lib, path
    raise OSError("embra: cannot load libembra (set %s to its path); tried:\n  %s" % (LIBRARY_ENV, "\n  ".join(tried)))


lib, library_path = _load()
