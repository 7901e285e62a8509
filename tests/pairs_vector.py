"""Plain and compiled paths of the batched engine: the checks of
``property_tests/test_compiled_paths.py`` for ``vector._scan_kernel`` and
``vector._contact_kernel``.

Each check takes ``plain_paths``, the context its plain side runs in (``numpy_paths()``); the
contact checks also take ``device`` (numpy, and torch on the CPU).

The batched range scan: for random grid scenes (obstacle cells, VOID, the map's edge) and
random poses of up to four robots per world, some absent, at robot radius / cell size ratios
from 0.3 to 5 (one radius for all robots, or each robot its own), the compiled path (numba)
and the array path (numpy, and torch on the CPU) give the same ranges, and every range lies
within 1e-4 m of an independent reference (``scan_reference``: shapely rays against the
blocked squares, a frame round the map and the other robots' discs), so no ray passes a
blocked cell; one case is a 2000 x 2000 floor.

The batched contacts: for random grid scenes (clutter, walls), robots crowded around a point
and random chords up to half a cell long (the longest the batched engines make:
``TRAVEL_CELLS``), the robots within reach of each other always resolved together (as the
engines' slow robots), driven for several rounds from where the last round left them (so that
they rest against walls and each other),
:func:`~pointnav_core.vector.contacts_jit.advance_compiled` gives the same end positions (bit
for bit on numpy, within 1e-12 m on torch) and contact flags as the array path, with one
radius for all robots or each robot its own: with several robots per world
:func:`~pointnav_core.vector.robots.advance_robots` (which the kinematic backend's resolver
checks in ``tests/test_vector_robots.py``), with one :func:`~pointnav_core.vector.contacts.advance`;
and whole engines step alike on both paths.
"""

from __future__ import annotations

import contextlib
import importlib.util
from collections.abc import Callable
from contextlib import AbstractContextManager

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scan_reference import assert_within, blocked_shapes, reference_ranges

from pointnav_core.floor.maps import OBSTACLE, VOID
from pointnav_core.scenes import Scene
from pointnav_core.sensors import scan_angles
from pointnav_core.vector.scan import ScanTables, cast_batch, compiled_available
from pointnav_core.vector.xp import make_arrays

HAS_TORCH = importlib.util.find_spec("torch") is not None
DEVICES = ["numpy"] + (["cpu"] if HAS_TORCH else [])
ATOL = 1e-4

Plain = Callable[[], AbstractContextManager[None]]


def random_grid(rng: np.random.Generator, rows: int, cols: int, density: float) -> np.ndarray:
    """A grid of OBSTACLE cells of ``density`` and 5 % VOID cells."""
    grid = np.zeros((rows, cols), np.uint8)
    grid[rng.random((rows, cols)) < density] = OBSTACLE
    grid[rng.random((rows, cols)) < 0.05] = VOID
    return grid


def _paths(plain_paths, scenes, tables_np, scene, x, y, yaw, present, radius, angles, max_range, crowd=None):
    """Ranges by every available path: array (numpy), numba, torch array, torch numba."""
    with plain_paths():
        out = {"array": cast_batch(tables_np, scene, x, y, yaw, present, radius, angles, max_range, "array", crowd)}
    if compiled_available():
        out["numba"] = cast_batch(tables_np, scene, x, y, yaw, present, radius, angles, max_range, "numba", crowd)
    if HAS_TORCH:
        import torch

        tables_t = ScanTables(scenes, 0, make_arrays("cpu"))
        rad = radius if isinstance(radius, float) else torch.as_tensor(radius)
        args = (torch.as_tensor(scene), *(torch.as_tensor(v) for v in (x, y, yaw, present)), rad, angles, max_range)
        crowd_t = None if crowd is None else tuple(torch.as_tensor(v) for v in crowd)
        with plain_paths():
            out["torch"] = cast_batch(tables_t, *args, "array", crowd_t).numpy()
        if compiled_available():  # torch on the CPU goes through the kernel, on views
            out["torch numba"] = cast_batch(tables_t, *args, "numba", crowd_t).numpy()
    return out


