"""Shared setup of the Python adapter tests.

Environment (set by tests/adapters/CMakeLists.txt): EMBRA_LIBRARY (libembra.so), EMBRA_CLI (the
`embra` command, the C reference), EMBRA_SOURCE_DIR (the repository), and EMBRA_TEST_NO_NUMPY=1 to
run everything as on a machine without numpy.
"""

import os
import subprocess
import sys

import pytest

if os.environ.get("EMBRA_TEST_NO_NUMPY") == "1":
    sys.modules["numpy"] = None  # `import numpy` now raises ImportError, as without numpy installed

sys.path.insert(0, os.path.join(os.environ.get("EMBRA_SOURCE_DIR", ""), "host_adapters", "python"))
sys.path.insert(0, os.path.dirname(__file__))

import embra  # noqa: E402


def pytest_report_header(config):
    return f"embra {embra.version_string()} from {embra.library_path}; numpy: {embra.have_numpy()}"


@pytest.fixture(scope="session")
def source_dir():
    return os.environ["EMBRA_SOURCE_DIR"]


@pytest.fixture(scope="session")
def cli():
    return os.environ["EMBRA_CLI"]


def read_obj_vertices(path):
    """The 'v' lines of an OBJ written by the `embra` command (%.17g: every double exactly)."""
    out = []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                out.extend(float(t) for t in line.split()[1:4])
    return out


@pytest.fixture(scope="session")
def c_tent_demo(cli, tmp_path_factory):
    """Positions after 100 frames of `embra demo tent` (the tent built through the C ABI in C)."""
    out = tmp_path_factory.mktemp("c_demo")
    subprocess.run([cli, "demo", "tent", "--frames", "100", "--every", "1000", "--out", str(out)], check=True,
                   stdout=subprocess.DEVNULL)
    return read_obj_vertices(out / "final.obj")


@pytest.fixture(scope="session")
def c_tent_scene(cli, source_dir, tmp_path_factory):
    """Positions after 100 frames of `embra run examples/gaudi_tent.json` (the scene loaded in C)."""
    out = tmp_path_factory.mktemp("c_scene")
    subprocess.run([cli, "run", os.path.join(source_dir, "examples", "gaudi_tent.json"), "--frames", "100", "--out",
                    str(out)], check=True, stdout=subprocess.DEVNULL)
    return read_obj_vertices(out / "final.obj")
