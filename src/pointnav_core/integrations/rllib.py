"""RLlib adapters (new API stack): the multi-robot env, a metrics callback, registration.

RLlib's own ``ParallelPettingZooEnv`` does not fit ``MultiPointNav-v0``: it calls
``render(self.render_mode)``; it says ``"__all__"`` only when every agent is terminated, or
every one truncated, on the same step, so an episode whose robots end some by termination
and some by truncation never ends for RLlib, which then calls ``step({})``; it keeps the
agent ids in a set, whose order (and so the seeded runs) differs between processes; and it
passes the ``Dict`` observations on, for which RLlib has no default encoder.

:class:`PointNavMultiAgentEnv` wraps the ParallelEnv instead:

- ``possible_agents`` and ``agents`` are lists in the env's order (``robot_0``, ...), and
  so are the keys of every returned dict;
- ``observation_spaces`` / ``action_spaces`` map each agent to its space; observations are
  the flat ``(8,)`` vectors by default (``flatten_obs=True``), which RLlib's default MLP
  encoder takes;
- ``step`` returns the ParallelEnv's per-agent results and ``"__all__"`` in both
  ``terminateds`` and ``truncateds``: False while any robot is alive; on the step the last
  robots finish, True in exactly one of the two, in ``truncateds`` if one of those robots
  was cut by a time limit (truncated and not terminated), else in ``terminateds``. A
  robot that finished earlier gets no more entries (RLlib sends it no more actions);
- ``render()`` takes no argument.

:class:`PointNavMetricsCallbacks` reports each robot's ``success``, ``spl``, ``soft_spl``
and ``collisions`` from its final info under ``env_runners/pointnav/...`` in the results.

Workers find the env ids only through RLlib's registry: call :func:`register_rllib_envs`
in the driver before building the algorithm (before or after ``ray.init``); Ray stores
the registration in the cluster and every worker imports this module to build the env.
Without it, ``config.environment("pointnav_core/PointNav-v0")`` reaches
``gymnasium.make`` in a worker that never imported ``pointnav_core`` and fails with
``NamespaceNotFound``; ``"pointnav_core:pointnav_core/PointNav-v0"`` also works there, as
it makes Gymnasium import the package.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

from ray.rllib.callbacks.callbacks import RLlibCallback
from ray.rllib.env.multi_agent_env import MultiAgentEnv
from ray.tune.registry import register_env

from pointnav_core.envs.multi_pointnav import MultiPointNavEnv
from pointnav_core.integrations import episode_metrics

__all__ = [
    "MULTI_ENV_ID",
    "SINGLE_ENV_ID",
    "PointNavMetricsCallbacks",
    "PointNavMultiAgentEnv",
    "init_local_ray",
    "make_multi_env",
    "make_single_env",
    "register_rllib_envs",
]

SINGLE_ENV_ID = "pointnav_core/PointNav-v0"
MULTI_ENV_ID = "pointnav_core/MultiPointNav-v0"


class PointNavMultiAgentEnv(MultiAgentEnv):
    """``MultiPointNav-v0`` as an RLlib ``MultiAgentEnv`` (see the module docstring).

    Parameters
    ----------
    config : dict, optional
        ``MultiPointNavEnv`` arguments (RLlib's ``env_config``); ``flatten_obs`` defaults
        to True. Ignored when ``env`` is given.
    env : MultiPointNavEnv, optional
        An env to wrap instead of building one.

    Examples
    --------
    >>> env = PointNavMultiAgentEnv({"n_robots": 2})
    >>> obs, infos = env.reset(seed=0)
    >>> env.agents, obs["robot_0"].shape
    (['robot_0', 'robot_1'], (8,))
    >>> actions = {agent: env.action_spaces[agent].sample() for agent in env.agents}
    >>> obs, rewards, terminateds, truncateds, infos = env.step(actions)
    >>> terminateds
    {'robot_0': False, 'robot_1': False, '__all__': False}
    """

    def __init__(
        self, config: Mapping[str, Any] | None = None, *, env: MultiPointNavEnv | None = None
    ) -> None:
        super().__init__()
        if env is None:
            env = MultiPointNavEnv(**{"flatten_obs": True, **dict(config or {})})
        self.par_env = env
        self.possible_agents = list(env.possible_agents)
        self.agents = list(env.agents)
        self.observation_spaces = {a: env.observation_space(a) for a in self.possible_agents}
        self.action_spaces = {a: env.action_space(a) for a in self.possible_agents}
        self.render_mode = env.render_mode
        self.metadata = env.metadata

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        """Start new episodes for every robot: ``(observations, infos)`` keyed by agent."""
        observations, infos = self.par_env.reset(seed=seed, options=options)
        self.agents = list(self.par_env.agents)
        return observations, infos

    def step(
        self, action_dict: Mapping[str, Any]
    ) -> tuple[dict[str, Any], dict[str, float], dict[str, bool], dict[str, bool], dict[str, Any]]:
        """One step of the alive robots; see the module docstring for ``"__all__"``."""
        observations, rewards, terminateds, truncateds, infos = self.par_env.step(action_dict)
        self.agents = list(self.par_env.agents)
        over = not self.agents
        cut = over and any(truncateds[a] and not terminateds[a] for a in truncateds)
        terminateds = {**terminateds, "__all__": over and not cut}
        truncateds = {**truncateds, "__all__": cut}
        return observations, rewards, terminateds, truncateds, infos

    def render(self) -> Any:
        """The ParallelEnv's ``render()``: an RGB image with ``render_mode="rgb_array"``."""
        return self.par_env.render()

    def close(self) -> None:
        self.par_env.close()


def make_multi_env(config: Mapping[str, Any] | None = None) -> PointNavMultiAgentEnv:
    """RLlib env creator of ``pointnav_core/MultiPointNav-v0`` (flat observations by default)."""
    return PointNavMultiAgentEnv(config)


def make_single_env(config: Mapping[str, Any] | None = None) -> Any:
    """RLlib env creator of ``pointnav_core/PointNav-v0`` (flat observations by default)."""
    from pointnav_core.envs.pointnav import PointNavEnv

    return PointNavEnv(**{"flatten_obs": True, **dict(config or {})})


def register_rllib_envs() -> tuple[str, str]:
    """Register both env ids with RLlib (``ray.tune.registry.register_env``); return them.

    Registered ids reach every worker of the cluster, which builds the envs with
    :func:`make_single_env` / :func:`make_multi_env` and ``env_config`` as arguments.
    """
    register_env(SINGLE_ENV_ID, make_single_env)
    register_env(MULTI_ENV_ID, make_multi_env)
    return SINGLE_ENV_ID, MULTI_ENV_ID


def init_local_ray(num_cpus: int | None = None, **kwargs: Any) -> Any:
    """Start a one-node Ray instance that listens on the loopback address only.

    For examples and tests on one machine. ``ray.init(_node_ip_address="127.0.0.1")`` alone
    does not do it on Linux: Ray swaps a loopback address for the machine's network address
    so that other nodes could join, unless ``RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER`` is "0"
    (its single-node mode). This sets that switch for this process and the ones Ray starts,
    then calls ``ray.init(address="local", include_dashboard=False,
    _node_ip_address="127.0.0.1", num_cpus=num_cpus, **kwargs)`` and returns its result.
    """
    import ray
    from ray._private import ray_constants

    os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"  # read by the processes Ray starts
    ray_constants.ENABLE_RAY_CLUSTER = False  # read at ray's import: set it for this process
    return ray.init(
        address="local",
        include_dashboard=False,
        _node_ip_address="127.0.0.1",
        num_cpus=num_cpus,
        **kwargs,
    )


class PointNavMetricsCallbacks(RLlibCallback):
    """Report each robot's success, SPL, SoftSPL and collisions when its episode ends.

    For every robot (or the single robot of ``PointNav-v0``) whose episode ended, logs the
    numbers of its final info with the env runner's ``MetricsLogger`` as means over the
    last ``WINDOW`` robot-episodes, under ``("pointnav", "success")``,
    ``("pointnav", "spl")``, ``("pointnav", "soft_spl")`` and
    ``("pointnav", "collisions")``: ``result["env_runners"]["pointnav"]["success"]`` is the
    success rate. A robot that finished before the others is read on the step it finished
    (its episode chunk may be gone by the episode's end).

    Use with ``config.callbacks(PointNavMetricsCallbacks)``.
    """

    WINDOW = 100
    _STASH = "pointnav_final_metrics"

    def on_episode_step(self, *, episode: Any, **kwargs: Any) -> None:
        _stash_finished(episode, self._STASH)

    def on_episode_end(self, *, episode: Any, metrics_logger: Any = None, **kwargs: Any) -> None:
        finished = _stash_finished(episode, self._STASH)
        if metrics_logger is None:
            return
        for metrics in finished.values():
            for key, value in metrics.items():
                metrics_logger.log_value(
                    ("pointnav", key), value, reduce="mean", window=self.WINDOW
                )


def _stash_finished(episode: Any, stash_key: str) -> dict[Any, dict[str, float]]:
    """Store the metrics of the episode's newly finished robots in its ``custom_data``.

    ``custom_data`` goes along when RLlib cuts an episode into chunks, so a robot is read
    once, on the step it finished. Returns all robots' metrics stored so far.
    """
    stash = episode.custom_data.setdefault(stash_key, {})
    agent_episodes = getattr(episode, "agent_episodes", None)
    if agent_episodes is None:  # a single-agent episode
        agent_episodes = {None: episode}
    for agent, agent_episode in agent_episodes.items():
        if agent in stash or not agent_episode.is_done:
            continue
        metrics = episode_metrics(agent_episode.get_infos(-1))
        if metrics is not None:
            stash[agent] = metrics
    return stash
