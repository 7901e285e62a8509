"""Batched robot-robot contacts against the kinematic backend's contacts, and by hand."""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest
from pointnav_kinematic.contacts import advance
from pointnav_kinematic.geometry import FloorGeometry

from pointnav_core.floor.maps import OBSTACLE, TraversableMap
from pointnav_core.scenes import Scene
from pointnav_core.vector.robots import advance_robots, robot_walls
from pointnav_core.vector.xp import make_arrays

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])
_OPEN = FloorGeometry(TraversableMap(np.zeros((40, 40), np.uint8), resolution=0.5), 0.0)


class _Disc:
    """The state contacts.advance reads and writes for one robot."""

    def __init__(self, x: float, y: float, mx: float, my: float, radius: float) -> None:
        self.x, self.y, self.mx, self.my, self.radius = x, y, mx, my, radius
        self.floor, self.geom = 0, _OPEN
        self.contact = self.stopped = False
        self.walls: list = []


def backend_step(x: np.ndarray, y: np.ndarray, mx: np.ndarray, my: np.ndarray, radius: float):
    """One world at a time through the backend's own resolver."""
    out_x, out_y, out_c = np.empty_like(x), np.empty_like(y), np.zeros(x.shape, bool)
    for w in range(x.shape[0]):
        discs = [_Disc(*map(float, v), radius) for v in zip(x[w], y[w], mx[w], my[w])]
        advance(discs, stop=False)
        out_x[w], out_y[w] = [d.x for d in discs], [d.y for d in discs]
        out_c[w] = [d.contact for d in discs]
    return out_x, out_y, out_c


@pytest.mark.parametrize("device", DEVICES)
def test_head_on_robots_share_the_gap_by_their_speeds(device: str) -> None:
    # Radius 0.2: centres 1.0 m apart leave a 0.6 m gap; closing at 0.5 + 0.25 m per step
    # they touch after 0.8 of the step, having moved 0.4 and 0.2 m (less the placing margin).
    a = make_arrays(device)
    x = a.asarray(np.array([[10.0, 11.0]]))
    y = a.asarray(np.array([[10.0, 10.0]]))
    mx = a.asarray(np.array([[0.5, -0.25]]))
    ex, ey, c = (a.numpy(v) for v in advance_robots(a, x, y, mx, 0.0 * mx, 0.2))
    np.testing.assert_allclose(ex[0], [10.4, 10.8], atol=1e-8)
    np.testing.assert_allclose(ey[0], [10.0, 10.0])
    assert c[0].tolist() == [True, True]
    assert math.hypot(ex[0, 1] - ex[0, 0], 0.0) >= 0.4 - 1e-9


