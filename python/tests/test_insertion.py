"""insert_points and insert_sensor_points: what they fuse, and the input they refuse."""
import numpy as np
import pytest

import multibin
from conftest import plane_points


def rotation(yaw, pitch, roll):
    """MRPT's CPose3D rotation: Rz(yaw) Ry(pitch) Rx(roll)."""
    cy, sy, cp, sp, cr, sr = (np.cos(yaw), np.sin(yaw), np.cos(pitch), np.sin(pitch),
                              np.cos(roll), np.sin(roll))
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    return rz @ ry @ rx


def test_a_plane_is_mapped_at_its_height_and_unknown_beyond(plane_map):
    x, y = np.meshgrid(np.linspace(0.1, 0.9, 9), np.linspace(0.1, 0.9, 9))
    h, s, src = plane_map.height(x, y)
    np.testing.assert_allclose(h, 0.1, atol=1e-3)
    assert np.all((s > 0) & (s < 0.01))
    assert np.all(src == multibin.SOURCE_MEASURED)
    h, s, src = plane_map.height([3.0, -3.0], [3.0, 0.5])
    assert np.all(np.isnan(h)) and np.all(np.isnan(s)) and np.all(src == multibin.SOURCE_UNKNOWN)


def test_insert_points_returns_the_counts_and_the_map_grows_to_cover_them():
    m = multibin.ElevationMap(resolution_m=0.05)
    stats = m.insert_points(*plane_points(500))
    assert stats["accepted"] == 500 and stats["rejected"] == 0
    xmin, xmax, ymin, ymax = m.extent_m
    assert xmin <= 0 and xmax >= 1 and ymin <= 0 and ymax >= 1
    assert m.insert_stats["accepted"] == 500


def test_float32_and_integer_arrays_are_accepted():
    m = multibin.ElevationMap(resolution_m=0.05)
    p, c = plane_points(50)
    assert m.insert_points(p.astype(np.float32), c.astype(np.float32))["accepted"] == 50
    assert m.insert_points(np.array([[0, 0, 1]]), np.zeros((1, 3, 3), dtype=int))["accepted"] == 1


def test_georeferenced_points_keep_their_precision():
    m = multibin.ElevationMap(resolution_m=0.05)
    p, c = plane_points(2000)
    p[:, 0] += 512345.0
    p[:, 1] += 4321987.0
    m.insert_points(p, c)
    assert m.origin_m == (512000.0, 4322000.0)  # the whole km nearest the data
    h, _, src = m.height(p[:50, 0], p[:50, 1])
    np.testing.assert_allclose(h, 0.1, atol=1e-4)
    assert np.all(src == multibin.SOURCE_MEASURED)


def test_sensor_points_are_the_map_points_the_pose_makes_of_them():
    """An exact pose: insert_sensor_points equals insert_points of the points moved in numpy."""
    sensor_pose = np.array([0.1, 0.0, 0.5, 0.0, 0.6, 0.0])  # pitched down 0.6 rad
    robot_pose = np.array([1.0, 2.0, 0.2, 0.4, 0.0, 0.0])
    rng = np.random.default_rng(3)
    n = 3000
    pts_s = np.column_stack([rng.uniform(0.3, 1.5, n), rng.uniform(-0.5, 0.5, n),
                             rng.uniform(-0.1, 0.1, n)])
    cov_s = np.tile(np.diag([4e-6, 1e-6, 1e-6]), (n, 1, 1))
    r_s, r_r = rotation(*sensor_pose[3:]), rotation(*robot_pose[3:])
    pts_m = (r_r @ (r_s @ pts_s.T + sensor_pose[:3, None]) + robot_pose[:3, None]).T
    r = r_r @ r_s
    cov_m = r @ cov_s @ r.T
    a = multibin.ElevationMap(resolution_m=0.05, visibility_constraint=False)
    b = multibin.ElevationMap(resolution_m=0.05, visibility_constraint=False)
    sa = a.insert_sensor_points(pts_s, cov_s, sensor_pose, robot_pose, np.zeros((6, 6)))
    sb = b.insert_points(pts_m, cov_m)
    assert sa == sb and sa["accepted"] > 0.9 * n
    x, y = pts_m[::7, 0], pts_m[::7, 1]
    ha, sa_, srca = a.height(x, y)
    hb, sb_, srcb = b.height(x, y)
    np.testing.assert_array_equal(srca, srcb)
    np.testing.assert_allclose(ha, hb, atol=1e-5)
    np.testing.assert_allclose(sa_, sb_, rtol=1e-3, atol=1e-6)


def test_robot_pose_uncertainty_widens_sigma():
    pts, cov = plane_points(3000, height_m=-0.5, sigma_m=0.001)
    pose = np.zeros(6)
    exact = multibin.ElevationMap(resolution_m=0.05)
    unsure = multibin.ElevationMap(resolution_m=0.05)
    exact.insert_sensor_points(pts, cov, pose, pose, np.zeros((6, 6)))
    unsure.insert_sensor_points(pts, cov, pose, pose, np.diag([0, 0, 0.02**2, 0, 0, 0]))
    x = np.full(5, 0.5)
    y = np.linspace(0.2, 0.8, 5)
    assert np.all(unsure.height(x, y)[1] > 2 * exact.height(x, y)[1])


