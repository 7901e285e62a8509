"""The range scan against an independent shapely reference (tests/scan_reference.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from scan_reference import assert_within, blocked_shapes, reference_ranges

from pointnav_core import scenes
from pointnav_core.floor.maps import TraversableMap
from pointnav_core.sensors import RangeScan, ScanGeometry, cast_rays, scan_angles

FULL = scan_angles(64, 2 * math.pi)


def _check(tmap, origin, yaw, angles, max_range, discs=(), polygons=()):
    got = cast_rays(ScanGeometry(tmap), [origin], [yaw], angles, max_range, discs=discs if len(discs) else None)[0]
    shapes = blocked_shapes(tmap.codes, tmap.resolution, tmap.origin, polygons)
    loose, strict = reference_ranges(shapes, origin, yaw + np.asarray(angles), max_range, discs)
    assert_within(got, loose, strict, atol=1e-8)
    return got


def test_ranges_to_walls_of_an_open_room_are_exact():
    tmap = TraversableMap(np.zeros((10, 20), np.uint8), 0.5, origin=(-5.0, -2.5))
    got = _check(tmap, (0.3, 0.2), 0.0, [0.0, math.pi / 2, math.pi, -math.pi / 2], 20.0)
    # The map's edge reads as a wall: x in [-5, 5], y in [-2.5, 2.5].
    np.testing.assert_allclose(got, [4.7, 2.3, 5.3, 2.7], atol=1e-12)


def test_void_is_not_seen_and_obstacle_is():
    codes = np.zeros((1, 10), np.uint8)
    codes[0, 3] = 2  # VOID
    codes[0, 6] = 1  # OBSTACLE
    tmap = TraversableMap(codes, 1.0)
    got = _check(tmap, (0.5, 0.5), 0.0, [0.0], 20.0)
    assert got.tolist() == [5.5]


def test_a_ray_through_the_corner_of_two_diagonal_squares_stops_there():
    codes = np.zeros((4, 4), np.uint8)
    codes[1, 2] = codes[2, 1] = 1
    tmap = TraversableMap(codes, 1.0)
    got = _check(tmap, (1.5, 1.5), 0.0, [math.pi / 4], 10.0)
    assert got[0] == pytest.approx(math.sqrt(0.5), abs=1e-12)


def test_a_ray_along_a_face_touches_it():
    codes = np.zeros((3, 6), np.uint8)
    codes[0, 4] = 1
    tmap = TraversableMap(codes, 1.0)
    got = _check(tmap, (0.5, 1.0), 0.0, [0.0], 10.0)  # along y = 1, the top face of (0, 4)
    assert got[0] == pytest.approx(3.5, abs=1e-12)


def test_other_robots_are_discs_and_the_own_disc_is_not_seen():
    tmap = TraversableMap(np.zeros((10, 10), np.uint8), 1.0)
    discs = np.array([[5.0, 5.0, 0.5], [8.0, 5.0, 1.0]])
    got = cast_rays(ScanGeometry(tmap), [[5.0, 5.0]], [0.0], [0.0], 20.0, discs=discs, own_disc=[0])
    assert got[0, 0] == pytest.approx(2.0, abs=1e-12)
    got = cast_rays(ScanGeometry(tmap), [[5.0, 5.0]], [0.0], [0.0], 20.0, discs=discs)
    assert got[0, 0] == 0.0  # inside a disc


def test_polygons_thinner_than_a_cell_are_seen():
    wall = shapely.box(2.02, -1.0, 2.04, 1.0)
    scene = scenes.Scene.from_polygons(shapely.box(-3, -3, 3, 3), [wall], resolution=0.5)
    tmap = scene.floors[0]
    got = _check(tmap, (0.1, 0.1), 0.0, FULL, 10.0, polygons=tmap.collision.polygons)
    assert got[32] == pytest.approx(1.92, abs=1e-12)  # angle 0


def test_generated_house_agrees_with_the_reference():
    scene = scenes.rooms(seed=3)
    tmap = scene.floors[0]
    rng = np.random.default_rng(0)
    for _ in range(5):
        _, xyz = scene.get_random_point(0, robot=0.18, rng=rng)
        _check(tmap, xyz[:2], rng.uniform(-math.pi, math.pi), FULL, 5.6, polygons=tmap.collision.polygons)


def test_rays_and_robots_vectorise():
    scene = scenes.rooms(seed=1)
    geo = ScanGeometry(scene.floors[0])
    rng = np.random.default_rng(2)
    points = np.array([scene.get_random_point(0, robot=0.18, rng=rng)[1][:2] for _ in range(5)])
    yaws = rng.uniform(-math.pi, math.pi, 5)
    discs = np.column_stack([points, np.full(5, 0.18)])
    together = cast_rays(geo, points, yaws, FULL, 5.6, discs=discs, own_disc=np.arange(5))
    for i in range(5):
        alone = cast_rays(geo, points[i : i + 1], yaws[i : i + 1], FULL, 5.6, discs=discs, own_disc=[i])
        np.testing.assert_array_equal(together[i], alone[0])


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"n_rays": 0}, "n_rays"),
        ({"n_rays": -3}, "n_rays"),
        ({"n_rays": 2.0}, "n_rays"),
        ({"n_rays": True}, "n_rays"),
        ({"fov": 2 * math.pi + 1e-6}, "fov"),
        ({"fov": 0.0}, "fov"),
        ({"fov": "1"}, "fov"),
        ({"min_range": 6.0, "max_range": 5.0}, "min_range"),
        ({"min_range": 5.0, "max_range": 5.0}, "min_range"),
        ({"max_range": -1.0}, "max_range"),
        ({"max_range": True}, "max_range"),
        ({"max_range": math.inf}, "max_range"),
        ({"noise_std": -0.1}, "noise_std"),
        ({"dropout": 1.5}, "dropout"),
        ({"dropout": math.nan}, "dropout"),
    ],
)
def test_bad_configuration_names_the_parameter(kwargs, name):
    with pytest.raises(ValueError, match=name):
        RangeScan(**kwargs)


def test_angles_are_read_only_and_in_the_robot_frame():
    scan = RangeScan(n_rays=5, fov=math.pi)
    assert scan.angles.tolist() == pytest.approx([-math.pi / 2, -math.pi / 4, 0.0, math.pi / 4, math.pi / 2])
    with pytest.raises(ValueError):
        scan.angles[0] = 1.0


def test_scan_geometry_and_sensors_pickle():
    import pickle

    from pointnav_core.sensors import LocalMap

    scene = scenes.rooms(seed=2)
    geo = ScanGeometry(scene.floors[0])
    again = pickle.loads(pickle.dumps(geo))
    p = [[0.0, 0.0]]
    np.testing.assert_array_equal(cast_rays(geo, p, [0.3], FULL, 5.6), cast_rays(again, p, [0.3], FULL, 5.6))
    scan = pickle.loads(pickle.dumps(RangeScan(n_rays=8, noise_std=0.1)))
    assert scan.angles.tolist() == RangeScan(n_rays=8).angles.tolist()
    assert pickle.loads(pickle.dumps(LocalMap(cells=4))).shape == (4, 4)


def test_method_names_the_choices():
    geo = ScanGeometry(TraversableMap(np.zeros((2, 2), np.uint8), 1.0))
    with pytest.raises(ValueError, match=r"method must be one of 'auto', 'array', 'numba', got 'fast'"):
        cast_rays(geo, [[0.5, 0.5]], [0.0], [0.0], 1.0, method="fast")
    # The old name of the plain path is refused, and the message says the new one.
    with pytest.raises(ValueError, match=r"got 'numpy' \(the plain path is 'array'\)"):
        cast_rays(geo, [[0.5, 0.5]], [0.0], [0.0], 1.0, method="numpy")


def test_without_numba_auto_takes_numpy_and_numba_is_refused():
    from pointnav_core.utils.compiled import numpy_paths

    geo = ScanGeometry(TraversableMap(np.zeros((1, 4), np.uint8), 1.0))
    with numpy_paths():  # the loader finds no kernel, as without numba
        # The map's edge at x = 4 and x = 0, by hand.
        assert cast_rays(geo, [[0.5, 0.5]], [0.0], [0.0, math.pi], 10.0).tolist() == [[3.5, 0.5]]
        with pytest.raises(ValueError, match=r"method=\"numba\" needs numba"):
            cast_rays(geo, [[0.5, 0.5]], [0.0], [0.0], 10.0, method="numba")