def _check_scenes(plain_paths, scenes, x, y, yaw, present, scene, radius, angles, max_range, crowd=None):
    tables = ScanTables(scenes, 0, make_arrays("numpy"))
    results = _paths(plain_paths, scenes, tables, scene, x, y, yaw, present, radius, angles, max_range, crowd)
    ref = results["array"]
    for name, got in results.items():
        assert got.shape == x.shape + (len(angles),)
        # The compiled path decides every crossing on the same numbers: equal to the ulp.
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-9, err_msg=f"{name} vs array")
    shapes = {}
    w_n, r_n = x.shape
    for w in range(w_n):
        k = int(scene[w])
        if k not in shapes:
            tmap = scenes[k].floors[0]
            shapes[k] = blocked_shapes(np.asarray(tmap.codes), float(tmap.resolution), tuple(tmap.origin))
        for i in range(r_n):
            if not present[w, i]:
                assert (ref[w, i] == max_range).all()
                continue
            rad = np.broadcast_to(radius, x.shape)  # one radius, or each robot's own
            discs = [(x[w, m], y[w, m], rad[w, m]) for m in range(r_n) if m != i and present[w, m]]
            if crowd is not None:  # the world's pedestrians: its first qn[w] discs
                discs += [(crowd[0][w, q], crowd[1][w, q], crowd[2][w, q]) for q in range(int(crowd[3][w]))]
            loose, strict = reference_ranges(shapes[k], (x[w, i], y[w, i]), yaw[w, i] + angles, max_range, discs)
            for got in results.values():
                assert_within(got[w, i], loose, strict, ATOL)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**31 - 1),
    n_worlds=st.integers(1, 3),
    n_robots=st.integers(1, 4),
    ratio=st.floats(0.3, 5.0),
    res=st.sampled_from([0.05, 0.1, 0.25]),
    n_rays=st.integers(1, 24),
    max_range=st.floats(0.3, 4.0),
    own_radii=st.booleans(),
    walkers=st.integers(-1, 6),
)
def check_batched_scan(seed, n_worlds, n_robots, ratio, res, n_rays, max_range, own_radii, walkers,
                       plain_paths: Plain) -> None:
    """Random scenes of floors of different cell sizes, maybe with pedestrians (``walkers``
    discs a world at most; -1: none given): every path equal, and against shapely."""
    rng = np.random.default_rng(seed)
    scenes = []
    for cell in (res, float(rng.choice([0.05, 0.1, 0.25]))):  # worlds on floors of different cell sizes
        rows, cols = rng.integers(4, 30, 2)
        scenes.append(Scene.from_array(random_grid(rng, rows, cols, rng.uniform(0.0, 0.3)), cell, origin=tuple(rng.uniform(-2, 2, 2))))
    scene = rng.integers(0, 2, n_worlds)
    x = np.empty((n_worlds, n_robots))
    y = np.empty((n_worlds, n_robots))
    for w in range(n_worlds):
        tmap = scenes[scene[w]].floors[0]
        h, wd = np.asarray(tmap.codes).shape
        res = float(tmap.resolution)
        # Anywhere on the map, obstacles and VOID included; some on grid lines.
        x[w] = tmap.origin[0] + rng.uniform(0, wd, n_robots) * res
        y[w] = tmap.origin[1] + rng.uniform(0, h, n_robots) * res
        snap = rng.random(n_robots) < 0.2
        x[w, snap] = tmap.origin[0] + np.round(rng.uniform(0, wd, snap.sum())) * res
    yaw = rng.uniform(-2 * np.pi, 2 * np.pi, (n_worlds, n_robots))
    present = rng.random((n_worlds, n_robots)) < 0.8
    angles = scan_angles(n_rays, rng.uniform(0.5, 2 * np.pi))
    radius = ratio * float(scenes[0].floors[0].resolution)
    if own_radii:  # each robot its own radius, down to a fifth of the drawn one
        radius = radius * rng.uniform(0.2, 1.0, (n_worlds, n_robots))
    crowd = None
    if walkers >= 0:  # discs near the robots (some over them), each world its own count
        q = max(walkers, 0)
        near = rng.integers(0, n_robots, (n_worlds, q))
        qx = np.take_along_axis(x, near, 1) + rng.uniform(-1.5, 1.5, (n_worlds, q)) * max_range
        qy = np.take_along_axis(y, near, 1) + rng.uniform(-1.5, 1.5, (n_worlds, q)) * max_range
        crowd = (qx, qy, rng.uniform(0.05, 0.4, (n_worlds, q)), rng.integers(0, q + 1, n_worlds))
    _check_scenes(plain_paths, scenes, x, y, yaw, present, scene, radius, angles, max_range, crowd)


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31 - 1), res=st.sampled_from([0.05, 0.1, 0.25]), max_range=st.floats(0.3, 3.0))
def check_batched_scan_wall_near_range(seed, res, max_range, plain_paths: Plain) -> None:
    """Robots in an open room whose nearest wall lies within a few cells of the scan's
    range, on either side: where the compiled cast may skip a robot's walks (open space
    beyond the range) or must walk them (a wall just within it)."""
    rng = np.random.default_rng(seed)
    span = 2 * (int(np.ceil(max_range / res)) + 8)  # the map's edge beyond every robot's range
    grid = np.zeros((2 * span + 3, 2 * span + 3), np.uint8)
    grid[:, span + 1] = OBSTACLE  # one wall down the middle
    scene = Scene.from_array(grid, res)
    n_worlds, n_robots = 3, 4
    # Each robot at max_range -3 to +3 cells from the wall's face, left or right of it.
    gap = max_range + rng.uniform(-3.0, 3.0, (n_worlds, n_robots)) * res
    side = rng.choice([-1.0, 1.0], (n_worlds, n_robots))
    ox, oy = scene.floors[0].origin
    wall_lo, wall_hi = ox + (span + 1) * res, ox + (span + 2) * res
    x = np.where(side < 0, wall_lo - gap, wall_hi + gap)
    y = oy + rng.uniform(span - 2.0, span + 3.0, (n_worlds, n_robots)) * res
    yaw = rng.uniform(-np.pi, np.pi, (n_worlds, n_robots))
    angles = scan_angles(int(rng.integers(8, 48)), 2 * np.pi)
    present = np.ones((n_worlds, n_robots), bool)
    _check_scenes(plain_paths, [scene], x, y, yaw, present, np.zeros(n_worlds, np.int64), 0.3 * res, angles, max_range)


