"""Adapters for reinforcement-learning libraries (the ``rl`` extra).

- :mod:`pointnav_core.integrations.sb3`: Stable-Baselines3. ``MultiRobotVecEnv`` gives
  every robot of one or more ``MultiPointNav-v0`` worlds a slot of an SB3 ``VecEnv``, and
  ``PointNavMetricsCallback`` logs success rate, SPL and SoftSPL to SB3's logger.
- :mod:`pointnav_core.integrations.rllib`: RLlib (new API stack). ``PointNavMultiAgentEnv``
  is an RLlib ``MultiAgentEnv`` over ``MultiPointNav-v0``, ``PointNavMetricsCallbacks``
  reports the same metrics (and collisions) at episode end, and ``register_rllib_envs``
  makes ``config.environment("pointnav_core/MultiPointNav-v0")`` work in every worker.

This package imports neither library; each submodule imports its own. The helpers here
are what both share: which numbers of a robot's final ``info`` are its episode metrics.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

__all__ = ["METRIC_KEYS", "episode_metrics"]

#: The keys of a robot's final task ``info`` reported as episode metrics, in order.
METRIC_KEYS = ("success", "spl", "soft_spl", "collisions")


def episode_metrics(info: Mapping[str, Any]) -> dict[str, float] | None:
    """The episode metrics of a robot's final ``info`` as floats, or None if it has none.

    ``info`` is the task info of the step where the robot's episode ended (success is
    1.0 or 0.0). An info without these keys (one that is not a pointnav-core task info)
    gives None.

    Examples
    --------
    >>> episode_metrics({"success": True, "spl": 0.8, "soft_spl": 0.9, "collisions": 2})
    {'success': 1.0, 'spl': 0.8, 'soft_spl': 0.9, 'collisions': 2.0}
    >>> episode_metrics({"terminal_observation": None}) is None
    True
    """
    if not all(key in info for key in METRIC_KEYS):
        return None
    return {key: float(info[key]) for key in METRIC_KEYS}
