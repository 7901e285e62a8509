"""The agents of :class:`~pointnav_core.envs.multi_pointnav.MultiPointNavEnv`: their spaces, resets and steps.

Agent ``robot_<i>`` drives robot ``i``. :class:`AgentTable` holds each agent's action and
observation spaces (the same objects on every call) and the values the step loop reads
(:data:`~pointnav_core.envs._multi_actions.Slot`), and hands out dataset episodes given by
agent one per robot. :func:`reset_tasks` starts every robot's episode, goals kept apart
(:func:`~pointnav_core.envs.fleet.goals_apart`); :func:`step_tasks` runs the acting agents'
tasks once the robots have moved and gathers what ``step()`` returns.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from gymnasium import spaces

from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.envs import common as _envcommon
from pointnav_core.envs._multi_actions import Slot, Todo
from pointnav_core.envs.fleet import goals_apart
from pointnav_core.errors import ArgumentError
from pointnav_core.task import PointNavigationTask

__all__ = ["AgentTable", "StepReturns", "reset_tasks", "step_tasks"]

#: What ``step()`` returns: observations, rewards, terminations, truncations and infos,
#: each keyed by agent.
StepReturns = tuple[dict[str, Any], dict[str, float], dict[str, bool], dict[str, bool], dict[str, dict[str, Any]]]


class AgentTable:
    """Every agent's spaces and per-step values, one robot and one task each.

    Parameters
    ----------
    robots : sequence of RobotSpec
        One per robot.
    tasks : sequence of PointNavigationTask
        One per robot, loaded (their observation spaces follow their observation terms).
    discrete_actions : DiscreteActions or None
        The discrete action set, or None for continuous actions.
    flatten_obs : bool
        Flat observations (the task's ``get_low_dim_obs``) or the ``Dict`` (``get_obs``).
    frequency : float
        Control rate (Hz).
    """

    def __init__(
        self, robots: Sequence[RobotSpec], tasks: Sequence[PointNavigationTask], discrete_actions: Any,
        flatten_obs: bool, frequency: float,
    ) -> None:
        #: Agent names, in robot order.
        self.names = [f"robot_{i}" for i in range(len(tasks))]
        #: Agent -> robot index.
        self.index = {agent: i for i, agent in enumerate(self.names)}
        self.action_spaces = {
            agent: _envcommon.action_space(rb, discrete_actions) for agent, rb in zip(self.names, robots)
        }
        self.observation_spaces = {
            agent: _envcommon.observation_space(t, flatten_obs) for agent, t in zip(self.names, tasks)
        }
        #: Per robot, each discrete action's command and control steps (None: continuous).
        self.plans = None if discrete_actions is None else [discrete_actions.commands(rb, frequency) for rb in robots]
        #: Per robot, its task's observation function.
        self.observe = [t.get_low_dim_obs if flatten_obs else t.get_obs for t in tasks]
        # One lookup per agent and step: robot index, action shape, drive, the task's step
        # and its observation function.
        self.slots: dict[str, Slot] = {
            agent: (i, (rb.action_dim,), rb.drive, t.step, self.observe[i])
            for i, (agent, rb, t) in enumerate(zip(self.names, robots, tasks))
        }

    def observation_space(self, agent: str) -> spaces.Space[Any]:
        """The observation space of ``agent``; KeyError naming the agents for an unknown one."""
        try:
            return self.observation_spaces[agent]
        except KeyError:
            raise KeyError(f"unknown agent {agent!r}; possible agents are {self.names}") from None

    def action_space(self, agent: str) -> spaces.Space[Any]:
        """The action space of ``agent``; KeyError naming the agents for an unknown one."""
        try:
            return self.action_spaces[agent]
        except KeyError:
            raise KeyError(f"unknown agent {agent!r}; possible agents are {self.names}") from None

    def episodes(self, episodes: Any) -> list[Any]:
        """One dataset episode (or None) per robot, from ``reset``'s ``options["episodes"]``:
        None, a sequence in robot order, or a dict keyed by agent.

        Raises
        ------
        ValueError
            For an unknown agent, or a sequence without one episode per robot.
        """
        n = len(self.names)
        if episodes is None:
            return [None] * n
        if isinstance(episodes, Mapping):
            unknown = [a for a in episodes if a not in self.names]
            if unknown:
                raise ArgumentError(f"options['episodes'] has unknown agent {unknown[0]!r}; agents are {self.names}")
            return [episodes.get(agent) for agent in self.names]
        episodes = list(episodes)
        if len(episodes) != n:
            raise ArgumentError(f"options['episodes'] must hold one episode per robot ({n}), got {len(episodes)}")
        return episodes


def reset_tasks(
    env: Any, tasks: Sequence[PointNavigationTask], order: Sequence[int], separation: float, episodes: Sequence[Any]
) -> list[dict[str, Any]]:
    """Reset every robot's task, robot by robot in ``order``, each goal kept ``separation``
    (m) apart from the goals decided before it; ``episodes`` holds each robot's dataset
    episode or None. Returns the tasks' infos at step 0, in robot order."""
    infos: list[dict[str, Any]] = [{}] * len(tasks)
    placed: list[int] = []
    for i in order:
        constraint = goals_apart(tasks, i, placed, separation)
        infos[i] = tasks[i].reset(env, goal_constraint=constraint, episode=episodes[i])
        placed.append(i)
    return infos


def step_tasks(
    env: Any, todo: Sequence[Todo], contacts: dict[int, bool] | None, cut: bool
) -> tuple[StepReturns, list[str], list[int]]:
    """Step the task of every acting agent in ``todo`` (the robots have moved) and observe.

    Parameters
    ----------
    env : MultiPointNavEnv
        The env the tasks step in.
    todo : sequence of Todo
        The acting agents, in ``env.agents`` order.
    contacts : dict or None
        Robot index -> whether its discrete action ended at a contact; None for continuous
        actions.
    cut : bool
        Whether the env reached ``max_cycles``: every agent is truncated.

    Returns
    -------
    StepReturns
        ``step()``'s observations, rewards, terminations, truncations and infos.
    alive : list of str
        The agents whose episode goes on, in order.
    ended : list of int
        The robots whose episode ended, in order.
    """
    observations: dict[str, Any] = {}
    rewards: dict[str, float] = {}
    terminations: dict[str, bool] = {}
    truncations: dict[str, bool] = {}
    infos: dict[str, dict[str, Any]] = {}
    alive = []
    ended = []
    for agent, i, action, task_step, observe in todo:
        if contacts is None:
            reward, terminated, truncated, info = task_step(env, action)
        else:
            reward, terminated, truncated, info = task_step(env, action, contact=contacts[i])
        if cut:
            truncated = True
        observations[agent] = observe(env)
        rewards[agent] = reward
        terminations[agent] = terminated
        truncations[agent] = truncated
        infos[agent] = info
        if terminated or truncated:
            ended.append(i)
        else:
            alive.append(agent)
    return (observations, rewards, terminations, truncations, infos), alive, ended