@settings(max_examples=3, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31 - 1), ratio=st.floats(0.3, 5.0))
def check_batched_scan_large_floor(seed, ratio, plain_paths: Plain) -> None:
    """A 2000 x 2000 floor of 0.05 m cells, sparse clutter, rays up to 5.6 m."""
    rng = np.random.default_rng(seed)
    grid = random_grid(rng, 2000, 2000, 0.002)
    res = 0.05
    scene = Scene.from_array(grid, res)
    n = 3
    x = rng.uniform(0, 2000 * res, (1, n))
    y = rng.uniform(0, 2000 * res, (1, n))
    x[0, 1], y[0, 1] = x[0, 0] + 0.8, y[0, 0] - 0.3  # a neighbour in sight
    x[0, 2], y[0, 2] = rng.uniform(0, 0.5), rng.uniform(0, 0.5)  # near the map's corner
    yaw = rng.uniform(-np.pi, np.pi, (1, n))
    present = np.ones((1, n), bool)
    _check_scenes(plain_paths, [scene], x, y, yaw, present, np.zeros(1, np.int64), ratio * res, scan_angles(32, 2 * np.pi), 5.6)


# The chords the batched engines hand their contacts: their control-rate check lets a robot
# drive at most half a cell in one step (top speed * dt <= 0.5 * resolution), and a faster
# step (a holonomic robot's diagonal) is split into sub-steps of at most half a cell each
# (vector.drive.sub_steps). The two paths are meant to agree on chords up to that bound, so
# a round's longest chord is drawn as one of these fractions of the scene's cell size.
TRAVEL_CELLS = (0.05, 0.2, 0.35, 0.5)


