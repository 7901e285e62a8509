"""Hypothesis strategies for scenes and what runs in them: navigation scenes, robots, task
arguments, valid poses, robot placements, action sequences and cluttered rooms.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import note
from hypothesis import strategies as st

from pointnav_core.errors import ArgumentError
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID
from pointnav_core.testing.strategies.geometry import yaws
from pointnav_core.testing.strategies.maps import code_grids
from pointnav_core.testing.strategies.robots import robot_actions

__all__ = [
    "nav_scenes",
    "nav_robot_specs",
    "nav_task_kwargs",
    "scenes",
    "valid_poses",
    "robot_placements",
    "action_sequences",
    "cluttered_rooms",
]


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
    from pointnav_core.backends.protocol import (
        RobotSpec,  # this block was appended: import here
    )

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
