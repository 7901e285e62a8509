"""Reward functions of a point-navigation episode: small objects the task sums, in order.

Each reward function returns a Python ``float`` once per control step. The task evaluates
them *after* every termination condition, in the order below, and reports each term in
``info["reward_breakdown"]``; the step's reward is their sum.

=================  ===============  ==================================================
class              name             reward at a step
=================  ===============  ==================================================
PotentialReward    ``"potential"``  ``r_potential * (previous potential - potential)``
CollisionReward    ``"collision"``  ``-r_collision`` if the robot touched something
PointGoalReward    ``"pointgoal"``  ``r_pointgoal`` on the step PointGoal succeeds
SlackReward        ``"slack"``      ``-r_slack`` on every step (only when ``r_slack > 0``)
=================  ===============  ==================================================

``SlackReward`` is not OmniGibson's: it is Habitat's ``slack_reward``, a time cost that
makes a detour cost reward (the potential terms telescope, so on their own they pay a long
way and the shortest one alike). Its default ``r_slack = 0`` leaves the task OmniGibson's,
with the three terms above and no ``"slack"`` key.

The potential is the task's distance to the goal (L2 or geodesic, see
:class:`~pointnav_core.task.PointNavigationTask`), so the potential rewards of an episode
telescope: they sum to ``r_potential * (potential at reset - potential at the end)``.

What a reward function may read
-------------------------------
The task's per-step snapshot, refreshed before any reward runs: ``task.robot_idn``,
``task.potential`` (float, m: the potential this step), ``task.distance_to_goal`` (m,
geodesic), ``task.robot_xyz``, ``task.goal_xy``, ``task.in_contact``
(``env.backend.in_contact(task.robot_idn)`` for this step), ``task.episode_length``,
``task.collisions`` and ``task.termination_results`` (name -> ``(done, success)`` of this
step's termination conditions); and ``env.backend``. Subclass :class:`RewardFunction` to
write your own and pass it as ``reward_functions`` (``docs/extending.md``).

Examples
--------
>>> import types
>>> task = types.SimpleNamespace(potential=3.0)
>>> reward = PotentialReward(r_potential=2.0)
>>> reward.reset(task, env=None)
>>> task.potential = 2.5  # 0.5 m closer
>>> reward.step(task, env=None, action=None)
1.0
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, ClassVar

from pointnav_core.errors import ArgumentError
from pointnav_core.task.metrics import scalar_where
from pointnav_core.task.terminations import _check_length

__all__ = ["RewardFunction", "PotentialReward", "CollisionReward", "PointGoalReward", "SlackReward"]


def _check_scale(name: str, value: Any) -> float:
    return _check_length(name, value, unit="reward units")


class RewardFunction:
    """Base class: one term of the step reward.

    Subclasses implement :meth:`compute`, or override :meth:`step` whole (the built-in
    rewards do, to keep the per-step path short); ``step`` returns a Python float and
    records it in ``reward``.

    Attributes
    ----------
    name : str
        Key of the term in the task's ``reward_functions`` and in
        ``info["reward_breakdown"]``.
    reward : float
        The term's value at the last step (0.0 after :meth:`reset`).
    """

    name: ClassVar[str] = "reward"

    def __init__(self) -> None:
        self.reward = 0.0

    def reset(self, task: Any, env: Any) -> None:
        """Clear the per-episode state; called by the task after the terminations' reset."""
        self.reward = 0.0

    def compute(self, task: Any, env: Any, action: Any) -> float:
        """The term's value at this step (the backend has moved; terminations are known)."""
        raise NotImplementedError(f"{type(self).__name__} must implement compute() or step()")

    def step(self, task: Any, env: Any, action: Any) -> float:
        """Evaluate the term for this step, as a Python float."""
        reward = float(self.compute(task, env, action))
        self.reward = reward
        return reward

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class PotentialReward(RewardFunction):
    """Dense shaping reward: progress towards the goal since the last step.

    ``r_potential * (previous potential - current potential)``: positive when the robot got
    closer. The potential is read from ``task.potential`` (metres); the previous one is the
    value at the last step, or at reset on the first step.

    Parameters
    ----------
    r_potential : float
        Reward per metre of progress, >= 0.
    """

    name = "potential"

    def __init__(self, r_potential: float = 1.0) -> None:
        super().__init__()
        self.r_potential = _check_scale("r_potential", r_potential)
        self.previous_potential = 0.0

    def reset(self, task: Any, env: Any) -> None:
        super().reset(task, env)
        self.previous_potential = task.potential

    @staticmethod
    def value(r_potential: Any, previous: Any, current: Any) -> Any:
        """The reward of one robot's step or of a batch's (the batched engine calls it):
        ``r_potential * (previous - current)``, potentials in metres."""
        return r_potential * (previous - current)

    def step(self, task: Any, env: Any, action: Any) -> float:
        current = task.potential
        self.reward = reward = self.value(self.r_potential, self.previous_potential, current)
        self.previous_potential = current
        return reward

    def __repr__(self) -> str:
        return f"PotentialReward(r_potential={self.r_potential})"