def test_a_query_thread_runs_while_another_thread_inserts(plane_map):
    """The GIL is released while the map works; its own lock keeps the two apart. With a long
    switch interval Python never takes the GIL from the inserting thread: the main thread can
    query during the insertion only because insert_points releases it."""
    import sys
    import threading
    pts, cov = plane_points(1_500_000, seed=7)
    inserting = threading.Event()
    done = threading.Event()

    def insert():
        inserting.set()
        plane_map.insert_points(pts, cov)
        done.set()

    x, y = np.full(100, 0.5), np.full(100, 0.5)
    interval = sys.getswitchinterval()
    sys.setswitchinterval(30.0)
    try:
        t = threading.Thread(target=insert)
        t.start()
        inserting.wait()
        # Counted when a query starts: the main thread runs before `done` only if insert_points
        # released the GIL. (Counted on return, the count depended on which thread the OS woke
        # first when the map's lock was released: the insertion holds it to the end.)
        started_during_insertion = 0
        while not done.is_set():
            started_during_insertion += 1
            h, _, src = plane_map.height(x, y)
            assert np.all(src == multibin.SOURCE_MEASURED) and np.all(np.abs(h - 0.1) < 1e-3)
        t.join()
    finally:
        sys.setswitchinterval(interval)
    assert started_during_insertion > 0


# --- bad input: every error names the function, the argument and the problem -----------------

P, C = plane_points(4)
POSE = np.zeros(6)
POSE_COV = np.zeros((6, 6))


def with_entry(a, index, value):
    a = a.copy()
    a[index] = value
    return a


@pytest.mark.parametrize("points, covariances, error, message", [
    (P[:, :2], C, ValueError, r"points must have shape \(N, 3\), has shape \(4, 2\)"),
    (P[0], C, ValueError, r"points must have shape \(N, 3\), has shape \(3,\)"),
    (P, C[:, :2], ValueError, r"covariances must have shape \(N, 3, 3\), has shape \(4, 2, 3\)"),
    (P, C[:3], ValueError, "covariances has 3 matrices for 4 points"),
    (P.astype(complex), C, TypeError, "points has dtype complex128"),
    (P, C.astype(object), TypeError, "covariances has dtype object"),
    (P.astype(bool), C, TypeError, "points has dtype bool"),
    ("points", C, TypeError, "points has dtype <U6"),
    (with_entry(P, (2, 1), np.nan), C, ValueError, r"points\[2\] has a NaN or infinite"),
    (P, with_entry(C, (1, 2, 2), np.inf), ValueError,
     r"covariances\[1\] has a NaN or infinite entry at \[2, 2\]"),
    (P, with_entry(C, (3, 0, 1), 1e-5), ValueError, r"covariances\[3\] is not symmetric"),
    (P, with_entry(C, (0, 2, 2), -1e-4), ValueError,
     r"covariances\[0\] is not positive semi-definite"),
])
def test_insert_points_refuses_bad_input(points, covariances, error, message):
    m = multibin.ElevationMap()
    with pytest.raises(error, match="insert_points: " + message):
        m.insert_points(points, covariances)
    assert m.insert_stats["accepted"] == 0


def test_insert_points_refuses_a_bad_sensor_origin():
    with pytest.raises(ValueError, match="sensor_origin must be 3 finite numbers"):
        multibin.ElevationMap().insert_points(P, C, sensor_origin=[0, np.nan, 1])


@pytest.mark.parametrize("sensor_pose, robot_pose, robot_pose_cov, message", [
    (POSE[:5], POSE, POSE_COV, r"sensor_pose must have shape \(6,\)"),
    (POSE, with_entry(POSE, 3, np.nan), POSE_COV, r"robot_pose\[3\] is NaN or infinite"),
    (POSE, POSE, POSE_COV[:5], r"robot_pose_cov must have shape \(6, 6\)"),
    (POSE, POSE, with_entry(POSE_COV, (4, 4), np.nan), r"robot_pose_cov has a NaN"),
    (POSE, POSE, with_entry(POSE_COV, (0, 0), -1e-4), "robot_pose_cov is not positive semi"),
    (POSE, POSE, with_entry(POSE_COV, (0, 1), 1e-4), "robot_pose_cov is not symmetric"),
])
def test_insert_sensor_points_refuses_bad_poses(sensor_pose, robot_pose, robot_pose_cov, message):
    m = multibin.ElevationMap()
    with pytest.raises(ValueError, match="insert_sensor_points: " + message):
        m.insert_sensor_points(P, C, sensor_pose, robot_pose, robot_pose_cov)
    assert m.insert_stats["accepted"] == 0


def test_a_dual_grid_follows_the_robot_of_insert_sensor_points():
    """The local grid (2 m) is centred on the robot pose before the points go in: points 5 m
    away from the first pose are kept in the local grid's precise cells."""
    m = multibin.ElevationMap(dual_grid=True)
    pts, cov = plane_points(3000, size_m=0.5, height_m=-0.3, sigma_m=0.002)
    pose = np.array([5.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    stats = m.insert_sensor_points(pts, cov, np.zeros(6), pose, np.zeros((6, 6)))
    assert stats["accepted"] == 3000
    h, _, src = m.height([5.25], [0.25])
    assert src[0] == multibin.SOURCE_MEASURED and abs(h[0] + 0.3) < 1e-3
