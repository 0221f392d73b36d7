"""Shared fixtures of the Python module's tests. ctest sets PYTHONPATH to the built module and
names the programs the tests compare with (python/CMakeLists.txt)."""
import os
import pathlib
import subprocess

import numpy as np
import pytest

import multibin

SOURCE_DIR = pathlib.Path(os.environ.get("MULTIBIN_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[2]))
MAPPER = os.environ.get("MULTIBIN_MAPPER", "")
QUERY_TABLE = os.environ.get("MULTIBIN_QUERY_TABLE", "")
MOCKUP_INI = SOURCE_DIR / "ini" / "mockup.ini"
MOCKUP_RAWLOG = SOURCE_DIR / "rawlogs" / "mockup.rawlog"
MOCKUP_SIMPLEMAP = SOURCE_DIR / "rawlogs" / "mockup.simplemap"


def plane_points(n, seed=1, size_m=1.0, height_m=0.1, sigma_m=0.01):
    """n points on the plane z = height_m over [0, size_m)^2 with isotropic covariance."""
    rng = np.random.default_rng(seed)
    points = np.column_stack([rng.uniform(0, size_m, n), rng.uniform(0, size_m, n),
                              np.full(n, height_m)])
    covariances = np.tile(np.eye(3) * sigma_m**2, (n, 1, 1))
    return points, covariances


@pytest.fixture
def plane_map():
    """A 5 cm map holding a plane at z = 0.1 m over [0, 1) m^2."""
    m = multibin.ElevationMap(resolution_m=0.05)
    m.insert_points(*plane_points(4000))
    return m


@pytest.fixture(scope="session")
def mapper_output(tmp_path_factory):
    """elevation-mapper's run on the shipped mock-up: its folder (elevation_map.bin) and stdout."""
    if not MAPPER:
        pytest.skip("MULTIBIN_MAPPER not set (run through ctest)")
    out = tmp_path_factory.mktemp("mapper")
    run = subprocess.run([MAPPER, "--config", str(MOCKUP_INI), "--rawlog", str(MOCKUP_RAWLOG),
                          "--out", str(out), "--outputs", "map"],
                         check=True, capture_output=True, text=True)
    return out, run.stdout
