"""The robots and tasks of a multi-robot env, and how their goals are kept apart.

:class:`~pointnav_core.envs.multi_pointnav.MultiPointNavEnv` takes ``robot`` and ``task`` as one value
shared by all robots or a list with one entry per robot; :func:`make_robots` and
:func:`make_tasks` build them (every error names the entry, ``task[1]`` say).
:func:`goal_separation` is how far apart two robots' goals must be;
:func:`check_fixed_positions` refuses fixed starts and goals that break it at construction,
and :func:`goals_apart` is the goal constraint each reset hands to the sampler
(:mod:`~pointnav_core.task.sampling`), so sampled goals keep it too.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from pointnav_core import scenes
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.envs import common as _envcommon
from pointnav_core.errors import ArgumentError
from pointnav_core.task import PointNavigationTask
from pointnav_core.task.sampling import GoalConstraint

__all__ = [
    "FINISHED_MODES",
    "check_finished",
    "check_fixed_positions",
    "derived_path_ranges",
    "goal_separation",
    "goals_apart",
    "make_robots",
    "make_tasks",
    "per_robot",
    "prefixed",
]


#: What happens to a robot whose episode ended: stays as an obstacle, or leaves the world.
FINISHED_MODES = ("park", "remove")


def check_finished(finished: Any) -> str:
    """``finished`` if it is one of :data:`FINISHED_MODES`; else ValueError naming it."""
    if not isinstance(finished, str) or finished not in FINISHED_MODES:
        raise ArgumentError(f"finished must be one of {list(FINISHED_MODES)}, got {finished!r}")
    return finished


def prefixed(name: str, err: ValueError) -> ValueError:
    """``err`` as a ValueError whose message starts with ``name`` (added if missing)."""
    message = str(err)
    return ArgumentError(message if message.startswith(name) else f"{name}: {message}")


def per_robot(value: Any, n: int, name: str) -> list[Any] | None:
    """The list of per-robot entries when ``value`` is a list, else None (one shared value)."""
    if not isinstance(value, (list, tuple)):
        return None
    if len(value) != n:
        raise ArgumentError(
            f"{name} must be one value for all robots or a list with one entry per robot "
            f"(n_robots={n}), got a list of {len(value)}"
        )
    return list(value)


def make_robots(robot: Any, n: int) -> tuple[RobotSpec, ...]:
    """``n`` robot specs from one ``robot`` argument or a list of one per robot."""
    entries = per_robot(robot, n, "robot")
    if entries is None:
        return (_envcommon.make_robot(robot),) * n
    robots = []
    for i, entry in enumerate(entries):
        try:
            robots.append(_envcommon.make_robot(entry, name=f"robot[{i}]"))
        except ValueError as err:
            raise prefixed(f"robot[{i}]", err) from None
    return tuple(robots)


def make_tasks(task: Any, n: int) -> list[PointNavigationTask]:
    """``n`` distinct tasks (task ``i`` drives robot ``i``) from one ``task`` argument (a
    dict, copied per robot) or a list of one task or dict per robot."""
    entries = per_robot(task, n, "task")
    if entries is None:
        if isinstance(task, PointNavigationTask) and n > 1:
            raise ArgumentError(
                f"task is a single PointNavigationTask, which drives one robot; for "
                f"n_robots={n} pass a dict of its arguments (shared by all robots) or a list "
                f"of {n} tasks or dicts"
            )
        return [_envcommon.make_task(task, name="task", robot_idn=i) for i in range(n)]
    tasks = []
    for i, entry in enumerate(entries):
        try:
            tasks.append(_envcommon.make_task(entry, name=f"task[{i}]", robot_idn=i))
        except ValueError as err:
            raise prefixed(f"task[{i}]", err) from None
    if len({id(t) for t in tasks}) != n:
        raise ArgumentError("task must not hold the same PointNavigationTask twice")
    return tasks


def derived_path_ranges(task: Any, n: int) -> list[bool]:
    """For each robot, whether the env chooses its task's ``path_range``."""
    entries = per_robot(task, n, "task")
    if entries is None:
        return [_envcommon.derives_path_range(task)] * n
    return [_envcommon.derives_path_range(entry) for entry in entries]


