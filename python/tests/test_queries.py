"""height(), layers() and fill()."""
import numpy as np
import pytest

import multibin
from conftest import plane_points


def test_height_keeps_the_shape_of_its_input(plane_map):
    x, y = np.meshgrid(np.linspace(0.1, 0.9, 4), np.linspace(0.1, 0.9, 3))
    h, s, src = plane_map.height(x, y)
    assert h.shape == s.shape == src.shape == (3, 4)
    assert h.dtype == np.float64 and src.dtype == np.uint8
    h, s, src = plane_map.height(0.5, 0.5)  # scalars give 0-d arrays
    assert h.shape == () and abs(float(h) - 0.1) < 1e-3
    h, _, _ = plane_map.height([0.5, 0.6], (0.5, 0.6))  # lists and tuples
    assert h.shape == (2,)
    h, _, _ = plane_map.height(np.zeros(0), np.zeros(0))
    assert h.shape == (0,)


def test_height_of_a_non_contiguous_view_is_that_of_its_values(plane_map):
    xy = np.random.default_rng(2).uniform(0, 1, (200, 2))
    for a, b in zip(plane_map.height(xy[:, 0], xy[:, 1]),
                    plane_map.height(xy[:, 0].copy(), xy[:, 1].copy())):
        np.testing.assert_array_equal(a, b)


def test_height_over_an_array_is_height_at_each_point_bit_for_bit():
    # A rough slope with a filled hole; the array goes through the map's batch query, a scalar
    # through height() alone: points measured, filled, unknown, on cell borders and outside.
    rng = np.random.default_rng(4)
    pts, cov = plane_points(30000, size_m=1.0)
    pts[:, 2] = 0.2 * pts[:, 0] + 0.03 * np.sin(9 * pts[:, 1]) + rng.normal(0, 0.003, len(pts))
    keep = np.hypot(pts[:, 0] - 0.5, pts[:, 1] - 0.5) > 0.1
    m = multibin.ElevationMap(resolution_m=0.05)
    m.insert_points(pts[keep], cov[keep])
    m.fill()
    x, y = rng.uniform(-0.2, 1.2, 3000), rng.uniform(-0.2, 1.2, 3000)
    x[::5] = np.round(x[::5] / 0.05) * 0.05
    h, s, src = m.height(x, y)
    one = [m.height(xi, yi) for xi, yi in zip(x.tolist(), y.tolist())]
    assert {multibin.SOURCE_UNKNOWN, multibin.SOURCE_MEASURED} <= set(src.tolist())
    assert np.any(src >= multibin.SOURCE_FILLED_MEDIAN)
    np.testing.assert_array_equal(src, [int(a[2]) for a in one])
    np.testing.assert_array_equal(h.view(np.uint64), np.array([float(a[0]) for a in one]).view(np.uint64))
    np.testing.assert_array_equal(s.view(np.uint64), np.array([float(a[1]) for a in one]).view(np.uint64))


def test_height_at_nan_coordinates_is_unknown(plane_map):
    h, s, src = plane_map.height([np.nan, 0.5], [0.5, np.inf])
    assert np.all(np.isnan(h)) and np.all(src == multibin.SOURCE_UNKNOWN)


def test_height_refuses_mismatched_shapes_and_dtypes(plane_map):
    with pytest.raises(ValueError, match="height: x and y must have the same shape"):
        plane_map.height(np.zeros(3), np.zeros(4))
    with pytest.raises(ValueError, match="height: x and y must have the same shape"):
        plane_map.height(np.zeros((2, 3)), np.zeros(6))
    with pytest.raises(TypeError, match="height: y has dtype complex128"):
        plane_map.height(np.zeros(3), np.zeros(3, dtype=complex))


def test_layers_are_the_cells_of_the_window_with_their_lattice(plane_map):
    layers = plane_map.layers()
    height = layers["height"]
    rows, cols = height.shape
    for name in ("sigma", "certainty", "source"):
        assert layers[name].shape == (rows, cols)
    assert height.dtype == np.float32 and layers["source"].dtype == np.uint8
    cell = layers["cell_size"]
    assert cell == pytest.approx(0.05)
    x0, x1, y0, y1 = layers["extent"]
    assert (x0, y0) == layers["origin"]
    assert x1 - x0 == pytest.approx(cols * cell) and y1 - y0 == pytest.approx(rows * cell)
    assert (x0, x1, y0, y1) == pytest.approx(plane_map.extent_m)
    # Row 0 is the southernmost: the cell centres' heights are the map's there.
    known = layers["source"] == multibin.SOURCE_MEASURED
    assert known.sum() == 400  # the plane covers 20 x 20 cells of 5 cm
    r, c = np.nonzero(known)
    _, _, src = plane_map.height(x0 + (c + 0.5) * cell, y0 + (r + 0.5) * cell)
    assert np.all(src == multibin.SOURCE_MEASURED)
    np.testing.assert_allclose(height[known], 0.1, atol=1e-3)
    assert np.all(np.isnan(height[~known])) and np.all(np.isnan(layers["sigma"][~known]))
    assert np.all(layers["certainty"][known] > 0)


def test_layers_of_an_empty_map_are_empty():
    layers = multibin.ElevationMap().layers()
    assert layers["height"].shape == (0, 0)


def test_fill_fills_a_hole_and_height_then_answers_it():
    pts, cov = plane_points(20000, size_m=1.0)
    hole = np.hypot(pts[:, 0] - 0.5, pts[:, 1] - 0.5) < 0.08
    m = multibin.ElevationMap(resolution_m=0.05)
    m.insert_points(pts[~hole], cov[~hole])
    assert m.height(0.5, 0.5)[2] == multibin.SOURCE_UNKNOWN
    counts = m.fill()
    assert counts["median"] + counts["surface"] > 0
    h, s, src = m.height(0.5, 0.5)
    assert src in (multibin.SOURCE_FILLED_MEDIAN, multibin.SOURCE_FILLED_SURFACE,
                   multibin.SOURCE_FILLED_HARMONIC)
    assert abs(float(h) - 0.1) < 0.01 and float(s) > 0
    layers = m.layers()
    assert np.any(layers["source"] >= multibin.SOURCE_FILLED_MEDIAN)
    filled = layers["source"] >= multibin.SOURCE_FILLED_MEDIAN
    assert np.all(layers["certainty"][filled] == 0)  # filled cells keep certainty 0