@pytest.mark.parametrize("device", DEVICES)
def test_a_glancing_robot_slides_past_a_standing_one(device: str) -> None:
    # Robot 0 drives +x towards robot 1 offset by 0.3 m in y: after touching, it slides
    # along the tangent and ends clear of robot 1, which does not move.
    a = make_arrays(device)
    x, y = np.array([[10.0, 10.6]]), np.array([[10.0, 10.3]])
    mx, my = np.array([[0.5, 0.0]]), np.zeros((1, 2))
    ex, ey, c = (a.numpy(v) for v in advance_robots(a, *(a.asarray(v) for v in (x, y, mx, my)), 0.2))
    assert c[0].tolist() == [True, True]
    assert (ex[0, 1], ey[0, 1]) == (10.6, 10.3)
    assert math.hypot(ex[0, 0] - 10.6, ey[0, 0] - 10.3) >= 0.4 - 1e-8
    assert ey[0, 0] < 10.0  # pushed aside, away from robot 1


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("n_robots", [2, 3, 4])
def test_random_crowds_match_the_backend(device: str, n_robots: int) -> None:
    # Many worlds of robots crowded in a 1.2 m square, driving anywhere up to 0.3 m a step.
    rng = np.random.default_rng(n_robots)
    a = make_arrays(device)
    n_worlds, radius = 400, 0.15
    x = np.empty((n_worlds, n_robots))
    y = np.empty((n_worlds, n_robots))
    for w in range(n_worlds):  # rejection: no overlapping starts
        pts: list[tuple[float, float]] = []
        while len(pts) < n_robots:
            p = tuple(rng.uniform(9.4, 10.6, 2))
            if all(math.dist(p, q) >= 2 * radius for q in pts):
                pts.append(p)
        x[w], y[w] = np.array(pts).T
    speed = rng.uniform(0.0, 0.3, (n_worlds, n_robots)) * (rng.random((n_worlds, n_robots)) > 0.2)
    heading = rng.uniform(-math.pi, math.pi, (n_worlds, n_robots))
    mx, my = speed * np.cos(heading), speed * np.sin(heading)
    want = backend_step(x, y, mx, my, radius)
    got = [a.numpy(v) for v in advance_robots(a, *(a.asarray(v) for v in (x, y, mx, my)), radius)]
    np.testing.assert_allclose(got[0], want[0], atol=1e-9)
    np.testing.assert_allclose(got[1], want[1], atol=1e-9)
    np.testing.assert_array_equal(got[2], want[2])
    assert want[2].any() and not want[2].all()  # the sample has contacts and free robots
    # Independently: no two robots end overlapping by more than the hit tolerance.
    gap = np.hypot(got[0][:, :, None] - got[0][:, None, :], got[1][:, :, None] - got[1][:, None, :])
    gap[:, np.arange(n_robots), np.arange(n_robots)] = np.inf
    assert gap.min() >= 2 * radius - 1e-8


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("n_robots", [2, 4])
def test_random_crowds_among_walls_match_the_backend(device: str, n_robots: int) -> None:
    # A cluttered 3 x 3 m room (0.1 m cells) with robots packed near each other and the clutter.
    from pointnav_core.vector.floors import FloorTables

    rng = np.random.default_rng(10 + n_robots)
    scene, geom = _cluttered_room(rng)
    a = make_arrays(device)
    n_worlds, radius, travel = 120, 0.12, 0.05
    x = np.empty((n_worlds, n_robots))
    y = np.empty((n_worlds, n_robots))
    for w in range(n_worlds):
        centre = rng.uniform(0.6, 2.4, 2)
        pts: list[tuple[float, float]] = []
        while len(pts) < n_robots:
            p = tuple(centre + rng.uniform(-0.5, 0.5, 2))
            if scene.is_usable(0, p, radius) and all(math.dist(p, q) >= 2 * radius for q in pts):
                pts.append(p)
        x[w], y[w] = np.array(pts).T
    speed = rng.uniform(0.0, travel, (n_worlds, n_robots)) * (rng.random((n_worlds, n_robots)) > 0.2)
    heading = rng.uniform(-math.pi, math.pi, (n_worlds, n_robots))
    mx, my = speed * np.cos(heading), speed * np.sin(heading)
    want_x, want_y, want_c = np.empty_like(x), np.empty_like(y), np.zeros(x.shape, bool)
    for w in range(n_worlds):
        discs = [_Disc(*map(float, v), radius) for v in zip(x[w], y[w], mx[w], my[w])]
        for d in discs:
            d.geom = geom
        advance(discs, stop=False)
        want_x[w], want_y[w], want_c[w] = [d.x for d in discs], [d.y for d in discs], [d.contact for d in discs]
    floors = FloorTables([scene], 0, radius, a)
    args = [a.asarray(v) for v in (x, y, mx, my)]
    walls = robot_walls(floors, a.zeros(x.shape, a.i64), *args, radius, travel * (1 + 1e-9))
    got = [a.numpy(v) for v in advance_robots(a, *args, radius, walls=walls)]
    np.testing.assert_allclose(got[0], want_x, atol=1e-9)
    np.testing.assert_allclose(got[1], want_y, atol=1e-9)
    np.testing.assert_array_equal(got[2], want_c)
    assert want_c.any() and not want_c.all()


@pytest.mark.parametrize("device", DEVICES)
def test_absent_robots_neither_move_nor_block(device: str) -> None:
    # Robot 1 stands in robot 0's way; absent, robot 0 drives through its place untouched.
    a = make_arrays(device)
    x, y = np.array([[10.0, 10.3], [10.0, 10.3]]), np.full((2, 2), 10.0)
    mx, my = np.array([[0.3, 0.0], [0.3, 0.0]]), np.zeros((2, 2))
    present = np.array([[True, False], [True, True]])
    args = [a.asarray(v) for v in (x, y, mx, my)]
    ex, ey, c = (a.numpy(v) for v in advance_robots(a, *args, 0.1, present=a.asarray(present, a.boolean)))
    assert ex[0].tolist() == [10.3, 10.3] and c[0].tolist() == [False, False]
    assert (ey == 10.0).all()
    # Present, robot 1 stops robot 0 head-on where the discs touch, 0.1 m on.
    np.testing.assert_allclose(ex[1], [10.1, 10.3], atol=1e-8)
    assert c[1].tolist() == [True, True]


@pytest.mark.parametrize("device", DEVICES)
def test_radii_01_and_03_touch_at_their_sum(device: str) -> None:
    # Robot 0 (0.1 m) drives 0.8 m at robot 1 (0.3 m) standing 1.0 m away: it stops where
    # the centres are 0.1 + 0.3 = 0.4 m apart, at 10.6 m (less the 1e-9 m placing margin);
    # robot 2 (0.3 m) drives 0.5 m at robot 3 (0.3 m) 1.0 m away: they touch at 0.6 m, at 10.4 m.
    a = make_arrays(device)
    x = a.asarray(np.array([[10.0, 11.0], [10.0, 11.0]]))
    y = a.asarray(np.full((2, 2), 10.0))
    mx = a.asarray(np.array([[0.8, 0.0], [0.5, 0.0]]))
    radius = a.asarray(np.array([[0.1, 0.3], [0.3, 0.3]]))
    ex, ey, c = (a.numpy(v) for v in advance_robots(a, x, y, mx, 0.0 * mx, radius))
    np.testing.assert_allclose(ex, [[10.6 - 1e-9, 11.0], [10.4 - 1e-9, 11.0]], rtol=0, atol=1e-12)
    assert (ey == 10.0).all() and c.tolist() == [[True, True], [True, True]]


