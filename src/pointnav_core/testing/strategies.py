"""Hypothesis strategies for pointnav-core values, exported for users' own property tests.

Strategies build valid values directly (rather than filtering) and put the simplest choice
first, so that failures shrink to something readable.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import note
from hypothesis import strategies as st

from pointnav_core import floorplans
from pointnav_core.errors import ArgumentError
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID, TraversableMap
from pointnav_core.floorplans import FloorPlan

__all__: list[str] = [
    "code_grids",
    "traversable_maps",
    "maps_with_points",
    "floor_plans",
    "unit_quaternions",
    "yaws",
    "euler_angles",
    "finite_vectors",
]


def floor_plans(
    kinds: tuple[str, ...] = ("rooms", "maze", "clutter"),
) -> st.SearchStrategy[FloorPlan]:
    """Procedurally generated :class:`~pointnav_core.floorplans.FloorPlan` values.

    Draws a generator from ``kinds`` (``"rooms"``, ``"maze"``, ``"clutter"``), a seed and a
    modest size (8 to 20 m a side), keeping every other parameter at its default, so that the
    plans' connectivity guarantee holds: one connected free region for robots narrower than
    the 0.8 m clearance, less grid slack (a 0.2 m radius on a 0.1 m grid is safe). The call
    that rebuilds a failing plan is printed with the falsifying example. Shrinks towards the
    first kind, seed 0 and the smallest size.

    Parameters
    ----------
    kinds : tuple of str
        A non-empty subset of ``("rooms", "maze", "clutter")``.
    """
    valid = ("rooms", "maze", "clutter")
    kinds = tuple(kinds)
    unknown = [k for k in kinds if k not in valid]
    if not kinds or unknown:
        raise ArgumentError(f"kinds must be a non-empty subset of {valid}, got {kinds!r}")
    return _floor_plans(kinds)


@st.composite
def _floor_plans(draw: st.DrawFn, kinds: tuple[str, ...]) -> FloorPlan:
    kind = draw(st.sampled_from(kinds))
    seed = draw(st.integers(0, 2**32 - 1))
    width = draw(st.floats(8.0, 20.0))
    height = draw(st.floats(8.0, 20.0))
    note(f"pointnav_core.floorplans.{kind}({seed}, size=({width!r}, {height!r}))")
    return getattr(floorplans, kind)(seed, size=(width, height))


# ----------------------------------------------------------------------- transforms


@st.composite
def unit_quaternions(draw: st.DrawFn) -> np.ndarray:
    """Unit quaternions ``(x, y, z, w)`` as float64 arrays of shape (4,), covering all rotations.

    Built without filtering: one component, the lead, gets a magnitude in [0.5, 1] and the
    others lie in [-1, 1], so the norm is at least 0.5 before normalising. Every unit
    quaternion is reachable (its largest component is at least 0.5), both signs included.
    Shrinks towards the identity ``(0, 0, 0, 1)``.
    """
    lead = draw(st.sampled_from((3, 0, 1, 2)))  # w first: shrinks to the identity
    magnitude = draw(st.floats(0.5, 1.0))
    sign = draw(st.sampled_from((1.0, -1.0)))
    q = [draw(st.floats(-1.0, 1.0)) if i != lead else sign * magnitude for i in range(4)]
    arr = np.array(q, dtype=np.float64)
    return arr / np.linalg.norm(arr)


def yaws(
    min_value: float = -math.pi, max_value: float = math.pi
) -> st.SearchStrategy[float]:
    """Headings in radians in ``[min_value, max_value]`` (default ``[-pi, pi]``).

    Shrinks towards 0 when it is in range. Pass a wider range (e.g. ``-4 * pi`` to ``4 * pi``)
    to test wrapping.

    Parameters
    ----------
    min_value, max_value : float
        Bounds in radians, finite, ``min_value <= max_value``.
    """
    if not (math.isfinite(min_value) and math.isfinite(max_value) and min_value <= max_value):
        raise ArgumentError(
            f"min_value and max_value must be finite with min_value <= max_value, "
            f"got {min_value!r} and {max_value!r}"
        )
    return st.floats(min_value, max_value)


def euler_angles(gimbal_margin: float = 0.0) -> st.SearchStrategy[np.ndarray]:
    """Euler angles ``(roll, pitch, yaw)`` in canonical ranges, as float64 arrays of shape (3,).

    Roll and yaw lie in (-pi, pi] and pitch in ``[-pi/2 + gimbal_margin, pi/2 - gimbal_margin]``;
    a positive ``gimbal_margin`` (radians) keeps away from gimbal lock, where roll and yaw
    are not unique. Shrinks towards ``(0, 0, 0)``.

    Parameters
    ----------
    gimbal_margin : float
        Distance in radians to keep from pitch = +-pi/2, in [0, pi/2).
    """
    if not 0.0 <= gimbal_margin < math.pi / 2:
        raise ArgumentError(f"gimbal_margin must be in [0, pi/2) radians, got {gimbal_margin!r}")
    half_turn = st.floats(-math.pi, math.pi, exclude_min=True)
    limit = math.pi / 2 - gimbal_margin
    return st.tuples(half_turn, st.floats(-limit, limit), half_turn).map(
        lambda angles: np.array(angles, dtype=np.float64)
    )


def finite_vectors(n: int, max_abs: float = 1e3) -> st.SearchStrategy[np.ndarray]:
    """Float64 arrays of shape ``(n,)`` with entries in ``[-max_abs, max_abs]``.

    The default bound (1 km for positions in metres) keeps sums and squares far from
    overflow, so tolerances in properties stay meaningful. Shrinks towards the zero vector.

    Parameters
    ----------
    n : int
        Length of the vectors, >= 1.
    max_abs : float
        Largest absolute value of an entry, finite and > 0.
    """
    if not (isinstance(n, int) and n >= 1):
        raise ArgumentError(f"n must be an int >= 1, got {n!r}")
    if not (math.isfinite(max_abs) and max_abs > 0):
        raise ArgumentError(f"max_abs must be a finite number > 0, got {max_abs!r}")
    return st.lists(st.floats(-max_abs, max_abs), min_size=n, max_size=n).map(
        lambda values: np.array(values, dtype=np.float64)
    )


# ----------------------------------------------------------------------- robots and actions


def robot_specs(
    drives: tuple[str, ...] = ("differential", "holonomic"),
    max_radius: float = 0.5,
    max_speed: float = 2.0,
) -> st.SearchStrategy:
    """Valid :class:`~pointnav_core.backends.robot_spec.RobotSpec` values.

    Radii lie in ``[0, max_radius]`` metres (shrinking to 0, a point robot), linear speed
    limits in ``[0.01, max_speed]`` m/s, yaw-rate limits in ``[0.01, 2 pi]`` rad/s, and the
    drive is drawn from ``drives`` (shrinking to the first).

    Parameters
    ----------
    drives : tuple of str
        A non-empty subset of ``("differential", "holonomic")``.
    max_radius : float
        Largest radius in metres, >= 0.
    max_speed : float
        Largest ``max_linear_velocity`` in m/s, >= 0.01.
    """
    from pointnav_core.backends.robot_spec import DRIVES, RobotSpec

    drives = tuple(drives)
    if not drives or any(d not in DRIVES for d in drives):
        raise ArgumentError(f"drives must be a non-empty subset of {tuple(DRIVES)}, got {drives!r}")
    if not (math.isfinite(max_radius) and max_radius >= 0.0):
        raise ArgumentError(f"max_radius must be a finite number >= 0 (metres), got {max_radius!r}")
    if not (math.isfinite(max_speed) and max_speed >= 0.01):
        raise ArgumentError(f"max_speed must be a finite number >= 0.01 (m/s), got {max_speed!r}")
    return st.builds(
        RobotSpec,
        radius=st.floats(0.0, max_radius),
        max_linear_velocity=st.floats(0.01, max_speed),
        max_angular_velocity=st.floats(0.01, 2 * math.pi),
        drive=st.sampled_from(drives),
    )


def robot_actions(spec: object, overshoot: float = 0.0) -> st.SearchStrategy[np.ndarray]:
    """Actions for a robot of ``spec``: float64 arrays of shape ``(spec.action_dim,)``.

    Components lie in ``[-1 - overshoot, 1 + overshoot]``; a positive ``overshoot`` also
    exercises clipping. Shrinks towards the zero action (standing still).

    Parameters
    ----------
    spec : RobotSpec
        The robot the actions are for.
    overshoot : float
        How far beyond ``[-1, 1]`` components may go, >= 0.
    """
    if not (math.isfinite(overshoot) and overshoot >= 0.0):
        raise ArgumentError(f"overshoot must be a finite number >= 0, got {overshoot!r}")
    bound = 1.0 + overshoot
    n = int(spec.action_dim)  # type: ignore[attr-defined]
    return st.lists(st.floats(-bound, bound), min_size=n, max_size=n).map(
        lambda values: np.array(values, dtype=np.float64)
    )


__all__ += ["robot_specs", "robot_actions"]


# ----------------------------------------------------------------------- maps


@st.composite
def code_grids(draw: st.DrawFn, min_side: int = 2, max_side: int = 24) -> np.ndarray:
    """Cell-code grids (uint8, FREE/OBSTACLE/VOID) made of a free floor and a few rectangles.

    At least one cell is FREE. Shrinks towards a small, all-free grid.
    """
    h = draw(st.integers(min_side, max_side))
    w = draw(st.integers(min_side, max_side))
    grid = np.full((h, w), FREE, dtype=np.uint8)
    for _ in range(draw(st.integers(0, 6))):
        r0, c0 = draw(st.integers(0, h - 1)), draw(st.integers(0, w - 1))
        r1, c1 = draw(st.integers(r0, h - 1)), draw(st.integers(c0, w - 1))
        grid[r0 : r1 + 1, c0 : c1 + 1] = draw(st.sampled_from((OBSTACLE, VOID)))
    if not (grid == FREE).any():
        grid[draw(st.integers(0, h - 1)), draw(st.integers(0, w - 1))] = FREE
    return grid


@st.composite
def traversable_maps(draw: st.DrawFn, max_side: int = 24) -> TraversableMap:
    """Small :class:`~pointnav_core.floor.maps.TraversableMap` values with a random origin."""
    grid = draw(code_grids(max_side=max_side))
    resolution = draw(st.sampled_from((0.1, 0.05, 0.25, 1.0)))
    origin = (draw(st.floats(-50.0, 50.0)), draw(st.floats(-50.0, 50.0)))
    height = draw(st.floats(-5.0, 5.0))
    return TraversableMap(grid, resolution, origin, height)


@st.composite
def maps_with_points(
    draw: st.DrawFn, n_points: int = 2, max_side: int = 24, max_radius_cells: float = 2.5
) -> tuple[TraversableMap, float, np.ndarray]:
    """A map, a robot radius (m) and ``n_points`` usable world points (n, 2) on it.

    The radius is chosen so that some cell is usable; points lie anywhere inside usable
    cells (not only at centres) where the disc fits, else at the cell's centre.
    """
    tmap = draw(traversable_maps(max_side=max_side))
    radius = draw(st.floats(0.0, max_radius_cells)) * tmap.resolution
    if not tmap.usable(radius).any():
        radius = 0.0
    cells = np.argwhere(tmap.usable(radius))
    points = []
    for _ in range(n_points):
        r, c = cells[draw(st.integers(0, len(cells) - 1))]
        fr, fc = draw(st.floats(0.05, 0.95)), draw(st.floats(0.05, 0.95))
        point = tmap.grid_to_world(np.array([r + fr, c + fc]))
        if not tmap.is_usable(point, radius):
            point = tmap.cell_to_world(np.array([r, c]))
        points.append(point)
    return tmap, radius, np.array(points)


# ----------------------------------------------------------------------- navigation episodes


@st.composite
def nav_scenes(draw: st.DrawFn, min_side: int = 16, max_side: int = 22) -> object:
    """Small one-floor :class:`~pointnav_core.scenes.Scene` values for whole episodes.

    A room of ``min_side`` to ``max_side`` cells a side (0.1 m cells) walled by OBSTACLE
    cells, with up to three 2 x 2 obstacle blocks inside and, sometimes, a hole (VOID)
    two cells deep along one wall, so that episodes can end by falling. Small blocks in a
    room at least 1.4 m across leave space for robots up to :func:`nav_robot_specs`'
    radius to move and for goals half a metre from the start. Shrinks towards an empty
    room of ``min_side`` cells.

    Parameters
    ----------
    min_side, max_side : int
        Bounds on the number of cells per side, ``16 <= min_side <= max_side``.
    """
    from pointnav_core.scenes import Scene  # this block was appended: import here

    if not 16 <= min_side <= max_side:
        raise ArgumentError(
            f"min_side and max_side must satisfy 16 <= min_side <= max_side, got "
            f"{min_side!r} and {max_side!r}"
        )
    rows = draw(st.integers(min_side, max_side))
    cols = draw(st.integers(min_side, max_side))
    grid = np.full((rows, cols), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    for _ in range(draw(st.integers(0, 3))):
        r = draw(st.integers(2, rows - 4))
        c = draw(st.integers(2, cols - 4))
        grid[r : r + 2, c : c + 2] = OBSTACLE
    hole = draw(st.sampled_from((None, "left", "right", "bottom", "top")))
    if hole == "left":
        grid[1:-1, 1:3] = VOID
    elif hole == "right":
        grid[1:-1, -3:-1] = VOID
    elif hole == "bottom":
        grid[1:3, 1:-1] = VOID
    elif hole == "top":
        grid[-3:-1, 1:-1] = VOID
    note(f"nav_scenes: grid rows={rows} cols={cols} hole={hole}\n{grid}")
    return Scene.from_array(grid, 0.1)


def nav_robot_specs() -> st.SearchStrategy:
    """Robots for :func:`nav_scenes`: radius 0 to 0.12 m, default speeds, either drive.

    Shrinks towards a point robot with differential drive.
    """
    from pointnav_core.backends.robot_spec import RobotSpec

    return st.builds(
        RobotSpec,
        radius=st.floats(0.0, 0.12),
        drive=st.sampled_from(("differential", "holonomic")),
    )


@st.composite
def nav_task_kwargs(draw: st.DrawFn, max_steps: int = 60) -> dict:
    """Keyword arguments of :class:`~pointnav_core.task.PointNavigationTask` for short episodes.

    Draws ``reward_type``, ``goal_tolerance`` (0.1 to 0.5 m), ``goal_in_polar`` and full
    termination and reward configs (``max_steps`` from 1 to ``max_steps``, small
    ``max_collisions``, any ``fall_height`` up to 0.1 m, rewards from 0). Start and goal
    are sampled. Shrinks towards L2 rewards, cartesian goals and one-step episodes.

    Parameters
    ----------
    max_steps : int
        Largest ``max_steps`` drawn, >= 1.
    """
    if not (isinstance(max_steps, int) and max_steps >= 1):
        raise ArgumentError(f"max_steps must be an int >= 1, got {max_steps!r}")
    return {
        "reward_type": draw(st.sampled_from(("l2", "geodesic"))),
        "goal_tolerance": draw(st.floats(0.1, 0.5)),
        "goal_in_polar": draw(st.booleans()),
        "termination_config": {
            "max_steps": draw(st.integers(1, max_steps)),
            "max_collisions": draw(st.integers(0, 20)),
            "fall_height": draw(st.floats(0.0, 0.1)),
        },
        "reward_config": {
            "r_potential": draw(st.floats(0.0, 5.0)),
            "r_collision": draw(st.floats(0.0, 1.0)),
            "r_pointgoal": draw(st.floats(0.0, 20.0)),
        },
    }


__all__ += ["nav_scenes", "nav_robot_specs", "nav_task_kwargs"]


# ----------------------------------------------------------------------- scenes and backends


@st.composite
def scenes(
    draw: st.DrawFn,
    max_floors: int = 2,
    max_side: int = 24,
    resolutions: tuple[float, ...] = (0.1, 0.05, 0.25),
) -> object:
    """Small :class:`~pointnav_core.scenes.Scene` values built with ``Scene.from_array``.

    One to ``max_floors`` floors (heights 0, 3, 6, ... m), each a :func:`code_grids` grid
    (FREE floor with OBSTACLE and VOID rectangles, at least one FREE cell) of its own size,
    sharing a resolution drawn from ``resolutions`` (m per cell) and a world origin within
    10 m of zero. Shrinks towards one small all-free floor at the first resolution and the
    origin (0, 0).

    Parameters
    ----------
    max_floors : int
        Most floors, >= 1.
    max_side : int
        Most cells along a side, >= 2.
    resolutions : tuple of float
        Cell sizes to choose from, in metres, each > 0.
    """
    from pointnav_core.scenes import Scene  # this block was appended: import here

    if not (isinstance(max_floors, int) and max_floors >= 1):
        raise ArgumentError(f"max_floors must be an int >= 1, got {max_floors!r}")
    if not (isinstance(max_side, int) and max_side >= 2):
        raise ArgumentError(f"max_side must be an int >= 2, got {max_side!r}")
    if not resolutions or not all(math.isfinite(r) and r > 0 for r in resolutions):
        raise ArgumentError(
            f"resolutions must be a non-empty tuple of numbers > 0, got {resolutions!r}"
        )
    n = draw(st.integers(1, max_floors))
    res = draw(st.sampled_from(tuple(resolutions)))
    origin = (draw(st.floats(-10.0, 10.0)), draw(st.floats(-10.0, 10.0)))
    grids = [draw(code_grids(max_side=max_side)) for _ in range(n)]
    note(f"scenes: resolution={res!r} origin={origin!r} grids={[g.tolist() for g in grids]!r}")
    return Scene.from_array(grids, res, origin=origin)


def _usable_cells(scene: object, radius: float, floors: object) -> dict[int, np.ndarray]:
    n = int(scene.n_floors)  # type: ignore[attr-defined]
    chosen = range(n) if floors is None else [floors] if isinstance(floors, int) else floors
    cells = {}
    for f in chosen:
        if not (isinstance(f, int) and 0 <= f < n):
            raise ArgumentError(f"floor must be an int in [0, {n}), got {f!r}")
        found = np.argwhere(scene.floors[f].usable(radius))  # type: ignore[attr-defined]
        if len(found):
            cells[f] = found
    return cells


def valid_poses(
    scene: object, robot: object = None, floor: int | None = None
) -> st.SearchStrategy[tuple[int, np.ndarray, np.ndarray]]:
    """Poses where a robot fits: ``(floor, position (3,), orientation (4,))``.

    The position is the centre of a cell where the robot's disc overlaps no OBSTACLE or
    VOID cell (the scene's eroded free space, ``TraversableMap.usable``), with z the floor's
    height; the orientation is a planar ``(x, y, z, w)`` quaternion. So every backend's
    ``is_valid_pose`` accepts it when no other robot is near. Shrinks towards the first
    usable floor, its first usable cell and yaw 0.

    Parameters
    ----------
    scene : Scene
        Anything with ``floors`` (TraversableMap) and ``n_floors``.
    robot : RobotSpec or float or None
        The robot (or its radius in metres); None is a point robot.
    floor : int, optional
        Only this floor (default: any floor where the robot fits).

    Raises
    ------
    ValueError
        When the robot fits nowhere on the chosen floors.
    """
    from pointnav_core.scenes import (
        robot_radius,  # this block was appended: import here
    )

    radius = robot_radius(robot)
    cells = _usable_cells(scene, radius, floor)
    if not cells:
        raise ArgumentError(
            f"robot of radius {radius} m fits nowhere on "
            f"{'floor ' + str(floor) if floor is not None else 'any floor'} of {scene!r}"
        )
    return _valid_poses(scene, cells)


@st.composite
def _valid_poses(
    draw: st.DrawFn, scene: object, cells: dict[int, np.ndarray]
) -> tuple[int, np.ndarray, np.ndarray]:
    f = draw(st.sampled_from(sorted(cells)))
    row, col = cells[f][draw(st.integers(0, len(cells[f]) - 1))]
    tmap = scene.floors[f]  # type: ignore[attr-defined]
    x, y = tmap.cell_to_world(np.array([row, col])).tolist()
    yaw = draw(yaws())
    return (
        f,
        np.array([x, y, float(tmap.height)]),
        np.array([0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)]),
    )


@st.composite
def robot_placements(
    draw: st.DrawFn, scene: object, robots: tuple[object, ...], floor: int | None = None
) -> list[tuple[int, np.ndarray, np.ndarray]]:
    """Valid poses for several robots at once, none overlapping another on its floor.

    One :func:`valid_poses` pose per robot, drawn in order; cells where a robot would
    overlap one placed before it are left out of its choices (built, not filtered). When a
    robot has no cell left the example is rejected, which is rare unless the scene is
    crowded. Shrinks like :func:`valid_poses`.

    Parameters
    ----------
    scene : Scene
        The scene.
    robots : sequence of RobotSpec or float
        The robots (or their radii in metres).
    floor : int, optional
        Put every robot on this floor (default: each on any floor where it fits).
    """
    from hypothesis import reject  # this block was appended: import here

    from pointnav_core.scenes import robot_radius

    placed: list[tuple[int, float, np.ndarray]] = []
    out = []
    for robot in robots:
        radius = robot_radius(robot)
        cells = _usable_cells(scene, radius, floor)
        free: dict[int, np.ndarray] = {}
        for f, found in cells.items():
            tmap = scene.floors[f]  # type: ignore[attr-defined]
            centres = tmap.cell_to_world(found)
            keep = np.ones(len(found), dtype=bool)
            for pf, pr, pxy in placed:
                if pf == f:
                    keep &= np.hypot(*(centres - pxy).T) >= radius + pr
            if keep.any():
                free[f] = found[keep]
        if not free:
            reject()
        pose = draw(_valid_poses(scene, free))
        placed.append((pose[0], radius, pose[1][:2]))
        out.append(pose)
    return out


def action_sequences(
    spec: object, min_steps: int = 1, max_steps: int = 20, overshoot: float = 0.0
) -> st.SearchStrategy[np.ndarray]:
    """Sequences of actions for one robot: float64 arrays of shape (steps, action_dim).

    Each row is a :func:`robot_actions` action; shrinks towards one step of the zero action.

    Parameters
    ----------
    spec : RobotSpec
        The robot the actions are for.
    min_steps, max_steps : int
        Bounds on the number of steps, ``0 <= min_steps <= max_steps``.
    overshoot : float
        How far beyond ``[-1, 1]`` components may go, >= 0 (exercises clipping).
    """
    ints = isinstance(min_steps, int) and isinstance(max_steps, int)
    if not (ints and 0 <= min_steps <= max_steps):
        raise ArgumentError(
            f"min_steps and max_steps must be ints with 0 <= min_steps <= max_steps, got "
            f"{min_steps!r} and {max_steps!r}"
        )
    n = int(getattr(spec, "action_dim"))
    return st.lists(robot_actions(spec, overshoot), min_size=min_steps, max_size=max_steps).map(
        lambda rows: np.array(rows, dtype=np.float64).reshape(len(rows), n)
    )


__all__ += ["scenes", "valid_poses", "robot_placements", "action_sequences"]


@st.composite
def cluttered_rooms(draw: st.DrawFn, max_clutter: float = 0.12, min_side: int = 12, patch: int = 6) -> object:
    """A walled room of 0.1 m cells, ``min_side`` to 30 cells a side: random OBSTACLE cells
    (up to ``max_clutter`` of them), maybe a 3 x 3 VOID hole, and a free ``patch`` x
    ``patch`` square, so that a robot (or a crowd, with a larger patch) always fits. A
    :class:`~pointnav_core.scenes.Scene`."""
    from pointnav_core.scenes import Scene

    rows, cols = draw(st.integers(min_side, 30)), draw(st.integers(min_side, 30))
    rng = np.random.default_rng(draw(st.integers(0, 2**31 - 1)))
    grid = np.zeros((rows, cols), np.uint8)
    grid[rng.random((rows, cols)) < draw(st.floats(0.0, max_clutter))] = OBSTACLE
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    if draw(st.booleans()):
        r, c = draw(st.integers(1, rows - 4)), draw(st.integers(1, cols - 4))
        grid[r : r + 3, c : c + 3] = VOID
    r, c = draw(st.integers(1, rows - 1 - patch)), draw(st.integers(1, cols - 1 - patch))
    grid[r : r + patch, c : c + patch] = FREE
    return Scene.from_array(grid, 0.1)


__all__ += ["cluttered_rooms"]
