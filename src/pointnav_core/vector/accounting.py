"""The task's step on a batch of robots: ``PointNavigationTask.step``'s accounting as arrays.

One function for both batched engines: the one-robot engine's ``(num_envs,)`` robots and
the fleet's ``(num_envs, n_robots)`` robots, masked there by the robots still acting (an
ended robot's path, steps, collisions and rewards stay as they were). The reward terms and
the collision, timeout and fall conditions are the single task's own definitions
(``value`` of each term in ``rewards`` and ``terminations``), called on arrays, so the
rewards are the same floats. The goal condition keeps its own form here: the single task
measures the distance with ``math.hypot``, the engine with ``sqrt`` of the squares (the
same within an ulp).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

from pointnav_core.task.rewards import (
    CollisionReward,
    PointGoalReward,
    PotentialReward,
    SlackReward,
)
from pointnav_core.task.terminations import Falling, MaxCollision, Timeout
from pointnav_core.vector.state import Motion

__all__ = ["BatchedTask", "TaskStep", "custom_rewards", "read_task", "task_step"]

#: The built-in reward terms' names (the engine computes them itself, from their ``value``).
BUILT_IN_REWARDS = ("potential", "collision", "pointgoal", "slack")


class BatchedTask(NamedTuple):
    """What a custom reward term's ``batched(task)`` reads: the single task's per-step
    snapshot (``pointnav_core.task.rewards``) for every robot at once, as arrays of the robots'
    shape (numpy or torch, as the engine's ``device``)."""

    xp: Any  #: the array module (numpy, or torch)
    zero: Any  #: float64 zeros of the robots' shape (``torch.where`` of two numbers gives float32)
    robot_xyz: tuple[Any, Any, Any]  #: the robots' positions after the step (m)
    goal_xy: tuple[Any, Any]  #: the goals (m)
    distance_to_goal: Any  #: geodesic distance now (m; inf where none)
    potential: Any  #: the potential this step (m)
    in_contact: Any  #: touched something this step
    success: Any  #: the goal condition succeeded this step
    episode_length: Any  #: steps taken in the episode
    collisions: Any  #: steps with a contact so far


class TaskStep(NamedTuple):
    """What one step does to the task of every robot (arrays of the robots' shape)."""

    path: Any  #: path length so far (m)
    steps: Any  #: steps taken in the episode
    collisions: Any  #: steps with a contact
    dist: Any  #: geodesic distance to the goal (m; inf where the field has none)
    pot: Any  #: the potential the next step's reward starts from (m)
    success: Any  #: within the goal tolerance (and STOP called, with STOP)
    fell: Any  #: fell below the floor by more than ``fall_height``
    terminated: Any
    truncated: Any  #: ``max_steps`` reached (the fleet adds ``max_cycles``)
    r_pot: Any  #: the potential reward
    r_col: Any  #: the collision penalty
    r_goal: Any  #: the goal reward
    r_custom: dict[str, Any]  #: the slack term's (with ``r_slack > 0``) and each custom term's values, by name
    reward: Any  #: their sum, as the task adds them


def task_step(engine: Any, moved: Motion, contact: Any, stopped: Any, acting: Any = None,
              pedestrian: Any = None) -> TaskStep:
    """The task's step over the robots' moves from the engine's committed state.

    Parameters
    ----------
    engine : VectorPointNavEnv
        Its committed ``state`` (:class:`~.state.WorldState`), goal fields and task
        constants (floats, or ``(1, n_robots)`` arrays when the robots' tasks differ).
    moved : Motion
        The moved state (``x``, ``y``, ``z``: m).
    contact : bool array
        Robots that touched a wall or another robot this step.
    stopped : bool array or None
        Robots that called STOP (None without the STOP action).
    acting : bool array, optional
        The robots still acting (the fleet); None: every robot acts (the one-robot engine).
    pedestrian : bool array, optional
        The robots that touched a pedestrian this step (with a crowd): with the crowd's
        ``end_on_collision``, their episodes end (``PedestrianCollision``).

    Returns
    -------
    TaskStep
    """
    a, xp, st = engine.arrays, engine.arrays.xp, engine.state
    x0, y0 = st.x, st.y
    x, y, z = moved.x, moved.y, moved.z
    zero = xp.zeros_like(x)  # torch.where of two numbers would give float32
    moved_by = xp.sqrt((x - x0) ** 2 + (y - y0) ** 2)
    height = engine.floors.height[engine.world_scene]
    if acting is None:
        path = st.path_length + moved_by
        steps = st.steps + 1
        touched = contact
    else:
        path = st.path_length + xp.where(acting, moved_by, zero)
        steps = st.steps + a.to_int(acting)
        touched = contact & acting
        height = height[:, None]
    collisions = st.collisions + a.to_int(touched)
    # The task's terms, each the single task's own definition on arrays (rewards, terminations).
    dist = engine.pool.fields.distance(st.goal_field, x, y)
    gx, gy = st.goal_x, st.goal_y
    l2 = xp.sqrt((gx - x) ** 2 + (gy - y) ** 2)
    pot = xp.where(st.geodesic_metric, xp.where(dist < math.inf, dist, st.potential), l2)
    success = l2 < engine.goal_tolerance
    fell = Falling.value(z, height, engine.fall_height)
    truncated = Timeout.value(steps, engine.max_steps)
    if acting is not None:
        success, fell, truncated = acting & success, acting & fell, acting & truncated
    if stopped is not None:  # with STOP, success needs STOP within the tolerance (StopAtGoal)
        success = success & stopped
    terminated = MaxCollision.value(collisions, engine.max_collisions) | fell | success
    if stopped is not None:
        terminated = terminated | stopped
    if pedestrian is not None and engine.crowd.config.end_on_collision:  # PedestrianCollision
        terminated = terminated | pedestrian
    r_pot = PotentialReward.value(engine.r_potential, st.potential, pot)
    if acting is not None:
        terminated = acting & terminated
        r_pot = xp.where(acting, r_pot, zero)
    r_col = CollisionReward.value(engine.r_collision, touched, xp.where, zero)
    r_goal = PointGoalReward.value(engine.r_pointgoal, success, xp.where, zero)
    reward = ((0.0 + r_pot) + r_col) + r_goal
    r_custom: dict[str, Any] = {}
    if engine.slack:  # Habitat's time cost, after OmniGibson's terms as the task adds it
        slack = SlackReward.value(engine.r_slack, zero)
        r_custom["slack"] = slack = slack if acting is None else xp.where(acting, slack, zero)
        reward = reward + slack
    if engine.custom_rewards:  # after the built-in ones, in order, as the task sums them
        view = BatchedTask(xp, zero, (x, y, z), (gx, gy), dist, pot, touched, success, steps, collisions)
        for name, term in engine.custom_rewards:
            value = xp.zeros_like(x) + term.batched(view)  # float64 of the robots' shape
            r_custom[name] = value if acting is None else xp.where(acting, value, zero)
            reward = reward + r_custom[name]
    return TaskStep(path, steps, collisions, dist, pot, success, fell, terminated, truncated, r_pot, r_col, r_goal,
                    r_custom, reward)


def custom_rewards(task: Any) -> list[tuple[str, Any]]:
    """The task's reward terms other than the built-in ones, ``(name, term)`` in order; each
    has a ``batched(task)`` method (:func:`~pointnav_core.vector.arguments.task_arguments`
    refuses the others)."""
    return [(name, term) for name, term in task.reward_functions.items() if name not in BUILT_IN_REWARDS]


def read_task(engine: Any, t: Any, action_frequency: float) -> None:
    """Set on ``engine`` the task ``t``'s settings that the batched step reads (both
    engines). Any control rate: a step near something is cut into the backend's sub-steps
    (:func:`~pointnav_core.vector.drive.sub_steps`)."""
    engine.action_frequency = action_frequency
    engine.dt = 1.0 / action_frequency
    engine.task = t
    cfg, rcfg = t.termination_config, t.reward_config
    engine.max_steps, engine.max_collisions = int(cfg["max_steps"]), int(cfg["max_collisions"])
    engine.fall_height, engine.goal_tolerance = float(cfg["fall_height"]), t.goal_tolerance
    engine.r_potential, engine.r_collision, engine.r_pointgoal, engine.r_slack = (
        float(rcfg[k]) for k in ("r_potential", "r_collision", "r_pointgoal", "r_slack")
    )
    engine.slack = "slack" in t.reward_functions
    engine.geodesic_reward = t.reward_type == "geodesic"
    engine.custom_rewards = custom_rewards(t)
    engine.goal_in_polar = bool(t.goal_in_polar)
    spec = engine.robot
    engine.holonomic = spec.drive == "holonomic"
    # A chord is never longer than its arc (a holonomic one: the diagonal of its two
    # top speeds); the margin covers rounding.
    top = spec.max_linear_velocity * (math.sqrt(2.0) if engine.holonomic else 1.0)
    engine.max_travel = top * engine.dt * (1.0 + 1e-9) + 1e-12