def goal_separation(
    scene: scenes.Scene, tasks: Sequence[PointNavigationTask], robots: Sequence[RobotSpec]
) -> list[list[float]]:
    """Minimum distance (m) between the goals of robots i and j (on the same floor).

    ``max(tol_i + tol_j, r_i + r_j, cell)``: the success discs do not overlap, both robots
    fit on their goals, and even point robots with no tolerance get goals a cell apart.
    """
    cells = [float(scene.floors[t.floor].resolution) for t in tasks]
    return [
        [
            max(ti.goal_tolerance + tj.goal_tolerance, ri.radius + rj.radius, cell)
            for tj, rj in zip(tasks, robots)
        ]
        for ti, ri, cell in zip(tasks, robots, cells)
    ]


def check_fixed_positions(
    tasks: Sequence[PointNavigationTask],
    robots: Sequence[RobotSpec],
    separation: Sequence[Sequence[float]],
) -> None:
    """Refuse fixed starts closer than the two radii, and fixed goals closer than
    :func:`goal_separation`, naming both tasks."""
    for i, ti in enumerate(tasks):
        for j in range(i + 1, len(tasks)):
            tj = tasks[j]
            if ti.floor != tj.floor:
                continue
            si, sj = ti.initial_pos, tj.initial_pos
            if si is not None and sj is not None:
                gap = math.hypot(*(si[:2] - sj[:2]))
                need = robots[i].radius + robots[j].radius
                if gap < need:
                    raise ArgumentError(
                        f"task[{i}] and task[{j}] have fixed initial_pos {si[:2].tolist()} "
                        f"and {sj[:2].tolist()}, {gap:.3g} m apart: the robots would "
                        f"overlap (fixed starts must be at least the sum of the radii, "
                        f"{need:.3g} m, apart)"
                    )
            gi, gj = ti.goal_pos, tj.goal_pos
            if gi is not None and gj is not None:
                gap = math.hypot(*(gi[:2] - gj[:2]))
                need = separation[i][j]
                if gap < need:
                    raise ArgumentError(
                        f"task[{i}] and task[{j}] have fixed goal_pos {gi[:2].tolist()} and "
                        f"{gj[:2].tolist()}, {gap:.3g} m apart: goals must be distinct, at "
                        f"least max(sum of goal tolerances, sum of radii, one cell) = "
                        f"{need:.3g} m apart"
                    )


def goals_apart(
    tasks: Sequence[PointNavigationTask],
    i: int,
    placed: Sequence[int],
    separation: Sequence[Sequence[float]],
) -> GoalConstraint | None:
    """The goal constraint of task ``i``'s reset (:mod:`~pointnav_core.task.sampling`'s hook).

    It keeps the goal :func:`goal_separation` away from the goals decided so far: those
    of the robots in ``placed``, and the fixed goals of robots still to come (fixed goals
    were checked against each other at construction). None when there are none.
    """
    task = tasks[i]
    others = [
        j
        for j in range(len(tasks))
        if j != i
        and tasks[j].floor == task.floor
        and (j in placed or tasks[j].goal_pos is not None)
    ]
    if not others:
        return None
    apart_from = separation[i]

    def apart(gx: float, gy: float) -> str | None:
        for j in others:
            ox, oy = tasks[j].goal_xy  # type: ignore[misc]
            if math.hypot(gx - ox, gy - oy) < apart_from[j]:
                return (
                    f"the goal must be distinct from the other robots' goals, at least max(sum "
                    f"of goal tolerances, sum of radii, one cell) apart ({apart_from[j]:.3g} m "
                    f"from robot {j}'s); use fewer robots, a smaller goal_tolerance or a "
                    f"larger scene"
                )
        return None

    return apart