class CollisionReward(RewardFunction):
    """Penalty for touching an obstacle or another robot.

    ``-r_collision`` on a step in which the robot touched something
    (``task.in_contact``, the task's reading of ``env.backend.in_contact(task.robot_idn)``),
    else 0.

    Parameters
    ----------
    r_collision : float
        Size of the penalty, >= 0.
    """

    name = "collision"

    def __init__(self, r_collision: float = 0.1) -> None:
        super().__init__()
        self.r_collision = _check_scale("r_collision", r_collision)

    @staticmethod
    def value(r_collision: Any, touched: Any, where: Callable[..., Any] = scalar_where, zero: Any = 0.0) -> Any:
        """The penalty of one step or a batch's: ``-r_collision`` where ``touched``, else
        ``zero`` (the batched engine passes its array library's ``where`` and a float64 zero
        array)."""
        return where(touched, -r_collision, zero)

    def step(self, task: Any, env: Any, action: Any) -> float:
        self.reward = reward = self.value(self.r_collision, task.in_contact)
        return reward

    def __repr__(self) -> str:
        return f"CollisionReward(r_collision={self.r_collision})"


class PointGoalReward(RewardFunction):
    """Sparse success reward, paid on the step the goal condition succeeds.

    ``r_pointgoal`` when this step's ``task.termination_results[condition]`` reports
    success, else 0. The task evaluates terminations before rewards, so this reads the
    current step's result.

    Parameters
    ----------
    r_pointgoal : float
        Success reward, >= 0.
    condition : str
        Name of the termination condition whose success is paid (default ``"pointgoal"``).

    Raises
    ------
    ValueError
        At reset, if the task has no termination condition of that name.
    """

    name = "pointgoal"

    def __init__(self, r_pointgoal: float = 10.0, condition: str = "pointgoal") -> None:
        super().__init__()
        self.r_pointgoal = _check_scale("r_pointgoal", r_pointgoal)
        if not isinstance(condition, str):
            raise ArgumentError(f"condition must be a termination condition name, got {condition!r}")
        self.condition = condition

    def reset(self, task: Any, env: Any) -> None:
        super().reset(task, env)
        names = list(task.termination_conditions)
        if self.condition not in names:
            raise ArgumentError(
                f"PointGoalReward pays the success of termination condition {self.condition!r}, "
                f"which the task does not have; its conditions are {names}"
            )

    @staticmethod
    def value(r_pointgoal: Any, success: Any, where: Callable[..., Any] = scalar_where, zero: Any = 0.0) -> Any:
        """The reward of one step or a batch's: ``r_pointgoal`` where ``success``, else
        ``zero`` (arguments as :meth:`CollisionReward.value`)."""
        return where(success, r_pointgoal, zero)

    def step(self, task: Any, env: Any, action: Any) -> float:
        self.reward = reward = self.value(self.r_pointgoal, task.termination_results[self.condition][1])
        return reward

    def __repr__(self) -> str:
        return f"PointGoalReward(r_pointgoal={self.r_pointgoal})"


class SlackReward(RewardFunction):
    """Time cost: ``-r_slack`` on every step, Habitat's ``slack_reward``.

    Not one of OmniGibson's terms: the task adds it after them only when ``r_slack > 0``.
    Habitat's PointNav pays ``-0.01`` a step beside a reward of 1 per metre of progress.

    Parameters
    ----------
    r_slack : float
        Cost of one step, >= 0 (reward units).
    """

    name = "slack"

    def __init__(self, r_slack: float = 0.0) -> None:
        super().__init__()
        self.r_slack = _check_scale("r_slack", r_slack)

    @staticmethod
    def value(r_slack: Any, zero: Any = 0.0) -> Any:
        """The cost of one step or a batch's: ``zero - r_slack`` (the batched engine passes a
        float64 zero array; ``r_slack`` may be a ``(1, R)`` row of the robots' costs)."""
        return zero - r_slack

    def step(self, task: Any, env: Any, action: Any) -> float:
        self.reward = reward = self.value(self.r_slack)
        return reward

    def __repr__(self) -> str:
        return f"SlackReward(r_slack={self.r_slack})"
