"""Checks of what a backend returns, and of how robots are placed, taken out and reset."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pointnav_core.backends.protocol import FLOAT_TWINS, check_backend, float_twin
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.errors import BackendError
from pointnav_core.floor.maps import OBSTACLE, VOID
from pointnav_core.scenes import Scene
from pointnav_core.testing.conformance.common import (
    _IDENTITY,
    MOTION_TOLERANCE,
    POSE_TOLERANCE,
    BackendFactory,
    _array,
    _expect,
    _fail,
    _flag,
    _fmt,
    _loaded,
    _pair,
    _quat,
    _room,
    _xyz,
    _yaw,
)

__all__ = [
    "check_absent_robots",
    "check_fast_paths",
    "check_landing",
    "check_pose_round_trip",
    "check_protocol",
    "check_reset",
    "check_valid_pose",
]


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


def check_fast_paths(factory: BackendFactory) -> None:
    """Float twins the task reads give exactly the numbers of ``get_pose``/``get_velocity``.

    The twins ``get_pose_floats`` and ``get_velocity_floats`` are optional (see
    :data:`~pointnav_core.backends.protocol.FLOAT_TWINS`); a backend without them passes. Each twin
    that :func:`~pointnav_core.backends.protocol.float_twin` binds (the ones the task reads instead
    of their methods) must return a flat tuple of Python floats equal, value for value, to
    the arrays of the method it mirrors: after ``land`` and ``set_pose`` at random headings
    and after each of 60 steps of random actions (held 10 steps each) by three robots, in a
    room with a pillar and a hole: with contacts, a fall and an absent robot.
    """
    backend = factory()
    twins = {twin: float_twin(backend, twin) for twin in FLOAT_TWINS}
    twins = {twin: read for twin, read in twins.items() if read is not None}
    if not twins:
        return
    grid = np.zeros((30, 30), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[12:16, 14:17] = OBSTACLE
    grid[22:28, 3:27] = VOID
    specs = [RobotSpec(), RobotSpec(radius=0.3, drive="holonomic"), RobotSpec(radius=0.1)]
    backend.load(Scene.from_array(grid, 0.1), specs, action_frequency=10.0)
    rng = np.random.default_rng(0)

    def compare(when: str) -> None:
        for idn in range(len(specs)):
            for twin, read in twins.items():
                method = FLOAT_TWINS[twin]
                got = read(idn)
                want = tuple(float(v) for part in getattr(backend, method)(idn) for v in part)
                _expect(
                    isinstance(got, tuple) and all(type(v) is float for v in got),
                    f"{twin}({idn}) must return a tuple of Python floats, got {got!r}",
                )
                _expect(
                    len(got) == len(want),
                    f"{twin}({idn}) {when} returned {len(got)} numbers, but {method}({idn}) "
                    f"gives {len(want)}",
                )
                wrong = [k for k, (a, b) in enumerate(zip(got, want)) if a != b]
                _expect(
                    not wrong,
                    f"{twin}({idn}) {when} returned {got!r}, but {method}({idn}) gives "
                    f"{want!r} (they differ at entries {wrong}); a float twin must give "
                    "exactly the numbers of the method it mirrors",
                )

    for idn, xy in enumerate([(0.6, 0.6), (1.4, 0.7)]):
        backend.land(idn, 0, xy, _quat(rng.uniform(-4.0, 4.0)))
    backend.land(2, 0, (0.8, 1.9), _quat(math.pi / 2))  # facing the hole
    compare("after land")
    backend.set_pose(0, (0.7, 0.5, 0.0), _quat(rng.uniform(-4.0, 4.0)))
    compare("after set_pose")
    actions: dict[int, Any] = {}
    for step in range(60):
        if step % 10 == 0:  # held for 10 steps, mostly ahead: robots reach walls
            actions = {i: rng.uniform(-0.5, 1.5, spec.action_dim) for i, spec in enumerate(specs)}
            actions[2] = (1.0, 0.1)  # into the hole
        if step == 45:
            backend.set_present(1, False)
        backend.step(actions)
        compare(f"after step {step + 1}")
