"""Stable-Baselines3 adapters: the multi-robot env as a ``VecEnv``, and a metrics callback.

SuperSuit (3.11) does not fit ``MultiPointNav-v0``: its ``black_death_v3``, which
``pettingzoo_env_to_vec_env_v1`` needs as robots leave at different steps, ends a world
only when every robot is both terminated *and* truncated, so the vec env steps a world
whose robots all ended and the env raises ``TaskStateError``; the vec env's auto-reset puts
the reset infos over the final ones (a logged success rate is not the episodes'); and
``concat_vec_envs_v1`` cannot be seeded. :class:`MultiRobotVecEnv` does this directly.

Slots
-----
Each robot of each world is one slot of the ``VecEnv`` (world by world, robots in
``possible_agents`` order), so ``num_envs`` is the total number of robots and one policy
drives them all (parameter sharing). Every robot must have the same observation and
action space.

Robots that finish early
------------------------
The worlds' robots end their episodes at different steps, but a world can only be reset
as a whole. A robot's slot reports ``done=True`` once, on the step its episode ends, with
``info["terminal_observation"]`` (its final observation) and its final task info
(``success``, ``spl``, ``soft_spl``, ``collisions``, ...; ``"TimeLimit.truncated"`` is
True when it was cut by a time limit without a termination). After that, until its
world resets, the slot is *idle*: its action is ignored, its observation stays the final
one, its reward is 0.0, ``done`` is False and its info is ``{"idle": True}``. When every
robot of a world has finished, the world is reset at once (as SB3's own VecEnvs do) and
its slots show the new episode's first observations; the reset infos go to
``reset_infos``, never into the step infos. The idle steps are transitions the policy
learns little from (a frozen observation, no reward); they are the price of sharing one
reset between robots. With one robot per world there are none.

Observations: use ``flatten_obs=True`` worlds (the default of :func:`make_vec_env`) for
SB3's ``MlpPolicy``; ``Dict`` observations work with ``MultiInputPolicy``.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterable, Mapping, Sequence
from copy import deepcopy
from types import MappingProxyType
from typing import Any

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.vec_env import VecEnv
from stable_baselines3.common.vec_env.base_vec_env import (
    VecEnvIndices,
    VecEnvObs,
    VecEnvStepReturn,
)
from stable_baselines3.common.vec_env.util import dict_to_obs, obs_space_info

from pointnav_core.envs.multi_pointnav import MultiPointNavEnv
from pointnav_core.errors import ArgumentError, TaskStateError
from pointnav_core.integrations import METRIC_KEYS, episode_metrics

__all__ = ["MultiRobotVecEnv", "PointNavMetricsCallback", "make_vec_env"]

World = Any  # a MultiPointNavEnv, or a PettingZoo wrapper around one


class MultiRobotVecEnv(VecEnv):
    """An SB3 ``VecEnv`` with one slot per robot of one or more multi-robot worlds.

    See the module docstring for what a slot reports after its robot finished.

    Parameters
    ----------
    worlds : ParallelEnv, or a sequence of ParallelEnvs or of functions returning one
        The worlds (``MultiPointNavEnv`` or a PettingZoo ParallelEnv like it); each must
        be its own object.

    Raises
    ------
    ValueError
        If there is no world, a world appears twice, or the robots' observation or action
        spaces differ.

    Notes
    -----
    ``seed(s)`` seeds world ``w`` with ``s + w`` at the next ``reset()`` (and returns that
    seed for each of the world's slots); auto-resets after that draw from each world's own
    generator. ``get_attr``, ``set_attr``, ``env_method``, ``env_is_wrapped`` and ``options``
    act on a slot's *world*: ``env_method`` calls the method once per world named by the
    indices and gives that world's result for each of its slots.
    """

    def __init__(self, worlds: World | Sequence[World | Callable[[], World]]) -> None:
        if hasattr(worlds, "possible_agents"):
            worlds = [worlds]
        self.worlds: list[World] = [w() if callable(w) else w for w in worlds]
        if not self.worlds:
            raise ArgumentError("MultiRobotVecEnv needs at least one world")
        if len({id(w) for w in self.worlds}) != len(self.worlds):
            raise ArgumentError(
                "each world must be its own env object; pass functions that build a new one"
            )
        #: ``(world index, agent)`` of each slot.
        self.slots: list[tuple[int, str]] = [
            (w, agent) for w, world in enumerate(self.worlds) for agent in world.possible_agents
        ]
        self._world_slots = [
            [k for k, (w, _) in enumerate(self.slots) if w == i] for i in range(len(self.worlds))
        ]
        first_world, first_agent = self.worlds[0], self.worlds[0].possible_agents[0]
        obs_space = first_world.observation_space(first_agent)
        act_space = first_world.action_space(first_agent)
        for w, agent in self.slots:
            if self.worlds[w].observation_space(agent) != obs_space:
                raise ArgumentError(
                    f"every robot must have the same observation space: world {w}'s {agent} "
                    f"has {self.worlds[w].observation_space(agent)}, world 0's {first_agent} "
                    f"{obs_space}"
                )
            if self.worlds[w].action_space(agent) != act_space:
                raise ArgumentError(
                    f"every robot must have the same action space (the same drive): world {w}'s "
                    f"{agent} has {self.worlds[w].action_space(agent)}, world 0's {first_agent} "
                    f"{act_space}"
                )
        super().__init__(len(self.slots), obs_space, act_space)
        self._keys, shapes, dtypes = obs_space_info(obs_space)
        n = self.num_envs
        self._buf_obs = {k: np.zeros((n, *shapes[k]), dtype=dtypes[k]) for k in self._keys}
        self._actions: np.ndarray | None = None

    # ------------------------------------------------------------------ VecEnv API
    def seed(self, seed: int | None = None) -> Sequence[int | None]:
        """Seed world ``w`` with ``seed + w`` at the next ``reset()``; one seed per slot."""
        if seed is None:
            seed = int(np.random.randint(0, np.iinfo(np.uint32).max, dtype=np.uint32))
        self._seeds = [seed + w for w, _ in self.slots]
        return list(self._seeds)

    def reset(self) -> VecEnvObs:
        for w, world in enumerate(self.worlds):
            first = self._world_slots[w][0]
            options = self._options[first]
            self._reset_world(w, seed=self._seeds[first], options=options or None)
        self._reset_seeds()
        self._reset_options()
        return self._obs_from_buf()

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions)

    def step_wait(self) -> VecEnvStepReturn:
        actions = self._actions
        if actions is None:
            raise TaskStateError("step_wait() needs a step_async(actions) first")
        self._actions = None
        rewards = np.zeros(self.num_envs, dtype=np.float32)
        dones = np.zeros(self.num_envs, dtype=bool)
        infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        for w, world in enumerate(self.worlds):
            slots = self._world_slots[w]
            alive = set(world.agents)
            step_actions = {
                self.slots[k][1]: actions[k] for k in slots if self.slots[k][1] in alive
            }
            observations, step_rewards, terminations, truncations, step_infos = world.step(
                step_actions
            )
            for k in slots:
                agent = self.slots[k][1]
                if agent not in observations:  # finished on an earlier step: idle
                    infos[k] = {"idle": True}
                    continue
                obs = observations[agent]
                self._save_obs(k, obs)
                rewards[k] = step_rewards[agent]
                terminated, truncated = terminations[agent], truncations[agent]
                info = dict(step_infos[agent])
                info["TimeLimit.truncated"] = bool(truncated and not terminated)
                if terminated or truncated:
                    dones[k] = True
                    info["terminal_observation"] = obs
                infos[k] = info
            if not world.agents:
                self._reset_world(w)
        return self._obs_from_buf(), rewards, dones, infos

    def close(self) -> None:
        for world in self.worlds:
            world.close()

    def get_images(self) -> Sequence[np.ndarray | None]:
        """One image per world (``render_mode="rgb_array"`` worlds)."""
        return [world.render() for world in self.worlds]

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        """The attribute of each slot's world."""
        return [
            getattr(self.worlds[self.slots[k][0]], attr_name) for k in self._get_indices(indices)
        ]

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        """Set the attribute on each world named by the slots (once per world)."""
        for w in self._worlds_of(indices):
            setattr(self.worlds[w], attr_name, value)

    def env_method(
        self,
        method_name: str,
        *method_args: Any,
        indices: VecEnvIndices = None,
        **method_kwargs: Any,
    ) -> list[Any]:
        """Call the method once per world named by the slots; each slot gets its world's result."""
        slots = list(self._get_indices(indices))
        results = {
            w: getattr(self.worlds[w], method_name)(*method_args, **method_kwargs)
            for w in self._worlds_of(slots)
        }
        return [results[self.slots[k][0]] for k in slots]

    def env_is_wrapped(self, wrapper_class: type, indices: VecEnvIndices = None) -> list[bool]:
        """Whether each slot's world is (or is wrapped by) an instance of ``wrapper_class``."""
        return [
            _is_wrapped(self.worlds[self.slots[k][0]], wrapper_class)
            for k in self._get_indices(indices)
        ]

    # ------------------------------------------------------------------ helpers
    def _worlds_of(self, indices: VecEnvIndices | Iterable[int]) -> list[int]:
        slots = self._get_indices(indices)  # type: ignore[arg-type]
        return list(dict.fromkeys(self.slots[k][0] for k in slots))

    def _reset_world(
        self, w: int, seed: int | None = None, options: Mapping[str, Any] | None = None
    ) -> None:
        observations, infos = self.worlds[w].reset(seed=seed, options=options)
        for k in self._world_slots[w]:
            agent = self.slots[k][1]
            self._save_obs(k, observations[agent])
            self.reset_infos[k] = infos.get(agent, {})

    def _save_obs(self, k: int, obs: Any) -> None:
        for key in self._keys:
            self._buf_obs[key][k] = obs if key is None else obs[key]

    def _obs_from_buf(self) -> VecEnvObs:
        return dict_to_obs(self.observation_space, deepcopy(self._buf_obs))


def _is_wrapped(env: Any, wrapper_class: type) -> bool:
    while env is not None:
        if isinstance(env, wrapper_class):
            return True
        env = getattr(env, "env", None)
    return False


def make_vec_env(
    n_worlds: int = 1, seed: int | None = None, flatten_obs: bool = True, **env_kwargs: Any
) -> MultiRobotVecEnv:
    """A :class:`MultiRobotVecEnv` over ``n_worlds`` new ``MultiPointNavEnv(**env_kwargs)``.

    ``flatten_obs`` defaults to True here, so that SB3's ``MlpPolicy`` fits; ``seed`` seeds
    the first ``reset()`` (world ``w`` gets ``seed + w``).

    Examples
    --------
    >>> venv = make_vec_env(n_worlds=2, n_robots=3, seed=0)
    >>> venv.num_envs, venv.observation_space.shape, venv.reset().shape
    (6, (8,), (6, 8))
    """
    if isinstance(n_worlds, bool) or not isinstance(n_worlds, int) or n_worlds < 1:
        raise ArgumentError(f"n_worlds must be an integer >= 1, got {n_worlds!r}")
    venv = MultiRobotVecEnv(
        [MultiPointNavEnv(flatten_obs=flatten_obs, **env_kwargs) for _ in range(n_worlds)]
    )
    if seed is not None:
        venv.seed(seed)
    return venv


class PointNavMetricsCallback(BaseCallback):
    """Log success rate, SPL, SoftSPL and collisions of finished episodes to SB3's logger.

    Reads the infos of the steps where an episode ended (``dones``): the final task info
    that :class:`MultiRobotVecEnv` and SB3's own VecEnvs keep there. Each robot's episode
    counts once. Records the means over the last ``window`` episodes as
    ``pointnav/success_rate``, ``pointnav/spl``, ``pointnav/soft_spl`` and
    ``pointnav/collisions``, and the count of episodes seen as ``pointnav/episodes``;
    SB3 writes them with its other logs (``ep_rew_mean``, ...).

    Parameters
    ----------
    window : int
        Episodes the means are taken over (SB3's ``stats_window_size`` is 100 too).
    """

    #: Logger key of each metric.
    KEYS = MappingProxyType(
        {
            "success": "pointnav/success_rate",
            "spl": "pointnav/spl",
            "soft_spl": "pointnav/soft_spl",
            "collisions": "pointnav/collisions",
        }
    )

    def __init__(self, window: int = 100, verbose: int = 0) -> None:
        super().__init__(verbose)
        if isinstance(window, bool) or not isinstance(window, int) or window < 1:
            raise ArgumentError(f"window must be an integer >= 1, got {window!r}")
        self.window = window
        self.episodes = 0
        self._recent: dict[str, deque[float]] = {key: deque(maxlen=window) for key in METRIC_KEYS}

    def _on_step(self) -> bool:
        dones = self.locals.get("dones")
        infos = self.locals.get("infos")
        if dones is None or infos is None:
            return True
        ended = 0
        for done, info in zip(dones, infos):
            metrics = episode_metrics(info) if done else None
            if metrics is None:
                continue
            ended += 1
            for key, value in metrics.items():
                self._recent[key].append(value)
        if ended:
            self.episodes += ended
            self.record()
        return True

    def means(self) -> dict[str, float]:
        """The metrics' means over the last ``window`` episodes (empty before the first)."""
        return {key: float(np.mean(values)) for key, values in self._recent.items() if values}

    def summary(self) -> str:
        """One line on the recent episodes: their count and the metrics' means."""
        if not self.episodes:
            return "no episode has ended yet"
        means = self.means()
        return (
            f"last {min(self.episodes, self.window)} of {self.episodes} episodes: success rate "
            f"{means['success']:.2f}, SPL {means['spl']:.2f}, SoftSPL {means['soft_spl']:.2f}, "
            f"collisions {means['collisions']:.1f}"
        )

    def record(self) -> None:
        """Record the current means (and the episode count) in the logger."""
        for key, value in self.means().items():
            self.logger.record(self.KEYS[key], value)
        self.logger.record("pointnav/episodes", self.episodes)
