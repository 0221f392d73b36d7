"""map_rawlog, map_simplemap, and maps saved by C++ read from Python."""
import subprocess

import numpy as np
import pytest

import multibin
from conftest import MOCKUP_INI, MOCKUP_RAWLOG, MOCKUP_SIMPLEMAP, QUERY_TABLE


def mapper_report(stdout):
    """The 'observations by class' block elevation-mapper prints."""
    lines = stdout.splitlines()
    start = lines.index("observations by class:")
    end = start + 1
    while end < len(lines) and lines[end].startswith("  "):
        end += 1
    return "\n".join(lines[start:end]) + "\n"


def test_map_rawlog_counts_are_the_mappers(mapper_output):
    m = multibin.ElevationMap(str(MOCKUP_INI))
    counts = m.map_rawlog(str(MOCKUP_RAWLOG))
    _, stdout = mapper_output
    assert counts["report"] == mapper_report(stdout)
    fused = sum(c["points_fused"] for c in counts["by_class"].values())
    assert fused == counts["points"]["accepted"] > 0
    assert f"points fused: {fused};" in stdout
    scans = counts["by_class"]["mrpt::obs::CObservation2DRangeScan"]
    assert scans["used"] > 0 and scans["points_fused"] > 0
    poses = counts["by_class"]["mrpt::obs::CObservationRobotPose"]["pose_pdfs"]
    assert counts["observations"] == sum(
        c["used"] + c["rejected"] + c["skipped_by_label"] + c["skipped"] + c["pose_pdfs"]
        for c in counts["by_class"].values())
    assert poses > 0 and counts["default_pose_covariance"] == 0


def test_map_simplemap_maps_the_same_scene():
    m = multibin.ElevationMap(str(MOCKUP_INI))
    counts = m.map_simplemap(str(MOCKUP_SIMPLEMAP))
    assert counts["entries"] > 0 and counts["points"]["accepted"] > 100000
    h, _, src = m.height(np.array([0.5, 1.0]), np.array([0.0, 0.5]))
    assert np.all(src == multibin.SOURCE_MEASURED) and np.all(np.isfinite(h))


def test_map_rawlog_refuses_missing_and_corrupt_files(tmp_path):
    m = multibin.ElevationMap()
    with pytest.raises(RuntimeError, match="none.rawlog"):
        m.map_rawlog(str(tmp_path / "none.rawlog"))
    junk = tmp_path / "junk.rawlog"
    junk.write_bytes(bytes(range(256)) * 8)
    with pytest.raises(RuntimeError, match="junk.rawlog"):
        m.map_rawlog(str(junk))
    with pytest.raises(RuntimeError, match="junk.rawlog"):
        m.map_simplemap(str(junk))


def test_a_rawlog_nothing_of_which_is_fused_is_an_error_saying_why():
    m = multibin.ElevationMap(str(MOCKUP_INI), sensor_labels=["NO_SUCH_SENSOR"])
    with pytest.raises(RuntimeError, match="no point fused .* skipped by sensor_labels"):
        m.map_rawlog(str(MOCKUP_RAWLOG))


@pytest.mark.parametrize("filled", [False, True])
def test_the_mappers_map_answers_python_as_it_answers_cpp_bit_for_bit(mapper_output, tmp_path,
                                                                      filled):
    """elevation_map.bin written by elevation-mapper, queried by a C++ program that loads it
    with MRPT, and loaded in Python: the same height, sigma and source at every point, measured
    and filled (a loaded map fills on its first query, as fill() does again)."""
    if not QUERY_TABLE:
        pytest.skip("MULTIBIN_QUERY_TABLE not set (run through ctest)")
    out, _ = mapper_output
    m = multibin.ElevationMap.load(str(out / "elevation_map.bin"))
    if filled:
        m.fill()
    xmin, xmax, ymin, ymax = m.extent_m
    rng = np.random.default_rng(5)
    xy = np.column_stack([rng.uniform(xmin - 0.1, xmax + 0.1, 50000),
                          rng.uniform(ymin - 0.1, ymax + 0.1, 50000)])
    xy.tofile(tmp_path / "xy.bin")
    subprocess.run([QUERY_TABLE] + (["--fill"] if filled else []) +
                   [str(out / "elevation_map.bin"), str(tmp_path / "xy.bin"),
                    str(tmp_path / "table.bin")], check=True)
    table = np.fromfile(tmp_path / "table.bin").reshape(-1, 5)
    np.testing.assert_array_equal(table[:, :2], xy)
    h, s, src = m.height(xy[:, 0], xy[:, 1])
    assert np.count_nonzero(src == multibin.SOURCE_MEASURED) > 5000
    assert np.count_nonzero(src >= multibin.SOURCE_FILLED_MEDIAN) > 500
    assert np.count_nonzero(src == multibin.SOURCE_UNKNOWN) > 1000
    np.testing.assert_array_equal(h, table[:, 2])  # NaN where NaN
    np.testing.assert_array_equal(s, table[:, 3])
    np.testing.assert_array_equal(src, table[:, 4])
