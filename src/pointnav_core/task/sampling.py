"""Episode sampling: a start and a goal that satisfy every constraint, or a clear error.

:func:`sample_episode` draws a start (in the fixed goal's connected region when the goal is
fixed), lands the robot there, draws a goal in the start's region, and accepts the pair
when, in this order:

1. the start is a valid pose for the backend (clear of obstacles and other robots);
2. the goal is a valid pose;
3. a sampled start or goal is at least ``goal_tolerance`` from the other (an episode is
   never won before it starts);
4. the caller's ``goal_constraint`` accepts the goal (a multi-robot env keeps goals
   apart this way);
5. the exact geodesic lies strictly inside ``path_range``.

A rejected pair counts against the constraint that rejected it; after ``max_trials``
rejections :class:`~pointnav_core.errors.SamplingError` names the constraint that failed
most, with every count. Fixed positions are taken as given (a fixed start that is not a
valid pose is a ``ValueError``), and a fixed pair is tried once. Randomness comes from
``env.np_random`` only.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from pointnav_core.errors import ArgumentError, SamplingError

__all__ = ["Episode", "GoalConstraint", "sample_episode", "sample_task_episode"]

_TWO_PI = 2.0 * math.pi

#: ``constraint(gx, gy)``: None to accept a goal (m), else what it must satisfy (for errors).
GoalConstraint = Callable[[float, float], "str | None"]


@dataclass(frozen=True)
class Episode:
    """A sampled episode: where the robot starts and where it must go.

    Attributes
    ----------
    start_xy : tuple of float
        Start (m); the robot stands there, landed by :func:`sample_episode`.
    start_quat : tuple of float
        Start orientation (x, y, z, w).
    goal_xy : tuple of float
        Goal (m).
    field : FloorGoalField
        The goal's geodesic field on the task's floor, for the robot.
    geodesic : float
        Exact geodesic distance (m) from the start to the goal (``inf`` if unreachable).
    """

    start_xy: tuple[float, float]
    start_quat: tuple[float, float, float, float]
    goal_xy: tuple[float, float]
    field: Any
    geodesic: float


def sample_episode(
    env: Any,
    *,
    robot_idn: int,
    floor: int,
    spec: Any,
    floor_height: float,
    initial_pos: tuple[float, float] | None,
    initial_quat: tuple[float, float, float, float] | None,
    goal_pos: tuple[float, float] | None,
    goal_tolerance: float,
    path_range: tuple[float, float] | None,
    max_trials: int,
    goal_constraint: GoalConstraint | None = None,
) -> Episode:
    """Sample (or take) a start and a goal for robot ``robot_idn``; see the module notes.

    Raises
    ------
    SamplingError
        No pair passed every constraint in ``max_trials`` trials.
    ValueError
        A fixed ``initial_pos`` is not a valid pose (an obstacle or another robot is there).
    """
    scene, backend, rng = env.scene, env.backend, env.np_random
    both_fixed = initial_pos is not None and goal_pos is not None
    if both_fixed:
        path_range = None
    fixed_field = None if goal_pos is None else scene.goal_field(floor, goal_pos, robot=spec)
    failures: dict[str, int] = {}
    # A geodesic is never shorter than the straight line, so a point farther than the
    # range's maximum can never pass: draw only among nearer ones (the accepted pairs
    # keep their distribution, and a short range no longer fails by rejection).
    reach = None if path_range is None or not math.isfinite(path_range[1]) else path_range[1]

    def fail(constraint: str) -> None:
        failures[constraint] = failures.get(constraint, 0) + 1

    for _ in range(1 if both_fixed else max_trials):
        sx, sy, quat = _start_pose(scene, rng, floor, spec, initial_pos, initial_quat, goal_pos, reach)
        # Land first: validity is checked on the robot's floor, and other robots that are
        # already placed (multi-robot resets place robots one by one) count.
        backend.land(robot_idn, floor, (sx, sy, floor_height), quat)
        if not backend.is_valid_pose(robot_idn, (sx, sy, floor_height), quat):
            if initial_pos is not None:
                raise ArgumentError(
                    f"initial_pos {[sx, sy]} is not a valid pose for robot {robot_idn}: its disc "
                    f"overlaps an obstacle or another robot"
                )
            fail("the start must be a valid pose (clear of obstacles and other robots)")
            continue
        if goal_pos is not None:
            gx, gy = goal_pos
        else:
            _, point = scene.get_random_point(
                floor=floor, reference_point=(sx, sy), robot=spec, rng=rng, max_distance=reach
            )
            gx, gy = float(point[0]), float(point[1])
            if not backend.is_valid_pose(robot_idn, (gx, gy, floor_height), quat):
                fail("the goal must be a valid pose (clear of obstacles and other robots)")
                continue
        if not both_fixed and math.hypot(gx - sx, gy - sy) < goal_tolerance:
            fail(f"the goal must be at least goal_tolerance ({goal_tolerance} m) from the start")
            continue
        if goal_constraint is not None and goal_pos is None and (broken := goal_constraint(gx, gy)) is not None:
            fail(broken)
            continue
        # A new goal costs only its graph solve here; the per-cell table is built on the
        # episode's first lookup, for the goal kept.
        field = fixed_field if fixed_field is not None else scene.goal_field(floor, (gx, gy), robot=spec)
        geodesic = field.exact_distance((sx, sy))
        if path_range is not None and not path_range[0] < geodesic < path_range[1]:
            fail(f"the geodesic must lie in path_range {path_range} m")
            continue
        return Episode((sx, sy), tuple(quat), (gx, gy), field, geodesic)  # type: ignore[arg-type]
    raise _exhausted(failures, robot_idn, floor, max_trials)


def _exhausted(failures: dict[str, int], robot_idn: int, floor: int, max_trials: int) -> SamplingError:
    """The error after ``max_trials`` rejections: the constraint that failed most, and every count."""
    worst = max(failures, key=failures.__getitem__)
    detail = "; ".join(f"{c}: failed {n} time(s)" for c, n in failures.items())
    return SamplingError(
        f"could not sample an episode for robot {robot_idn} on floor {floor} in {max_trials} "
        f"trials: {worst} ({detail})"
    )


def _start_pose(
    scene: Any,
    rng: Any,
    floor: int,
    spec: Any,
    initial_pos: tuple[float, float] | None,
    initial_quat: tuple[float, float, float, float] | None,
    goal_pos: tuple[float, float] | None,
    reach: float | None,
) -> tuple[float, float, tuple[float, float, float, float]]:
    """One trial's start ``(x, y)`` (m) and orientation ``(x, y, z, w)``: the fixed ones, or
    drawn (a start within ``reach`` m of a fixed goal, a uniform heading)."""
    if initial_pos is not None:
        sx, sy = initial_pos
    else:
        _, point = scene.get_random_point(
            floor=floor, reference_point=goal_pos, robot=spec, rng=rng,
            max_distance=None if goal_pos is None else reach,
        )
        sx, sy = float(point[0]), float(point[1])
    if initial_quat is not None:
        return sx, sy, initial_quat
    half = 0.5 * float(rng.uniform(0.0, _TWO_PI))
    return sx, sy, (0.0, 0.0, math.sin(half), math.cos(half))


def sample_task_episode(
    env: Any,
    config: Any,
    *,
    spec: Any,
    floor_height: float,
    max_trials: int,
    goal_constraint: GoalConstraint | None = None,
    given: Any = None,
) -> Episode:
    """:func:`sample_episode` with a task's :class:`~pointnav_core.task.config.TaskConfig`.

    A dataset episode ``given`` (:mod:`pointnav_core.datasets`) replaces the fixed or
    sampled start, start orientation and goal; it is checked first, and every error then
    names it.

    Raises
    ------
    SamplingError, ValueError
        As :func:`sample_episode`; a ``ValueError`` of a dataset episode names its id.
    """
    start, quat, goal = config.initial_pos, config.initial_quat, config.goal_pos
    if given is not None:
        from pointnav_core.datasets.playback import episode_poses

        start, quat, goal = episode_poses(given, env.scene, config.floor, spec, config.robot_idn)
    try:
        return sample_episode(
            env,
            robot_idn=config.robot_idn,
            floor=config.floor,
            spec=spec,
            floor_height=floor_height,
            initial_pos=start,
            initial_quat=quat,
            goal_pos=goal,
            goal_tolerance=config.goal_tolerance,
            path_range=config.path_range,
            max_trials=max_trials,
            goal_constraint=goal_constraint,
        )
    except ValueError as err:
        if given is None:
            raise
        raise ArgumentError(f"episode {given.episode_id!r}: field 'start_position': {err}") from None
