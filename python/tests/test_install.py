"""cmake --install puts a module that imports from the installed tree alone, in a folder that
is on /usr/bin/python3's own sys.path under the default prefix."""
import os
import subprocess
import sys

import pytest

BUILD_DIR = os.environ.get("MULTIBIN_BUILD_DIR", "")
MODULE_DIR = os.environ.get("MULTIBIN_PYTHON_INSTALL_DIR", "")


def test_the_installed_module_imports_from_the_installed_tree_alone(tmp_path):
    if not BUILD_DIR or not MODULE_DIR:
        pytest.skip("MULTIBIN_BUILD_DIR / MULTIBIN_PYTHON_INSTALL_DIR not set (run through ctest)")
    prefix = tmp_path / "prefix"
    subprocess.run([os.environ.get("CMAKE_COMMAND", "cmake"), "--install", BUILD_DIR,
                    "--prefix", str(prefix)], check=True, capture_output=True)
    env = {k: v for k, v in os.environ.items() if k != "LD_LIBRARY_PATH"}
    env["PYTHONPATH"] = str(prefix / MODULE_DIR)  # its RUNPATH must find the library
    run = subprocess.run([sys.executable, "-c",
                          "import multibin; multibin.ElevationMap(resolution_m=0.05); "
                          "print(multibin.__file__)"],
                         check=True, capture_output=True, text=True, env=env)
    assert run.stdout.startswith(str(prefix / MODULE_DIR / "multibin"))
    assert "/usr/local/" + MODULE_DIR in sys.path  # the default prefix needs no PYTHONPATH
