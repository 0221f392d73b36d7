"""ElevationMap(): defaults, ini files, keyword options, load and save."""
import gzip

import numpy as np
import pytest

import multibin
from conftest import MOCKUP_INI, plane_points


def test_defaults_give_an_empty_map_of_the_library_defaults():
    m = multibin.ElevationMap()
    assert m.resolution_m == pytest.approx(0.02)
    assert m.insert_stats["accepted"] == 0
    h, s, src = m.height([0.0], [0.0])
    assert np.isnan(h[0]) and np.isnan(s[0]) and src[0] == multibin.SOURCE_UNKNOWN


def test_keyword_options_set_creation_and_insertion_keys():
    m = multibin.ElevationMap(resolution_m=0.05, max_elevation_uncertainty_m=0.001, grow=False,
                              min_x_m=0, max_x_m=1, min_y_m=0, max_y_m=1)
    assert m.resolution_m == pytest.approx(0.05)
    assert m.extent_m == pytest.approx((0, 1, 0, 1))
    # sigma_z = 1 cm: 3 sigma is far over the 1 mm Delta_max, so eq 13 rejects every point.
    stats = m.insert_points(*plane_points(100))
    assert stats["accepted"] == 0 and stats["too_uncertain"] == 100


def test_list_and_bool_options_reach_the_map():
    m = multibin.ElevationMap(default_pose_sigmas=[0.1, 0.1, 0.1, 0.01, 0.01, 0.01],
                              visibility_constraint=False, sensor_labels=["A", "B"])
    assert m.insert_points(*plane_points(10))["accepted"] == 10


def test_ini_file_defines_the_map_and_options_override_it():
    assert multibin.ElevationMap(str(MOCKUP_INI)).resolution_m == pytest.approx(0.015)
    m = multibin.ElevationMap(str(MOCKUP_INI), resolution_m=0.03)
    assert m.resolution_m == pytest.approx(0.03)


def test_unknown_option_is_a_value_error_naming_it():
    with pytest.raises(ValueError, match="unknown option 'resolution'"):
        multibin.ElevationMap(resolution=0.05)  # the old name: keywords take the suffixed ones


def test_bad_option_value_carries_the_library_message():
    with pytest.raises(ValueError, match="'resolution_m': must be from 0.0001 to 1000"):
        multibin.ElevationMap(resolution_m=-1)
    with pytest.raises(ValueError, match="grow"):
        multibin.ElevationMap(grow="maybe")
    with pytest.raises(TypeError, match="option 'grow'"):
        multibin.ElevationMap(grow={})


def test_missing_ini_and_section_without_a_map_are_errors(tmp_path):
    with pytest.raises(RuntimeError, match="not found"):
        multibin.ElevationMap(str(tmp_path / "none.ini"))
    with pytest.raises(ValueError, match=r"no multiBinElevationMap in \[Other\]"):
        multibin.ElevationMap(str(MOCKUP_INI), section="Other")


def test_save_then_load_answers_the_same_heights_bit_for_bit(plane_map, tmp_path):
    path = tmp_path / "map.bin"
    plane_map.save(str(path))
    assert [p.name for p in tmp_path.iterdir()] == ["map.bin"], "no temporary left"
    loaded = multibin.ElevationMap.load(str(path))
    x, y = np.meshgrid(np.linspace(-0.2, 1.2, 57), np.linspace(-0.2, 1.2, 61))
    for a, b in zip(plane_map.height(x, y), loaded.height(x, y)):
        np.testing.assert_array_equal(a, b)
    assert loaded.resolution_m == plane_map.resolution_m
    assert loaded.extent_m == plane_map.extent_m


def test_load_refuses_missing_and_corrupt_files(tmp_path):
    with pytest.raises(RuntimeError, match="not found"):
        multibin.ElevationMap.load(str(tmp_path / "none.bin"))
    junk = tmp_path / "junk.bin"
    junk.write_bytes(b"not a map" * 10)
    with pytest.raises(RuntimeError, match="ElevationMap.load: '.*junk.bin'"):
        multibin.ElevationMap.load(str(junk))


def test_a_map_file_with_a_flipped_byte_is_an_error_naming_its_checksum(plane_map, tmp_path):
    """The reader's reason (the payload's checksum) comes through MRPT's wrapper of it."""
    path = tmp_path / "map.bin"
    plane_map.save(str(path))
    payload = bytearray(gzip.decompress(path.read_bytes()))
    payload[len(payload) // 2] ^= 0xFF
    bad = tmp_path / "flipped.bin"
    bad.write_bytes(gzip.compress(bytes(payload)))
    with pytest.raises(RuntimeError, match=r"ElevationMap.load: '.*flipped\.bin'.*checksum mismatch"):
        multibin.ElevationMap.load(str(bad))


def test_save_to_a_missing_folder_is_an_error_naming_the_path(plane_map, tmp_path):
    with pytest.raises(RuntimeError, match="ElevationMap.save: '.*nowhere"):
        plane_map.save(str(tmp_path / "nowhere" / "map.bin"))
