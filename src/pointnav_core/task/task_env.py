"""What the task needs from the environment it runs in, and what it does with it each step.

:class:`TaskEnv` is the four members the task reads; :func:`check_fits` checks a task's
configuration against an environment when the task first meets it; and
:func:`evaluate_terminations` is the per-step pass over the termination conditions.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from pointnav_core.errors import ArgumentError

if TYPE_CHECKING:
    from pointnav_core.backends.protocol import Backend, RobotSpec
    from pointnav_core.scenes import Scene
    from pointnav_core.task.config import TaskConfig
    from pointnav_core.task.terminations import TerminationCondition

__all__ = ["TaskEnv", "check_fits", "evaluate_terminations"]


class TaskEnv(Protocol):
    """What the task needs from the environment it runs in.

    A ``PointNavEnv`` provides these, and so must any multi-robot environment.
    """

    @property
    def scene(self) -> Scene:
        """The floors, their sampling and geodesic queries."""
        ...

    @property
    def backend(self) -> Backend:
        """The world: poses, velocities, contacts of every robot."""
        ...

    @property
    def robots(self) -> Sequence[RobotSpec]:
        """One spec per robot; the index is ``robot_idn``."""
        ...

    @property
    def np_random(self) -> np.random.Generator:
        """The only source of randomness the task uses (seeded by the env's reset)."""
        ...


def check_fits(cfg: TaskConfig, env: TaskEnv) -> RobotSpec:
    """The spec of the task's robot, once ``cfg`` is checked against ``env``.

    Raises
    ------
    ValueError
        Naming ``robot_idn``, ``floor``, ``initial_pos`` or ``goal_pos``.
    """
    robots, scene = env.robots, env.scene
    idn, floor = cfg.robot_idn, cfg.floor
    if idn >= len(robots):
        raise ArgumentError(
            f"robot_idn must be in [0, {len(robots)}) for an environment with "
            f"{len(robots)} robot(s), got {idn}"
        )
    if floor >= scene.n_floors:
        raise ArgumentError(
            f"floor must be in [0, {scene.n_floors}) for a scene with {scene.n_floors} "
            f"floor(s), got {floor}"
        )
    spec = robots[idn]
    for name, xy in (("initial_pos", cfg.initial_pos), ("goal_pos", cfg.goal_pos)):
        if xy is not None and not scene.is_usable(floor, xy, spec):
            raise ArgumentError(
                f"{name} {list(xy)} is not usable on floor {floor} by robot "
                f"{idn} (radius {spec.radius} m): it is off the map, on an "
                f"obstacle or void, or closer than the radius to one"
            )
    return spec


def evaluate_terminations(
    items: tuple[tuple[str, TerminationCondition], ...],
    task: Any,
    env: TaskEnv,
    action: Any,
) -> tuple[dict[str, tuple[bool, bool]], dict[str, dict[str, bool]], bool, bool, bool, bool]:
    """Evaluate every termination condition in ``items``, none short-circuiting.

    Returns ``(results, conditions, done, success, terminated, truncated)``: each
    condition's ``(done, success)``, the same as ``info["termination_conditions"]``, and
    the step's flags.
    """
    results: dict[str, tuple[bool, bool]] = {}
    conditions: dict[str, dict[str, bool]] = {}
    done = success = terminated = truncated = False
    for name, condition in items:
        result = condition.step(task, env, action)
        results[name] = result
        is_done, is_success = result
        conditions[name] = {"done": is_done, "success": is_success}
        if is_done:
            done = True
            if is_success:
                success = True
            if condition.is_truncation:
                truncated = True
            else:
                terminated = True
    return results, conditions, done, success, terminated, truncated