def _travel(scene: Scene, cells: float) -> float:
    """The longest chord (m) of a round: ``cells`` (<= 0.5) of the floor's cell size."""
    return cells * float(scene.floors[0].resolution)


def _assert_same(device: str, got: np.ndarray, want: np.ndarray) -> None:
    # numpy's array path does each operation as the kernel does: the same floats. torch's
    # vectorised CPU kernels may round an operation differently in the last place.
    if device == "numpy":
        np.testing.assert_array_equal(got, want)
    else:
        np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-12)


@st.composite
def cluttered_scenes(draw: st.DrawFn, patch: int = 8) -> Scene:
    """A walled room, 14 to 30 cells a side, random obstacle cells, a few bars and a free
    ``patch`` x ``patch`` cell patch, 0.1 m cells."""
    rows, cols = draw(st.integers(patch + 6, 30)), draw(st.integers(patch + 6, 30))
    rng = np.random.default_rng(draw(st.integers(0, 2**31 - 1)))
    grid = np.zeros((rows, cols), np.uint8)
    grid[rng.random((rows, cols)) < draw(st.floats(0.0, 0.15))] = OBSTACLE
    for _ in range(draw(st.integers(0, 3))):  # bars: long faces to slide along
        r, c = rng.integers(rows), rng.integers(cols)
        grid[r, c : c + rng.integers(2, 8)] = OBSTACLE
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    r, c = draw(st.integers(1, rows - patch - 1)), draw(st.integers(1, cols - patch - 1))
    grid[r : r + patch, c : c + patch] = 0  # a free patch: some robot (a 1.2 m one: three of them) always fits
    return Scene.from_array(grid, 0.1)


