"""What the conformance checks share: tolerances, the error, scenes and assertions."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from typing import Any

import numpy as np

from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.errors import BackendError
from pointnav_core.floor.maps import OBSTACLE, TraversableMap
from pointnav_core.scenes import Scene

__all__ = [
    "MOTION_TOLERANCE",
    "OVERLAP_TOLERANCE",
    "POSE_TOLERANCE",
    "BackendFactory",
    "ConformanceError",
    "obstacle_distance",
]

#: Deepest overlap (m) of a robot with an obstacle or another robot after any step.
OVERLAP_TOLERANCE = 1e-3
#: Position (m) and quaternion agreement of a pose read back after it was set.
POSE_TOLERANCE = 1e-9
#: Position (m) and yaw (rad) agreement of open-space motion with the commanded motion;
#: also the agreement of velocities with displacement / duration (m/s, rad/s).
MOTION_TOLERANCE = 1e-6

_IDENTITY = (0.0, 0.0, 0.0, 1.0)

BackendFactory = Callable[[], Any]


class ConformanceError(BackendError, AssertionError):
    """A backend failed conformance checks; the message is the report of the failures."""


# ----------------------------------------------------------------------- helpers


def _fail(message: str) -> None:
    raise AssertionError(message)


def _expect(condition: Any, message: str) -> None:
    if not condition:
        raise AssertionError(message)


def _quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def _yaw(q: Any) -> float:
    x, y, z, w = (float(v) for v in q)
    return math.atan2(2.0 * (w * z + x * y), w * w + x * x - y * y - z * z)


def _room(cells: int = 60, res: float = 0.1, heights: Sequence[float] = (0.0,)) -> Scene:
    """A square room with a one-cell wall all around; the inside spans (res, (cells-1)*res)."""
    grid = np.zeros((cells, cells), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return Scene.from_array([grid] * len(heights), res, heights=list(heights))


def _loaded(
    factory: BackendFactory, scene: Scene, specs: Sequence[RobotSpec], freq: float = 10.0
) -> Any:
    backend = factory()
    backend.load(scene, list(specs), action_frequency=freq)
    return backend


def _xyz(backend: Any, idn: int) -> np.ndarray:
    pos = np.asarray(backend.get_pose(idn)[0], dtype=np.float64)
    _expect(
        pos.shape == (3,), f"get_pose({idn}) position must have shape (3,), got shape {pos.shape}"
    )
    return pos


def _fmt(values: Any) -> str:
    return "(" + ", ".join(f"{float(v):.9g}" for v in np.ravel(values)) + ")"


def obstacle_distance(tmap: TraversableMap, x: float, y: float) -> float:
    """Return the signed distance (m) from a point to the OBSTACLE cell squares of a map.

    An exact reference, computed square by square with numpy and independent of any
    backend: a disc of radius ``r`` centred at ``(x, y)`` overlaps an obstacle by
    ``r - obstacle_distance(tmap, x, y)`` (clear when that is <= 0).

    Parameters
    ----------
    tmap : TraversableMap
        The floor; its OBSTACLE cells are closed squares of side ``tmap.resolution``.
    x, y : float
        World coordinates in metres.

    Returns
    -------
    float
        The distance to the nearest OBSTACLE square; inside a square, minus the depth
        into the square it is deepest in (the distance to that square's nearest side);
        ``inf`` when the map has no OBSTACLE cell.

    Examples
    --------
    >>> tmap = TraversableMap([[0, 0, 0, 0, 1]], resolution=1.0)  # a wall at 4 <= x <= 5
    >>> obstacle_distance(tmap, 2.5, 0.5)
    1.5
    >>> obstacle_distance(tmap, 4.25, 0.5)
    -0.25
    >>> obstacle_distance(TraversableMap([[0]], resolution=1.0), 0.5, 0.5)
    inf
    """
    rows, cols = np.nonzero(np.asarray(tmap.codes) == OBSTACLE)
    if rows.size == 0:
        return math.inf
    res = tmap.resolution
    x0 = tmap.origin[0] + cols * res
    y0 = tmap.origin[1] + rows * res
    gx = np.maximum(np.maximum(x0 - x, 0.0), x - (x0 + res))
    gy = np.maximum(np.maximum(y0 - y, 0.0), y - (y0 + res))
    inside = (x0 < x) & (x < x0 + res) & (y0 < y) & (y < y0 + res)
    depth = np.minimum.reduce([x - x0, x0 + res - x, y - y0, y0 + res - y])
    return float(np.where(inside, -depth, np.hypot(gx, gy)).min())


def _expect_clear_of_walls(
    backend: Any, scene: Scene, specs: Sequence[RobotSpec], idns: Iterable[int], when: str
) -> None:
    for idn in idns:
        x, y, _ = _xyz(backend, idn)
        floor = backend.get_robot_floor(idn)
        depth = specs[idn].radius - obstacle_distance(scene.floors[floor], x, y)
        _expect(
            depth <= OVERLAP_TOLERANCE,
            f"robot {idn} (radius {specs[idn].radius} m) ended {when} at {_fmt((x, y))} "
            f"overlapping an obstacle by {depth:.6g} m (tolerance {OVERLAP_TOLERANCE} m)",
        )


def _expect_apart(backend: Any, specs: Sequence[RobotSpec], a: int, b: int, when: str) -> float:
    gap = float(np.linalg.norm(_xyz(backend, a)[:2] - _xyz(backend, b)[:2]))
    reach = specs[a].radius + specs[b].radius
    _expect(
        gap >= reach - OVERLAP_TOLERANCE,
        f"robots {a} and {b} ended {when} {gap:.6g} m apart, overlapping by "
        f"{reach - gap:.6g} m (radii sum {reach} m, tolerance {OVERLAP_TOLERANCE} m)",
    )
    return gap


def _array(value: Any, shape: tuple[int, ...], what: str) -> np.ndarray:
    _expect(
        isinstance(value, np.ndarray),
        f"{what} must be a numpy array of shape {shape}, got {type(value).__name__}",
    )
    _expect(value.shape == shape, f"{what} must have shape {shape}, got shape {value.shape}")
    _expect(
        np.issubdtype(value.dtype, np.floating),
        f"{what} must hold floats, got dtype {value.dtype}",
    )
    _expect(bool(np.isfinite(value).all()), f"{what} must be finite, got {value.tolist()}")
    return value


def _pair(value: Any, what: str) -> tuple[Any, Any]:
    _expect(
        isinstance(value, tuple) and len(value) == 2,
        f"{what} must return a tuple of two arrays, got {type(value).__name__}"
        + (f" of length {len(value)}" if isinstance(value, (tuple, list)) else ""),
    )
    return value[0], value[1]


def _flag(value: Any, what: str) -> bool:
    _expect(
        isinstance(value, (bool, np.bool_)),
        f"{what} must return a bool, got {type(value).__name__} {value!r}",
    )
    return bool(value)
