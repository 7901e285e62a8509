"""Behavioural checks that any backend must pass: the Backend protocol, as the task uses it.

Each check is a plain function that takes a *backend factory* (a callable returning a fresh,
unloaded backend), builds tiny scenes with :meth:`Scene.from_array`, drives robots and
raises :class:`AssertionError` with a readable message at the first thing that is wrong.
They are gathered in :data:`CHECKS`, in the order below, and run:

- from pytest, one test per check and backend (a failing check fails its test)::

      import pytest
      from pointnav_core.testing.conformance import CHECKS, backend_factory

      @pytest.mark.parametrize("check", CHECKS, ids=str)
      def test_my_backend_conforms(check):
          check(backend_factory("my_backend"))  # a name, a class or a factory

- from the command line, one line per check, exit status 0 when every check passes::

      python -m pointnav_core.testing my_backend

- from code: :func:`run_checks` returns one :class:`CheckResult` per check and
  :func:`assert_conforms` raises :class:`ConformanceError` listing the failures.

==========================  ===================================================================
Check                       What it asks of a backend
==========================  ===================================================================
``protocol``                every protocol member; right return types and shapes; fresh arrays;
                            bad actions are a ValueError and move nothing
``pose_round_trip``         ``set_pose`` then ``get_pose`` gives the pose back; ``land`` puts z
                            at the floor height
``open_space_motion``       in open space a robot moves as commanded (clipped to [-1, 1])
``velocity_matches_motion`` ``get_velocity`` is the displacement and yaw change over the step
``wall_contact``            driving into a wall sets the flag, never ends inside the wall, stops
                            at it; backing away is no contact
``robot_contact``           two robots driven into each other both get the flag and never
                            overlap; a robot hit while standing is flagged too
``no_tunnelling``           at full speed, nothing passes through a one-cell wall or a robot
``valid_pose``              ``is_valid_pose`` rejects overlap with an obstacle or a robot, and a
                            centre over VOID or off the map; touching is fine
``landing``                 ``land`` puts z at the chosen floor's height; floors do not collide
``falling``                 driving over VOID makes the robot fall (z drops, keeps dropping)
``absent_robots``           an absent robot is not moved and collides with nothing
``reset``                   ``reset`` zeroes velocities and flags; robots block nothing until
                            placed again
``determinism``             the same actions from the same state give the same result, also
                            after ``reset``
==========================  ===================================================================

Tolerances are stated with each check: a robot may end a step overlapping an obstacle or
another robot by at most :data:`OVERLAP_TOLERANCE` (1 mm), positions read back after
``set_pose`` agree to :data:`POSE_TOLERANCE`, and open-space motion to
:data:`MOTION_TOLERANCE`. Overlap with obstacles is measured by :func:`obstacle_distance`,
an exact reference that backend tests may use too.
"""

from __future__ import annotations

import importlib
import math
import time
import traceback
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from pointnav_core.backend import RobotSpec, check_backend, get_backend
from pointnav_core.errors import BackendError
from pointnav_core.maps import OBSTACLE, VOID, TraversableMap
from pointnav_core.scenes import Scene