def _cluttered_room(rng: np.random.Generator) -> tuple[Scene, FloorGeometry]:
    """A walled 3 x 3 m room of 0.1 m cells, 12 % of them OBSTACLE, and the backend's geometry of it."""
    grid = (rng.random((30, 30)) < 0.12).astype(np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = OBSTACLE
    scene = Scene.from_array(grid, 0.1)
    return scene, FloorGeometry(scene.floors[0], 0.0)


def _mixed_crowds(rng: np.random.Generator, scene: Scene, n_worlds: int, n_robots: int) -> tuple[np.ndarray, ...]:
    """Robots of radii 0.05 to 0.2 m packed near each other and the clutter, starts clear
    of walls and of each other (by the sum of the radii)."""
    radius = rng.choice([0.05, 0.1, 0.12, 0.2], (n_worlds, n_robots))
    x, y = np.empty((n_worlds, n_robots)), np.empty((n_worlds, n_robots))
    for w in range(n_worlds):
        pts: list[tuple[float, float]] = []
        while len(pts) < n_robots:  # a new centre until the world's robots fit around one
            centre, pts = rng.uniform(0.6, 2.4, 2), []
            for _ in range(300):
                p = tuple(centre + rng.uniform(-0.5, 0.5, 2))
                r = radius[w, len(pts)]
                if scene.is_usable(0, p, float(r)) and all(math.dist(p, q) >= r + radius[w, k] for k, q in enumerate(pts)):
                    pts.append(p)
                    if len(pts) == n_robots:
                        break
        x[w], y[w] = np.array(pts).T
    return x, y, radius


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("path", ["array", "compiled"])
@pytest.mark.parametrize("n_robots", [2, 4])
def test_crowds_of_different_radii_among_walls_match_the_backend(device: str, path: str, n_robots: int) -> None:
    # As above, each robot with its own radius: walls at its radius, robots at the sum.
    from pointnav_core.vector.contacts_jit import advance_compiled, available
    from pointnav_core.vector.floors import FloorTables

    rng = np.random.default_rng(20 + n_robots)
    scene, geom = _cluttered_room(rng)
    a = make_arrays(device)
    n_worlds, travel = 120, 0.05
    x, y, radius = _mixed_crowds(rng, scene, n_worlds, n_robots)
    speed = rng.uniform(0.0, travel, (n_worlds, n_robots)) * (rng.random((n_worlds, n_robots)) > 0.2)
    heading = rng.uniform(-math.pi, math.pi, (n_worlds, n_robots))
    mx, my = speed * np.cos(heading), speed * np.sin(heading)
    want_x, want_y, want_c = np.empty_like(x), np.empty_like(y), np.zeros(x.shape, bool)
    for w in range(n_worlds):
        discs = [_Disc(*map(float, v)) for v in zip(x[w], y[w], mx[w], my[w], radius[w])]
        for d in discs:
            d.geom = geom
        advance(discs, stop=False)
        want_x[w], want_y[w], want_c[w] = [d.x for d in discs], [d.y for d in discs], [d.contact for d in discs]
    floors = FloorTables([scene], 0, 0.2, a)
    args = [a.asarray(v) for v in (x, y, mx, my)]
    scene_ids = a.zeros(x.shape, a.i64)
    limit = travel * (1 + 1e-9)
    if path == "array":
        walls = robot_walls(floors, scene_ids, *args, a.asarray(radius), limit)
        got = [a.numpy(v) for v in advance_robots(a, *args, a.asarray(radius), walls=walls)]
    else:
        if not available(floors):
            pytest.skip("the compiled path needs numba")
        got = advance_compiled(floors, scene_ids, *args, a.full(x.shape, True, a.boolean), a.asarray(radius), limit)
    np.testing.assert_allclose(got[0], want_x, atol=1e-9)
    np.testing.assert_allclose(got[1], want_y, atol=1e-9)
    np.testing.assert_array_equal(got[2], want_c)
    assert want_c.any() and not want_c.all()
    # Independently: no two robots end overlapping by more than the hit tolerance.
    gap = np.hypot(got[0][:, :, None] - got[0][:, None, :], got[1][:, :, None] - got[1][:, None, :])
    gap[:, np.arange(n_robots), np.arange(n_robots)] = np.inf
    assert (gap - (radius[:, :, None] + radius[:, None, :])).min() >= -1e-8
