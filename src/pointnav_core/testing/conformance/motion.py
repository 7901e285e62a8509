"""Checks of how robots move: commands, velocities, contacts, tunnelling, falls, replay."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.floor.maps import OBSTACLE, VOID
from pointnav_core.scenes import Scene
from pointnav_core.testing.conformance.common import (
    _IDENTITY,
    MOTION_TOLERANCE,
    OVERLAP_TOLERANCE,
    BackendFactory,
    _expect,
    _expect_apart,
    _expect_clear_of_walls,
    _flag,
    _fmt,
    _loaded,
    _quat,
    _room,
    _xyz,
    _yaw,
)

__all__ = [
    "check_determinism",
    "check_falling",
    "check_no_tunnelling",
    "check_open_space_motion",
    "check_robot_contact",
    "check_velocity_matches_motion",
    "check_wall_contact",
]


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
