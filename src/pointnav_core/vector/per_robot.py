"""Per-robot ``robot`` and ``task`` lists for several robots per world in the batched engine.

``VectorPointNavEnv(n, n_robots=R, robot=[...], task=[...])`` takes, as
:func:`pointnav_core.envs.multi_pointnav.parallel_env` does, one value shared by all robots or a list
with one entry per robot. The numbers that may differ per robot become arrays with a
robot axis ``(1, R)`` that the step broadcasts over its ``(num_envs, R)`` state:

- from each task: ``goal_tolerance``, ``reward_type`` (geodesic or l2 potential),
  ``goal_in_polar``, ``termination_config`` (``max_steps``, ``max_collisions``,
  ``fall_height``) and ``reward_config`` (``r_potential``, ``r_collision``,
  ``r_pointgoal``, ``r_slack``); ``path_range``, ``initial_pos``, ``initial_quat`` and ``goal_pos``
  only shape the episodes, which each scene's multi-robot env draws;
- from each robot: ``max_linear_velocity`` and ``max_angular_velocity`` (the drive's
  scaling, the observations' bounds and, with discrete actions, each action's control
  steps) and ``radius`` (the fast path's clearance table of that radius, the contacts,
  with walls at the radius and with another robot at the sum of the two radii, and the
  disc the others' scans and local maps see).

What the engine cannot vary per robot is refused with a ``ValueError`` naming it: the
task's ``floor`` (the floor tables are built for one floor; see ``docs/decisions.md``) and
the robots' drives (the actions are one array, of one ``action_dim``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.envs.fleet import make_robots, per_robot
from pointnav_core.errors import ArgumentError
from pointnav_core.vector.drive import drive_of
from pointnav_core.vector.xp import Arrays

__all__ = ["envelope", "read_tasks", "robot_specs", "task_arguments"]

_CUSTOM_TERMS = ("termination_conditions", "reward_functions", "observation_terms")


def _one_task(entry: Any, name: str) -> dict[str, Any]:
    """A copy of one robot's task arguments; ValueError naming ``name`` if not a dict or custom."""
    if entry is not None and not isinstance(entry, Mapping):
        raise ArgumentError(f"{name} must be None or a dict of PointNavigationTask arguments, got {entry!r}")
    for key in _CUSTOM_TERMS:
        if entry is not None and entry.get(key) is not None:
            raise ArgumentError(f"{name}: {key} is not supported by the batched engine")
    return dict(entry or {})


def task_arguments(task: Any, n_robots: int, max_episode_steps: int | None) -> dict[str, Any] | list[dict[str, Any]]:
    """``task`` as one dict for every robot or a list of ``n_robots`` dicts (copies).

    ``max_episode_steps`` (already checked, or None) sets every task's ``max_steps``.

    Raises
    ------
    ValueError
        Naming ``task`` (a list of the wrong length, not a dict) or ``task[i]`` (an entry
        that is not None or a dict, or that has custom terms).
    """
    entries = per_robot(task, n_robots, "task")
    tasks: Any = _one_task(task, "task") if entries is None else [_one_task(e, f"task[{i}]") for i, e in enumerate(entries)]
    if max_episode_steps is not None:
        for t in tasks if isinstance(tasks, list) else [tasks]:
            t["termination_config"] = {**dict(t.get("termination_config") or {}), "max_steps": max_episode_steps}
    return tasks


def robot_specs(robot: Any, n_robots: int) -> tuple[RobotSpec, ...]:
    """One :class:`RobotSpec` per robot, all of one drive.

    Raises
    ------
    ValueError
        Naming ``robot`` (a list of the wrong length, drives that differ) or ``robot[i]``
        (an entry that is not a spec, dict or None).
    """
    specs = make_robots(robot, n_robots)
    drive_of(specs)  # one action array, of one action_dim, for every robot
    return specs


def envelope(specs: Sequence[RobotSpec]) -> RobotSpec:
    """The spec that bounds every robot's step: their largest radius and highest speed limits."""
    return dataclasses.replace(
        specs[0],
        radius=max(s.radius for s in specs),
        max_linear_velocity=max(s.max_linear_velocity for s in specs),
        max_angular_velocity=max(s.max_angular_velocity for s in specs),
    )


def read_tasks(env: Any, tasks: Sequence[Any], specs: Sequence[RobotSpec], arrays: Arrays) -> None:
    """Set the engine's per-robot settings from the robots' built ``tasks`` and ``specs``.

    The reward weights, tolerances, step and collision limits, fall height, speed limits
    (``vmax``: m/s, ``wmax``: rad/s) and radii (``radius``: m) become ``(1, R)`` arrays on
    the engine's device, public attributes that its step reads; ``goal_in_polar`` stays a bool when all
    robots agree, else it is a ``(1, R)`` mask. ValueError naming ``task`` if the robots'
    floors differ.
    """
    floors = sorted({t.floor for t in tasks})
    if len(floors) > 1:
        raise ArgumentError(f"task: every robot of a world must use the same floor in the batched engine, got floors {floors}")

    def row(values: Sequence[Any], dtype: Any = None) -> Any:
        return arrays.asarray(np.asarray(values, dtype=np.float64).reshape(1, -1), dtype)

    cfg = [t.termination_config for t in tasks]
    rcfg = [t.reward_config for t in tasks]
    env.max_steps = row([int(c["max_steps"]) for c in cfg], arrays.i64)
    env.max_collisions = row([int(c["max_collisions"]) for c in cfg], arrays.i64)
    env.fall_height = row([float(c["fall_height"]) for c in cfg])
    env.goal_tolerance = row([float(t.goal_tolerance) for t in tasks])
    env.r_potential, env.r_collision, env.r_pointgoal, env.r_slack = (
        row([float(c[k]) for c in rcfg]) for k in ("r_potential", "r_collision", "r_pointgoal", "r_slack")
    )
    env.slack = any("slack" in t.reward_functions for t in tasks)
    env.geodesic_reward = row([t.reward_type == "geodesic" for t in tasks], arrays.boolean)
    polar = [bool(t.goal_in_polar) for t in tasks]
    env.goal_in_polar = polar[0] if len(set(polar)) == 1 else row(polar, arrays.boolean)
    env.vmax = row([s.max_linear_velocity for s in specs])
    env.wmax = row([s.max_angular_velocity for s in specs])
    env.radius = row([s.radius for s in specs])