__all__ = [
    "CHECKS",
    "MOTION_TOLERANCE",
    "OVERLAP_TOLERANCE",
    "POSE_TOLERANCE",
    "Check",
    "CheckResult",
    "ConformanceError",
    "assert_conforms",
    "backend_factory",
    "format_report",
    "get_check",
    "obstacle_distance",
    "run_checks",
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


# ----------------------------------------------------------------------- checks


def check_protocol(factory: BackendFactory) -> None:
    """Every protocol member exists; returns have the right types and shapes; bad actions raise.

    Arrays must be fresh float arrays (position (3,), quaternion (4,), velocities (3,));
    flags ``bool``; ``n_robots`` and ``get_robot_floor`` ``int``. A NaN or wrong-shaped
    action is a ValueError and moves no robot, not even those with good actions.
    """
    backend = factory()
    try:
        check_backend(backend)
    except BackendError as exc:
        _fail(str(exc))
    n0 = backend.n_robots
    _expect(
        isinstance(n0, (int, np.integer)) and not isinstance(n0, bool) and n0 == 0,
        f"n_robots must be the int 0 before load, got {n0!r}",
    )
    specs = [RobotSpec(), RobotSpec(drive="holonomic")]
    backend.load(_room(20), specs, action_frequency=10.0)
    n = backend.n_robots
    _expect(
        isinstance(n, (int, np.integer)) and not isinstance(n, bool) and n == 2,
        f"n_robots must be the int 2 after loading two robots, got {n!r}",
    )
    backend.land(0, 0, (0.5, 0.5), _IDENTITY)
    backend.land(1, 0, (1.5, 1.5), _quat(1.0))
    pos, quat = _pair(backend.get_pose(0), "get_pose(0)")
    _array(pos, (3,), "get_pose(0) position")
    _array(quat, (4,), "get_pose(0) orientation")
    lin, ang = _pair(backend.get_velocity(0), "get_velocity(0)")
    _array(lin, (3,), "get_velocity(0) linear velocity")
    _array(ang, (3,), "get_velocity(0) angular velocity")
    before = pos.copy()
    pos[:] = 99.0
    quat[:] = 0.0
    lin[:] = 99.0
    again, q_again = backend.get_pose(0)
    _expect(
        np.array_equal(again, before) and not np.array_equal(q_again, quat),
        "get_pose must return fresh arrays: writing into the returned arrays changed the "
        "robot's pose",
    )
    _expect(
        not np.array_equal(backend.get_velocity(0)[0], lin),
        "get_velocity must return fresh arrays: writing into the returned array changed it",
    )
    _flag(backend.in_contact(0), "in_contact(0)")
    _flag(backend.is_present(0), "is_present(0)")
    _flag(backend.is_valid_pose(0, (1.0, 1.0)), "is_valid_pose(0, (1.0, 1.0))")
    _flag(
        backend.is_valid_pose(0, (1.0, 1.0, 0.0), _IDENTITY, floor=0),
        "is_valid_pose(..., floor=0)",
    )
    floor = backend.get_robot_floor(0)
    _expect(
        isinstance(floor, (int, np.integer)) and not isinstance(floor, bool) and floor == 0,
        f"get_robot_floor(0) must be the int 0 after landing on floor 0, got {floor!r}",
    )
    start = [_xyz(backend, i) for i in range(2)]
    for actions, why in (
        ({0: [0.5, 0.0], 1: [math.nan, 0.0, 0.0]}, "a NaN action"),
        ({0: [0.5, 0.0, 0.0]}, "a 3-vector for a differential drive"),
        ({1: [0.5, 0.0]}, "a 2-vector for a holonomic drive"),
    ):
        try:
            backend.step(actions)
        except ValueError:
            pass
        else:
            _fail(f"step must raise ValueError for {why}, but it returned")
        for i in range(2):
            _expect(
                np.array_equal(_xyz(backend, i), start[i]),
                f"step raised for {why} but robot {i} moved from {_fmt(start[i])} to "
                f"{_fmt(_xyz(backend, i))}; a rejected step must move nothing",
            )
    backend.step({0: np.array([0.5, 0.0]), 1: (0.0, 0.5, 0.0)})
    _flag(backend.in_contact(0), "in_contact(0) after a step")


def check_pose_round_trip(factory: BackendFactory) -> None:
    """``set_pose`` then ``get_pose`` returns the same position and rotation (1e-9).

    The quaternion must be a unit, planar (x = y = 0) quaternion of the same rotation (q
    or -q); ``set_pose`` keeps the given z and leaves the robot at rest; ``land`` replaces
    z by the floor's height.
    """
    backend = _loaded(factory, _room(60), [RobotSpec()])
    for x, y, z, yaw in (
        (1.5, 2.5, 0.0, 0.0),
        (3.25, 1.125, 0.0, 2.0),
        (2.0, 4.0, 0.25, -2.9),
        (4.0, 4.0, 0.0, math.pi),
    ):
        backend.set_pose(0, (x, y, z), _quat(yaw))
        pos, q = backend.get_pose(0)
        _expect(
            np.allclose(pos, (x, y, z), rtol=0.0, atol=POSE_TOLERANCE),
            f"set_pose(0, {_fmt((x, y, z))}) then get_pose gave position {_fmt(pos)}",
        )
        q = np.asarray(q, dtype=np.float64)
        _expect(
            abs(np.linalg.norm(q) - 1.0) <= POSE_TOLERANCE
            and abs(q[0]) <= POSE_TOLERANCE
            and abs(q[1]) <= POSE_TOLERANCE,
            f"get_pose must return a unit planar quaternion (x = y = 0), got {_fmt(q)}",
        )
        agreement = abs(float(np.dot(q, _quat(yaw))))
        _expect(
            agreement >= 1.0 - POSE_TOLERANCE,
            f"set_pose with yaw {yaw:.6g} rad then get_pose gave quaternion {_fmt(q)} "
            f"(yaw {_yaw(q):.6g} rad)",
        )
        lin, ang = backend.get_velocity(0)
        _expect(
            not np.any(lin) and not np.any(ang),
            f"a robot is at rest after set_pose, but get_velocity gave {_fmt(lin)}, {_fmt(ang)}",
        )
    backend.land(0, 0, (2.0, 3.0, 99.0), _quat(1.0))
    pos, q = backend.get_pose(0)
    _expect(
        np.allclose(pos, (2.0, 3.0, 0.0), rtol=0.0, atol=POSE_TOLERANCE),
        f"land(0, 0, (2, 3, 99)) on a floor at height 0 gave position {_fmt(pos)}; "
        "x, y must be kept and z set to the floor height",
    )
    _expect(
        abs(_yaw(q) - 1.0) <= 1e-6, f"land with yaw 1 rad gave yaw {_yaw(q):.6g} rad"
    )


def check_open_space_motion(factory: BackendFactory) -> None:
    """In open space a robot moves exactly as commanded, actions clipped to [-1, 1].

    Straight motion, turning in place and holonomic side steps must match to 1e-6 m and
    rad; an arc (driving while turning) to 1e-3 m. Robots without an action stand still.
    """
    spec = RobotSpec(max_linear_velocity=1.0, max_angular_velocity=2.0)
    backend = _loaded(factory, _room(60), [spec, spec], freq=4.0)  # dt = 0.25 s
    yaw0 = 0.3
    backend.land(0, 0, (3.0, 3.0), _quat(yaw0))
    backend.land(1, 0, (1.0, 1.0), _IDENTITY)

    def one(
        action: Any, want_xy: tuple[float, float], want_yaw: float, tol: float, what: str
    ) -> None:
        backend.step({0: action})
        pos, q = backend.get_pose(0)
        _expect(
            np.allclose(pos[:2], want_xy, rtol=0.0, atol=tol),
            f"{what}: expected the robot at {_fmt(want_xy)}, it is at {_fmt(pos[:2])} "
            f"(tolerance {tol} m)",
        )
        _expect(
            abs(math.remainder(_yaw(q) - want_yaw, 2 * math.pi)) <= max(tol, MOTION_TOLERANCE),
            f"{what}: expected yaw {want_yaw:.6g} rad, got {_yaw(q):.6g} rad",
        )

    x, y = 3.0, 3.0
    x, y = x + 0.125 * math.cos(yaw0), y + 0.125 * math.sin(yaw0)
    one([0.5, 0.0], (x, y), yaw0, MOTION_TOLERANCE, "driving straight at 0.5 m/s for 0.25 s")
    yaw = yaw0 - 0.25
    one([0.0, -0.5], (x, y), yaw, MOTION_TOLERANCE, "turning in place at -1 rad/s for 0.25 s")
    x, y = x + 0.25 * math.cos(yaw), y + 0.25 * math.sin(yaw)
    one([5.0, 0.0], (x, y), yaw, MOTION_TOLERANCE, "action (5, 0), clipped to (1, 0)")
    v, w, dt = 0.5, 0.5, 0.25
    x2 = x + v / w * (math.sin(yaw + w * dt) - math.sin(yaw))
    y2 = y - v / w * (math.cos(yaw + w * dt) - math.cos(yaw))
    one([0.5, 0.25], (x2, y2), yaw + w * dt, 1e-3, "driving an arc (v = 0.5 m/s, w = 0.5 rad/s)")
    _expect(
        np.array_equal(_xyz(backend, 1), (1.0, 1.0, 0.0)),
        f"robot 1 had no action (a zero command) but moved to {_fmt(_xyz(backend, 1))}",
    )
    holo = RobotSpec(max_linear_velocity=1.0, drive="holonomic")
    backend = _loaded(factory, _room(60), [holo], freq=4.0)
    backend.land(0, 0, (3.0, 3.0), _quat(math.pi / 2))  # facing +y: its left is -x
    one([0.0, 1.0, 0.0], (2.75, 3.0), math.pi / 2, MOTION_TOLERANCE, "holonomic side step")


def check_velocity_matches_motion(factory: BackendFactory) -> None:
    """``get_velocity`` equals the step's displacement and yaw change over its duration.

    Checked to 1e-6 (m/s, rad/s) in open space, while turning and while sliding along a
    wall; angular velocity is about +z only; all zero after ``land``.
    """
    spec = RobotSpec(drive="holonomic")
    backend = _loaded(factory, _room(60), [spec])
    dt = 0.1
    backend.land(0, 0, (5.6, 3.0), _quat(0.2))  # 0.12 m from touching the x = 5.9 wall
    lin, ang = backend.get_velocity(0)
    _expect(
        not np.any(lin) and not np.any(ang),
        f"velocity after land must be zero, got {_fmt(lin)}, {_fmt(ang)}",
    )
    for action in (
        [1.0, 0.3, 0.5],
        [1.0, 1.0, -1.0],
        [1.0, 1.0, 0.0],
        [1.0, -0.5, 0.0],
        [-1.0, 0.0, 1.0],
        [0.0, 0.0, 0.0],
    ):
        before, q0 = backend.get_pose(0)
        backend.step({0: action})
        after, q1 = backend.get_pose(0)
        lin, ang = backend.get_velocity(0)
        want = (np.asarray(after) - np.asarray(before)) / dt
        _expect(
            np.allclose(lin, want, rtol=0.0, atol=MOTION_TOLERANCE),
            f"after action {action}: linear velocity {_fmt(lin)} m/s, but the robot moved "
            f"{_fmt(np.asarray(after) - np.asarray(before))} m in {dt} s ({_fmt(want)} m/s)",
        )
        dyaw = math.remainder(_yaw(q1) - _yaw(q0), 2 * math.pi) / dt
        _expect(
            np.allclose(ang, (0.0, 0.0, dyaw), rtol=0.0, atol=MOTION_TOLERANCE),
            f"after action {action}: angular velocity {_fmt(ang)} rad/s, but yaw changed at "
            f"{dyaw:.6g} rad/s",
        )


def check_wall_contact(factory: BackendFactory) -> None:
    """Driving into a wall sets the flag on the step it hits, never ends inside, stops at it.

    A robot (radius 0.18 m) 0.12 m from touching a wall drives at it at 0.05 m per step:
    no flag on steps 1-2, a flag on steps 3-5, never more than 1 mm inside the wall, and
    it ends within 1 mm of touching. Backing away from the wall is not a contact. Driving
    diagonally into a corner ends in the corner.
    """
    scene = _room(60)  # right wall: x in [5.9, 6.0)
    spec = RobotSpec()
    backend = _loaded(factory, scene, [spec])
    backend.land(0, 0, (5.6, 3.0), _IDENTITY)
    flags = []
    for step in range(1, 6):
        backend.step({0: [1.0, 0.0]})
        flags.append(_flag(backend.in_contact(0), "in_contact(0)"))
        _expect_clear_of_walls(backend, scene, [spec], [0], f"step {step}")
    _expect(
        flags == [False, False, True, True, True],
        f"contact flags over 5 steps towards a wall (touching during step 3) were {flags}, "
        "expected [False, False, True, True, True]",
    )
    x = _xyz(backend, 0)[0]
    _expect(
        5.72 - 1e-3 <= x,
        f"a robot driven into the wall stopped at x = {x:.6g} m, more than 1 mm short of "
        "touching it (x = 5.72 m)",
    )
    backend.step({0: [-1.0, 0.0]})
    _expect(
        not backend.in_contact(0),
        "backing away from a wall set the contact flag; only motion into something counts",
    )
    _expect(
        _xyz(backend, 0)[0] <= x - 0.04,
        f"backing away from the wall at 0.05 m per step moved the robot from x = {x:.6g} "
        f"to x = {_xyz(backend, 0)[0]:.6g} m",
    )
    backend.land(0, 0, (5.5, 5.5), _quat(math.pi / 4))
    for step in range(1, 21):
        backend.step({0: [1.0, 0.0]})
        _expect_clear_of_walls(backend, scene, [spec], [0], f"corner step {step}")
    pos = _xyz(backend, 0)
    _expect(
        backend.in_contact(0) and np.allclose(pos[:2], (5.72, 5.72), atol=1e-3),
        f"driving diagonally into a corner for 20 steps ended at {_fmt(pos[:2])} with "
        f"contact {backend.in_contact(0)}; expected (5.72, 5.72) and contact True",
    )


def check_robot_contact(factory: BackendFactory) -> None:
    """Two robots driven into each other both get the flag and never overlap (1 mm).

    Head on at 0.05 m per step each, 0.27 m apart: both flagged on the same step, never
    overlapping, and they end touching (within 1 cm). A robot that drives into a standing
    one flags both.
    """
    scene = _room(60)
    specs = [RobotSpec(), RobotSpec(radius=0.25)]
    backend = _loaded(factory, scene, specs)
    backend.land(0, 0, (2.0, 3.0), _IDENTITY)
    backend.land(1, 0, (2.7, 3.0), _quat(math.pi))
    both = False
    seen = [False, False]
    for step in range(1, 11):
        backend.step({0: [1.0, 0.0], 1: [1.0, 0.0]})
        gap = _expect_apart(backend, specs, 0, 1, f"step {step}")
        flags = [_flag(backend.in_contact(i), f"in_contact({i})") for i in range(2)]
        seen = [s or f for s, f in zip(seen, flags)]
        both = both or all(flags)
    _expect(
        both,
        f"two robots driven into each other for 10 steps were never both flagged on the "
        f"same step (robot 0 ever: {seen[0]}, robot 1 ever: {seen[1]})",
    )
    _expect(
        gap <= 0.43 + 0.01,
        f"two robots driven into each other for 10 steps ended {gap:.6g} m apart; they "
        "should have met (radii sum 0.43 m)",
    )
    backend = _loaded(factory, scene, [RobotSpec(), RobotSpec()])
    backend.land(0, 0, (2.0, 3.0), _IDENTITY)
    backend.land(1, 0, (2.4, 3.0), _IDENTITY)
    seen = [False, False]
    for step in range(1, 4):
        backend.step({0: [1.0, 0.0]})
        _expect_apart(backend, [RobotSpec(), RobotSpec()], 0, 1, f"step {step}")
        seen = [s or backend.in_contact(i) for i, s in enumerate(seen)]
    _expect(
        all(seen),
        f"a robot driven into a standing robot: flagged robot 0 {seen[0]}, robot 1 "
        f"{seen[1]}; both touched something",
    )


def check_no_tunnelling(factory: BackendFactory) -> None:
    """At full speed, no robot passes through a one-cell wall or through another robot.

    Robots of radius 0 and 0.05 m at 20 m/s (2 m, 20 cells, per step) aimed at a 0.1 m
    wall must stop on the near side with the flag set; two robots of radius 0.1 m closing
    at 10 m/s (1 m per step) must not pass through each other.
    """
    grid = np.zeros((5, 40), np.uint8)
    grid[:, 20] = OBSTACLE  # wall: x in [2.0, 2.1)
    scene = Scene.from_array(grid, 0.1)
    for radius in (0.0, 0.05):
        for drive, action in (("holonomic", [1.0, 0.01, 0.0]), ("differential", [1.0, 0.0])):
            spec = RobotSpec(radius=radius, max_linear_velocity=20.0, drive=drive)
            backend = _loaded(factory, scene, [spec])
            backend.land(0, 0, (1.0, 0.25), _IDENTITY)
            backend.step({0: action})
            x, y, _ = _xyz(backend, 0)
            what = f"a {drive} robot of radius {radius} m at 20 m/s"
            _expect(
                x <= 2.0 - radius + OVERLAP_TOLERANCE,
                f"{what} aimed at a one-cell wall (x in [2.0, 2.1)) ended at x = {x:.6g} m: "
                "it passed into or through the wall",
            )
            _expect(backend.in_contact(0), f"{what} hit a one-cell wall without the contact flag")
            _expect_clear_of_walls(backend, scene, [spec], [0], f"the step ({what})")
    open_floor = Scene.from_array(np.zeros((5, 40), np.uint8), 0.1)
    fast = RobotSpec(radius=0.1, max_linear_velocity=5.0)
    backend = _loaded(factory, open_floor, [fast, fast])
    backend.land(0, 0, (1.0, 0.25), _IDENTITY)
    backend.land(1, 0, (2.0, 0.25), _quat(math.pi))
    backend.step({0: [1.0, 0.0], 1: [1.0, 0.0]})
    x0, x1 = _xyz(backend, 0)[0], _xyz(backend, 1)[0]
    _expect(
        x0 < x1,
        f"two robots closing at 10 m/s passed through each other (x = {x0:.6g} and {x1:.6g} m)",
    )
    _expect_apart(backend, [fast, fast], 0, 1, "a head-on step at 5 m/s each")
    _expect(
        backend.in_contact(0) and backend.in_contact(1),
        "two robots met head on at 5 m/s without both contact flags",
    )


def check_valid_pose(factory: BackendFactory) -> None:
    """``is_valid_pose`` rejects overlap with obstacles and robots, VOID and off the map.

    Overlaps of 2 cm and more are rejected, a disc clear by 0.1 um is accepted (touching
    is allowed); only present, placed robots on that floor block; a disc overhanging VOID
    or the map's edge is rejected (SPEC 2: a robot stands where its disc misses both the
    blocked set and VOID); ``floor=`` picks the floor.
    """
    scene = _room(60)
    backend = _loaded(factory, scene, [RobotSpec(), RobotSpec(radius=0.1)])

    def valid(idn: int, xy: Any, want: bool, why: str, **kw: Any) -> None:
        got = _flag(backend.is_valid_pose(idn, xy, **kw), "is_valid_pose")
        _expect(
            got == want, f"is_valid_pose({idn}, {_fmt(xy)}) is {got} but should be {want}: {why}"
        )

    valid(0, (3.0, 3.0), True, "the middle of an empty room")
    valid(0, (5.72 - 1e-7, 3.0), True, "the disc touches the wall (clear by 0.1 um)")
    valid(0, (5.74, 3.0), False, "the disc overlaps the wall by 2 cm")
    valid(0, (5.95, 3.0), False, "the centre is inside the wall")
    valid(0, (5.8, 5.8), False, "the disc overlaps the corner walls")
    _expect(
        backend.is_valid_pose(0, (3.0, 3.0, 0.0), _IDENTITY),
        "is_valid_pose with an (x, y, z) position and an orientation rejected a free pose",
    )
    valid(0, (3.2, 3.0), True, "robot 1 is not placed yet, so it blocks nothing")
    backend.land(1, 0, (3.0, 3.0), _IDENTITY)
    valid(0, (3.2, 3.0), False, "the disc overlaps robot 1 (radius 0.1 m at (3, 3)) by 8 cm")
    valid(0, (3.3, 3.0), True, "the disc is 2 cm clear of robot 1")
    backend.set_present(1, False)
    valid(0, (3.2, 3.0), True, "robot 1 is absent (set_present(1, False))")
    backend.set_present(1, True)
    valid(0, (3.2, 3.0), False, "robot 1 is present again")
    grid = np.zeros((10, 10), np.uint8)
    grid[:, 7:] = VOID
    blocked = np.zeros((10, 10), np.uint8)
    blocked[4:6, 4:6] = OBSTACLE
    scene = Scene.from_array([grid, blocked], 0.1)
    backend = _loaded(factory, scene, [RobotSpec(radius=0.05)])
    valid(0, (0.5, 0.5), True, "free floor")
    valid(0, (0.64, 0.5), True, "the disc is 1 cm clear of the VOID cells")
    valid(0, (0.69, 0.5), False, "the centre is on the floor but the disc overhangs VOID")
    valid(0, (0.75, 0.5), False, "the centre is over VOID")
    valid(0, (-0.01, 0.5), False, "the centre is off the map")
    valid(0, (0.5, 1.2), False, "the centre is off the map")
    valid(0, (0.5, 0.5), False, "floor 1 has an obstacle there", floor=1)


def check_landing(factory: BackendFactory) -> None:
    """``land`` puts z at the chosen floor's height; robots on different floors never meet."""
    scene = _room(60, heights=(0.0, 2.5))
    specs = [RobotSpec(), RobotSpec()]
    backend = _loaded(factory, scene, specs)
    backend.land(0, 1, (3.0, 2.0, 99.0), _quat(1.0))
    pos = _xyz(backend, 0)
    _expect(
        np.allclose(pos, (3.0, 2.0, 2.5), rtol=0.0, atol=POSE_TOLERANCE),
        f"land(0, floor=1, (3, 2, 99)) on a floor at height 2.5 m gave {_fmt(pos)}",
    )
    _expect(
        backend.get_robot_floor(0) == 1,
        f"get_robot_floor(0) is {backend.get_robot_floor(0)} after landing on floor 1",
    )
    backend.step({0: [1.0, 0.0]})
    _expect(
        abs(_xyz(backend, 0)[2] - 2.5) <= POSE_TOLERANCE,
        f"a robot driving on floor 1 (height 2.5 m) is at z = {_xyz(backend, 0)[2]:.6g} m",
    )
    backend.land(0, 0, (2.0, 3.0), _IDENTITY)
    _expect(
        np.allclose(_xyz(backend, 0), (2.0, 3.0, 0.0), rtol=0.0, atol=POSE_TOLERANCE)
        and backend.get_robot_floor(0) == 0,
        f"landing back on floor 0 gave {_fmt(_xyz(backend, 0))} on floor "
        f"{backend.get_robot_floor(0)}",
    )
    backend.land(1, 1, (2.3, 3.0), _quat(math.pi))
    _expect(
        backend.is_valid_pose(0, (2.3, 3.0)),
        "a robot on floor 1 blocked is_valid_pose for a robot on floor 0",
    )
    for step in range(1, 6):
        backend.step({0: [1.0, 0.0], 1: [1.0, 0.0]})
        _expect(
            not backend.in_contact(0) and not backend.in_contact(1),
            f"robots on different floors collided on step {step}",
        )
    x0, x1 = _xyz(backend, 0)[0], _xyz(backend, 1)[0]
    _expect(
        abs(x0 - 2.25) <= MOTION_TOLERANCE and abs(x1 - 2.05) <= MOTION_TOLERANCE,
        f"robots on different floors should drive through each other's x, y: ended at "
        f"x = {x0:.6g} (want 2.25) and {x1:.6g} (want 2.05)",
    )


def check_falling(factory: BackendFactory) -> None:
    """Driving over VOID makes the robot fall: z below the floor by 3 cm within two steps.

    It then keeps falling (z strictly decreasing), VOID is no contact, the reported
    vertical velocity matches the drop, a robot landed over VOID falls on the next step,
    and ``land`` ends a fall.
    """
    grid = np.zeros((20, 40), np.uint8)
    grid[:, 25:] = VOID  # no floor for x >= 2.5
    scene = Scene.from_array(grid, 0.1, heights=[1.0])
    backend = _loaded(factory, scene, [RobotSpec()])
    backend.land(0, 0, (2.47, 1.0), _IDENTITY)
    for _ in range(2):
        backend.step({0: [1.0, 0.0]})
        _expect(
            not backend.in_contact(0),
            "driving over VOID set the contact flag; VOID is not an obstacle",
        )
    z = _xyz(backend, 0)[2]
    _expect(
        z < 1.0 - 0.03,
        f"a robot driven over VOID from a floor at 1 m is at z = {z:.6g} m after two steps; "
        "it should have fallen (z < 0.97 m)",
    )
    for step in range(1, 4):
        backend.step({0: [1.0, 0.0]})
        new = _xyz(backend, 0)[2]
        _expect(
            new < z, f"a falling robot stopped falling on step {step} (z {z:.6g} -> {new:.6g} m)"
        )
        vz = backend.get_velocity(0)[0][2]
        _expect(
            abs(vz - (new - z) / 0.1) <= MOTION_TOLERANCE,
            f"a falling robot dropped {z - new:.6g} m in 0.1 s but reports vz = {vz:.6g} m/s",
        )
        z = new
    backend.land(0, 0, (1.0, 1.0), _IDENTITY)
    backend.step({0: [1.0, 0.0]})
    pos = _xyz(backend, 0)
    _expect(
        np.allclose(pos, (1.05, 1.0, 1.0), rtol=0.0, atol=MOTION_TOLERANCE),
        f"after land ended a fall, one step at 0.5 m/s gave {_fmt(pos)}; expected (1.05, 1, 1)",
    )
    backend.land(0, 0, (2.6, 1.0), _IDENTITY)  # over the hole
    backend.step({})
    _expect(
        _xyz(backend, 0)[2] < 1.0,
        "a robot landed over VOID did not fall on the next step",
    )


def check_absent_robots(factory: BackendFactory) -> None:
    """An absent robot is not moved by ``step`` and collides with nothing; it can come back."""
    scene = _room(60)
    backend = _loaded(factory, scene, [RobotSpec(), RobotSpec()])
    backend.land(0, 0, (2.0, 3.0), _IDENTITY)
    backend.land(1, 0, (2.3, 3.0), _IDENTITY)
    backend.set_present(1, False)
    _expect(not backend.is_present(1), "is_present(1) is True after set_present(1, False)")
    for step in range(1, 7):
        backend.step({0: [1.0, 0.0], 1: [1.0, 0.0]})
        _expect(
            not backend.in_contact(0) and not backend.in_contact(1),
            f"a robot collided with an absent robot on step {step}",
        )
    _expect(
        np.array_equal(_xyz(backend, 1), (2.3, 3.0, 0.0)),
        f"an absent robot with an action moved to {_fmt(_xyz(backend, 1))}",
    )
    _expect(
        not np.any(backend.get_velocity(1)[0]),
        f"an absent robot reports velocity {_fmt(backend.get_velocity(1)[0])}",
    )
    _expect(
        abs(_xyz(backend, 0)[0] - 2.3) <= MOTION_TOLERANCE,
        "robot 0 should have driven through the absent robot to x = 2.3, got "
        f"{_xyz(backend, 0)[0]:.6g}",
    )
    backend.set_present(1, True)
    _expect(backend.is_present(1), "is_present(1) is False after set_present(1, True)")
    _expect(
        not backend.is_valid_pose(0, (2.0, 3.0)),
        "a robot brought back with set_present(1, True) does not block is_valid_pose",
    )


def check_reset(factory: BackendFactory) -> None:
    """``reset`` zeroes velocities and flags; robots block nothing and stay put until placed."""
    scene = _room(60)
    backend = _loaded(factory, scene, [RobotSpec(), RobotSpec()])
    backend.land(0, 0, (5.6, 3.0), _IDENTITY)
    backend.land(1, 0, (3.0, 3.0), _IDENTITY)
    for _ in range(4):
        backend.step({0: [1.0, 0.0]})
    _expect(backend.in_contact(0), "a robot driven into a wall for 4 steps is not flagged")
    backend.reset()
    lin, ang = backend.get_velocity(0)
    _expect(not backend.in_contact(0), "reset() did not clear the contact flag")
    _expect(not np.any(lin) and not np.any(ang), f"reset() left velocity {_fmt(lin)}, {_fmt(ang)}")
    _expect(
        backend.is_present(0) and backend.is_present(1), "reset() must leave every robot present"
    )
    _expect(
        backend.is_valid_pose(0, (3.0, 3.0)),
        "after reset() a robot that is not placed again (robot 1) still blocks is_valid_pose; "
        "robots block nothing until land or set_pose places them",
    )
    before = _xyz(backend, 0)
    backend.step({0: [1.0, 0.0]})
    _expect(
        np.array_equal(_xyz(backend, 0), before),
        "after reset() a robot that is not placed again moved on step()",
    )


def check_determinism(factory: BackendFactory) -> None:
    """The same actions from the same state give bit-identical poses, velocities and flags.

    Three robots driving random actions (clipped) for 40 steps in a small room with a
    pillar: two fresh backends must agree exactly, and so must the first one replaying
    after ``reset`` and landing the robots again.
    """
    grid = np.zeros((30, 30), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[12:16, 14:17] = OBSTACLE
    scene = Scene.from_array(grid, 0.1)
    specs = [RobotSpec(), RobotSpec(radius=0.3, drive="holonomic"), RobotSpec(radius=0.1)]
    rng = np.random.default_rng(0)
    actions = [
        {i: rng.uniform(-1.5, 1.5, size=spec.action_dim) for i, spec in enumerate(specs)}
        for _ in range(40)
    ]
    starts = [(0.6, 0.6), (1.4, 0.7), (0.8, 2.2)]

    def run(backend: Any) -> list[tuple[Any, ...]]:
        for idn, xy in enumerate(starts):
            backend.land(idn, 0, xy, _quat(idn))
        trace = []
        for step in actions:
            backend.step(step)
            for i in range(len(specs)):
                pos, q = backend.get_pose(i)
                lin, ang = backend.get_velocity(i)
                trace.append(
                    (np.asarray(pos).tolist(), np.asarray(q).tolist(), np.asarray(lin).tolist(),
                     np.asarray(ang).tolist(), bool(backend.in_contact(i)))
                )
        return trace

    def first_difference(a: list[Any], b: list[Any]) -> str:
        for k, (x, y) in enumerate(zip(a, b)):
            if x != y:
                return f"step {k // len(specs) + 1}, robot {k % len(specs)}: {x} != {y}"
        return "traces of different lengths"

    backend = _loaded(factory, scene, specs)
    first = run(backend)
    second = run(_loaded(factory, scene, specs))
    _expect(
        first == second,
        "two fresh backends given the same actions diverged at "
        + first_difference(first, second),
    )
    backend.reset()
    third = run(backend)
    _expect(
        first == third,
        "replaying the same actions after reset() diverged at " + first_difference(first, third),
    )


# ----------------------------------------------------------------------- registry


@dataclass(frozen=True)
class Check:
    """One named conformance check.

    Parameters
    ----------
    name : str
        Short identifier, e.g. ``"wall_contact"``.
    func : callable
        ``func(factory)``: runs the check on backends made by ``factory()``; raises
        :class:`AssertionError` with a readable message when the backend fails it.

    Examples
    --------
    >>> check = get_check("pose_round_trip")
    >>> str(check)
    'pose_round_trip'
    >>> check.summary  # the first line of its docstring
    '``set_pose`` then ``get_pose`` returns the same position and rotation (1e-9).'
    >>> check(backend_factory("kinematic"))  # passes: returns None
    """

    name: str
    func: Callable[[BackendFactory], None]

    @property
    def summary(self) -> str:
        """The first line of the check's docstring."""
        return (self.func.__doc__ or self.name).strip().splitlines()[0]

    def __call__(self, factory: BackendFactory) -> None:
        self.func(factory)

    def __str__(self) -> str:
        return self.name


#: Every check, in the order they run.
CHECKS: tuple[Check, ...] = tuple(
    Check(name, func)
    for name, func in (
        ("protocol", check_protocol),
        ("pose_round_trip", check_pose_round_trip),
        ("open_space_motion", check_open_space_motion),
        ("velocity_matches_motion", check_velocity_matches_motion),
        ("wall_contact", check_wall_contact),
        ("robot_contact", check_robot_contact),
        ("no_tunnelling", check_no_tunnelling),
        ("valid_pose", check_valid_pose),
        ("landing", check_landing),
        ("falling", check_falling),
        ("absent_robots", check_absent_robots),
        ("reset", check_reset),
        ("determinism", check_determinism),
    )
)


def get_check(name: str) -> Check:
    """Return the check called ``name``.

    Raises
    ------
    ValueError
        If there is no such check; the message lists the valid names.

    Examples
    --------
    >>> get_check("falling").name
    'falling'
    >>> get_check("flying")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: check must be one of ['protocol', ..., 'determinism'], got 'flying'
    """
    for check in CHECKS:
        if check.name == name:
            return check
    raise ValueError(f"check must be one of {[c.name for c in CHECKS]}, got {name!r}")


def backend_factory(backend: str | type | Callable[[], Any]) -> BackendFactory:
    """Turn a backend name, class or factory into a factory of fresh backends.

    Parameters
    ----------
    backend : str or type or callable
        A registered name (see :func:`~pointnav_core.backend.available_backends`), a
        ``"package.module:Class"`` path, a backend class (built with no arguments), or a
        callable returning a fresh, unloaded backend each time it is called.

    Returns
    -------
    callable
        ``factory()`` returns a new backend.

    Raises
    ------
    UnknownBackendError
        For a name that is not registered (a ValueError; the message lists the names).
    TypeError
        For anything else.

    Examples
    --------
    >>> factory = backend_factory("kinematic")
    >>> type(factory()).__name__
    'KinematicBackend'
    >>> factory() is factory()
    False
    """
    if isinstance(backend, str):
        if ":" in backend:
            module, _, attr = backend.partition(":")
            target = importlib.import_module(module)
            for part in attr.split("."):
                target = getattr(target, part)
            return backend_factory(target)
        cls = get_backend(backend)
        return cls
    if callable(backend):
        return backend
    raise TypeError(
        "backend must be a backend name, a class or a factory callable, got "
        f"{type(backend).__name__}"
    )


@dataclass(frozen=True)
class CheckResult:
    """The outcome of one check on one backend.

    Attributes
    ----------
    name : str
        The check's name.
    passed : bool
        Whether the backend passed.
    message : str
        Empty when passed; otherwise why it failed (an unexpected exception is reported
        with its type and where it was raised).
    seconds : float
        How long the check ran, in seconds.
    """

    name: str
    passed: bool
    message: str
    seconds: float


def _describe(exc: BaseException) -> str:
    if isinstance(exc, AssertionError):
        return str(exc) or "assertion failed"
    # Point at the innermost frame outside numpy: the backend's or the check's own line.
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if "/numpy/" not in f.filename]
    if not frames:
        return f"raised {type(exc).__name__}: {exc}"
    last = frames[-1]
    where = f" (at {last.filename}:{last.lineno} in {last.name})"
    return f"raised {type(exc).__name__}: {exc}{where}"


def run_checks(
    backend: str | type | Callable[[], Any], checks: Iterable[Check | str] | None = None
) -> list[CheckResult]:
    """Run conformance checks on a backend and return one result per check.

    Parameters
    ----------
    backend : str or type or callable
        See :func:`backend_factory`.
    checks : iterable of Check or str, optional
        Which checks to run (default: all of :data:`CHECKS`, in order).

    Returns
    -------
    list of CheckResult

    Examples
    --------
    >>> results = run_checks("kinematic", ["protocol", "falling"])
    >>> [(r.name, r.passed) for r in results]
    [('protocol', True), ('falling', True)]
    """
    factory = backend_factory(backend)
    chosen = CHECKS if checks is None else checks
    selected = [get_check(c) if isinstance(c, str) else c for c in chosen]
    results = []
    for check in selected:
        start = time.perf_counter()
        try:
            check(factory)
        except Exception as exc:  # a check fails on any error, and the run goes on
            seconds = time.perf_counter() - start
            results.append(CheckResult(check.name, False, _describe(exc), seconds))
        else:
            results.append(CheckResult(check.name, True, "", time.perf_counter() - start))
    return results


def format_report(results: Sequence[CheckResult], title: str = "") -> str:
    """Render results as text: an optional title, one line per check, then a summary.

    Examples
    --------
    >>> print(format_report([CheckResult("falling", False, "it floats", 0.01),
    ...                      CheckResult("reset", True, "", 0.002)]))
    FAIL  falling  it floats
    PASS  reset
    2 checks: 1 passed, 1 failed
    """
    width = max((len(r.name) for r in results), default=0)
    lines = [title] if title else []
    for r in results:
        status = "PASS" if r.passed else "FAIL"
        line = f"{status}  {r.name:<{width}}"
        lines.append(f"{line}  {r.message}" if r.message else line.rstrip())
    failed = sum(not r.passed for r in results)
    lines.append(f"{len(results)} checks: {len(results) - failed} passed, {failed} failed")
    return "\n".join(lines)


def assert_conforms(
    backend: str | type | Callable[[], Any], checks: Iterable[Check | str] | None = None
) -> None:
    """Raise :class:`ConformanceError` unless the backend passes every check.

    Parameters
    ----------
    backend : str or type or callable
        See :func:`backend_factory`.
    checks : iterable of Check or str, optional
        Which checks to run (default: all).

    Raises
    ------
    ConformanceError
        (a BackendError and an AssertionError) whose message lists each failed check and
        why.

    Examples
    --------
    >>> assert_conforms("kinematic", ["protocol", "valid_pose"])
    """
    results = run_checks(backend, checks)
    failed = [r for r in results if not r.passed]
    if failed:
        name = getattr(backend, "__name__", None) or str(backend)
        raise ConformanceError(
            f"backend {name} failed {len(failed)} of {len(results)} conformance checks:\n"
            + "\n".join(f"  {r.name}: {r.message}" for r in failed)
        )