def _crowd(
    scene: Scene, worlds: int, n_robots: int, radius: float, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Robot positions as an episode can have them: each world's robots within about 0.6 m
    of a usable point, clear of every obstacle cell and of each other (brute force).

    Robots that find no room there are put off the map, apart, and marked in the returned
    ``(worlds, n_robots)`` mask as not on the map: the engines never resolve a robot that
    is off its floor (one that fell has left the world), so they must not take part."""
    tmap = scene.floors[0]
    rows, cols = np.nonzero(np.asarray(tmap.codes) == OBSTACLE)
    res, (ox, oy) = tmap.resolution, tmap.origin[:2]
    x0, y0 = ox + cols * res, oy + rows * res
    height, width = (n * res for n in np.asarray(tmap.codes).shape)

    def clear(px: float, py: float, others: list[tuple[float, float]]) -> bool:
        dx = np.maximum(np.maximum(x0 - px, px - (x0 + res)), 0.0)
        dy = np.maximum(np.maximum(y0 - py, py - (y0 + res)), 0.0)
        walls_ok = not len(dx) or float(np.sqrt(dx * dx + dy * dy).min()) >= radius
        return walls_ok and all((px - qx) ** 2 + (py - qy) ** 2 >= (2 * radius) ** 2 for qx, qy in others)

    x, y = np.empty((worlds, n_robots)), np.empty((worlds, n_robots))
    on_map = np.ones((worlds, n_robots), bool)
    for w in range(worlds):
        cx, cy = scene.get_random_point(0, robot=radius, rng=rng)[1][:2]
        placed = [(cx, cy)]
        for _ in range(200):
            if len(placed) == n_robots:
                break
            px, py = cx + rng.uniform(-0.6, 0.6), cy + rng.uniform(-0.6, 0.6)
            if 0.0 < px - ox < width and 0.0 < py - oy < height and clear(px, py, placed):
                placed.append((px, py))
        on_map[w, len(placed) :] = False
        while len(placed) < n_robots:  # no room near it: off the map, apart
            placed.append((ox - 10.0 * len(placed), oy - 10.0))
        x[w], y[w] = [p[0] for p in placed], [p[1] for p in placed]
    return x, y, on_map


def _chords(rng: np.random.Generator, shape: tuple[int, ...], travel: float) -> tuple[np.ndarray, np.ndarray]:
    heading = rng.uniform(-np.pi, np.pi, shape)
    length = rng.uniform(0.0, travel, shape)
    length[rng.random(shape) < 0.3] = travel  # full speed, often
    length[rng.random(shape) < 0.1] = 0.0  # standing robots still block
    return length * np.cos(heading), length * np.sin(heading)


def _resolved(
    rng: np.random.Generator, x: np.ndarray, y: np.ndarray, mx: np.ndarray, my: np.ndarray,
    radii: np.ndarray, on_map: np.ndarray,
) -> np.ndarray:
    """The robots a round resolves, chosen as the engines choose their slow robots: every
    robot with another one within reach (the sum of both radii and both chords, m) takes
    part, the others at random (85 %), robots off the map never. A robot that is not
    resolved is then out of every resolved robot's reach, so none drives into it: robots
    that do not block (``present`` False) never overlap the others, as in the engines."""
    n_robots = x.shape[1]
    reach = radii + np.hypot(mx, my)  # (W, R)
    gap = reach[:, :, None] + reach[:, None, :]
    dist2 = (x[:, :, None] - x[:, None, :]) ** 2 + (y[:, :, None] - y[:, None, :]) ** 2
    near = ~np.eye(n_robots, dtype=bool) & on_map[:, None, :] & (dist2 <= gap * gap)
    return ((rng.random(x.shape) < 0.85) | near.any(-1)) & on_map


@settings(max_examples=25, deadline=None)
@given(scene=cluttered_scenes(), seed=st.integers(0, 2**31 - 1), n_robots=st.integers(2, 5),
       radius=st.sampled_from([0.0, 0.05, 0.12, 0.18]), cells=st.sampled_from(TRAVEL_CELLS),
       own_radii=st.booleans())
def check_contacts_multi_robot(
    device: str, scene: Scene, seed: int, n_robots: int, radius: float, cells: float, own_radii: bool, plain_paths: Plain
) -> None:
    """Several robots a world: ``advance_compiled`` against ``advance_robots``."""
    from pointnav_core.vector.contacts_jit import advance_compiled
    from pointnav_core.vector.floors import FloorTables
    from pointnav_core.vector.robots import advance_robots, robot_walls
    from pointnav_core.vector.xp import make_arrays

    rng = np.random.default_rng(seed)
    a, worlds = make_arrays(device), 12
    travel = _travel(scene, cells)
    floors = FloorTables([scene], 0, radius, a)
    x, y, on_map = _crowd(scene, worlds, n_robots, radius, rng)
    scene_ids = a.zeros((worlds, n_robots), a.i64)
    # Placed for the drawn radius, so smaller robots fit too: radii from 0 to it, per robot.
    radii = rng.choice([0.0, 0.5, 1.0], (worlds, n_robots)) * radius if own_radii else np.full((worlds, n_robots), radius)
    rad = a.asarray(radii) if own_radii else radius
    for _ in range(6):
        mx, my = _chords(rng, (worlds, n_robots), travel)
        slow = _resolved(rng, x, y, mx, my, radii, on_map)
        args = [a.asarray(v) for v in (x, y, mx, my)]
        walls = robot_walls(floors, scene_ids, *args, rad, travel)
        with plain_paths():
            want = [a.numpy(v) for v in advance_robots(a, *args, rad, present=a.asarray(slow, a.boolean), walls=walls)]
        got = advance_compiled(floors, scene_ids, *args, a.asarray(slow, a.boolean), rad, travel)
        _assert_same(device, got[0][slow], want[0][slow])
        _assert_same(device, got[1][slow], want[1][slow])
        np.testing.assert_array_equal(got[2][slow], want[2][slow])
        # The robots not resolved stay where they were and touch nothing.
        np.testing.assert_array_equal(got[0][~slow], x[~slow])
        assert not got[2][~slow].any()
        x, y = want[0], want[1]


@settings(max_examples=25, deadline=None)
@given(scene=cluttered_scenes(), seed=st.integers(0, 2**31 - 1),
       radius=st.sampled_from([0.0, 0.05, 0.12, 0.18]), cells=st.sampled_from(TRAVEL_CELLS),
       own_radii=st.booleans())
def check_contacts_one_robot(
    device: str, scene: Scene, seed: int, radius: float, cells: float, own_radii: bool, plain_paths: Plain
) -> None:
    """One robot a world: ``advance_compiled`` against ``vector.contacts.advance``."""
    from pointnav_core.vector.contacts import advance
    from pointnav_core.vector.contacts_jit import advance_compiled
    from pointnav_core.vector.floors import FloorTables
    from pointnav_core.vector.xp import make_arrays

    rng = np.random.default_rng(seed)
    a, worlds = make_arrays(device), 48
    travel = _travel(scene, cells)
    limit = travel * (1.0 + 1e-9) + 1e-12  # the env's max_travel: a chord's rounding fits
    floors = FloorTables([scene], 0, radius, a)
    x, y, _ = _crowd(scene, worlds, 1, radius, rng)
    x, y = x[:, 0], y[:, 0]
    scene_ids = a.zeros(worlds, a.i64)
    rad = a.asarray(rng.choice([0.0, 0.5, 1.0], worlds) * radius) if own_radii else radius
    for _ in range(6):
        mx, my = _chords(rng, (worlds,), travel)
        args = [a.asarray(v) for v in (x, y, mx, my)]
        with plain_paths():
            want = [a.numpy(v) for v in advance(floors, scene_ids, *args, rad, limit)]
        got = advance_compiled(floors, scene_ids[:, None], *(v[:, None] for v in args),
                               a.asarray(np.ones((worlds, 1), bool), a.boolean),
                               rad[:, None] if own_radii else rad, limit)
        _assert_same(device, got[0][:, 0], want[0])
        _assert_same(device, got[1][:, 0], want[1])
        np.testing.assert_array_equal(got[2][:, 0], want[2])
        x, y = want[0], want[1]


@settings(max_examples=10, deadline=None)
@given(scene=cluttered_scenes(patch=12), seed=st.integers(0, 2**31 - 1), n_robots=st.integers(1, 3),
       drive=st.sampled_from(["holonomic", "differential"]))
def check_engines_step_alike(device: str, scene: Scene, seed: int, n_robots: int, drive: str, plain_paths: Plain) -> None:
    """Whole engines, sub-steps included (a holonomic robot's diagonal step takes two), give
    the same poses, contacts and rewards with the compiled contacts as with the array path
    (the path a GPU takes; on torch it runs on the CPU here). The array run takes every
    plain path (``plain_paths``), the scan's too, which gives the compiled scan's ranges."""
    from fleet_reference import fleet_episodes
    from vector_reference import random_actions, random_episodes

    from pointnav_core.vector import VectorPointNavEnv

    rng = np.random.default_rng(seed)
    worlds, steps = 6, 40
    if n_robots == 1:
        episodes = random_episodes(scene, worlds, rng)
    else:
        episodes = fleet_episodes(scene, worlds, n_robots, rng, goal_gap=0.4)
    actions = random_actions(rng, (steps, worlds) if n_robots == 1 else (steps, worlds, n_robots), drive)
    kwargs = {"scene": scene, "robot": {"drive": drive}, "seed": seed, "pool_size": 2, "n_robots": n_robots,
              "device": device,
              "task": {"goal_tolerance": 0.1, "termination_config": {"max_steps": 25, "max_collisions": 30}}}
    runs = []
    for compiled in (True, False):
        with contextlib.nullcontext() if compiled else plain_paths():
            env = VectorPointNavEnv(worlds, **kwargs)
            to_np = env.arrays.numpy
            out = [[to_np(env.reset(options={"episodes": episodes})[0])]]
            for act in actions:
                obs, reward, terminated, truncated, info = env.step(act)
                out.append([to_np(v) for v in (obs, reward, terminated, truncated, info["in_contact"],
                                               env.state.x, env.state.y, env.state.yaw)])
        runs.append(out)
    for t, (got, want) in enumerate(zip(*runs)):
        for g, w in zip(got, want):
            if g.dtype == np.bool_:
                np.testing.assert_array_equal(g, w, err_msg=f"step {t}")
            else:
                np.testing.assert_allclose(g, w, rtol=0.0, atol=1e-9, err_msg=f"step {t}")
