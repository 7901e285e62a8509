"""Registration of the pointnav-core environments with Gymnasium and PettingZoo.

Neither library discovers plugins (Gymnasium 1.x removed the ``gymnasium.envs`` entry-point
group of gym 0.2x; PettingZoo 1.27's registry is filled only by ``pettingzoo.register``
calls), so the ids exist once :func:`register_envs` has run. Importing ``pointnav_core``
runs it. ``gymnasium.make("pointnav_core:pointnav_core/PointNav-v0")`` imports the package
by itself; PettingZoo's ``make`` has no such ``module:`` prefix, so import ``pointnav_core``
before ``pettingzoo.make("parallel", "pointnav_core/MultiPointNav-v0")``.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

import gymnasium
import pettingzoo

__all__ = ["ENV_IDS", "PARALLEL_ENV_IDS", "AEC_ENV_IDS", "register_envs"]

#: The Gymnasium (single-robot) ids, each with its lazy ``"module:Class"`` entry point.
ENV_IDS: Mapping[str, str] = MappingProxyType(
    {"pointnav_core/PointNav-v0": "pointnav_core.env:PointNavEnv"}
)

#: The PettingZoo parallel (multi-robot) ids, each with its lazy ``"module:function"``.
PARALLEL_ENV_IDS: Mapping[str, str] = MappingProxyType(
    {"pointnav_core/MultiPointNav-v0": "pointnav_core.parallel:parallel_env"}
)

#: The same multi-robot envs in PettingZoo's AEC form (``parallel_to_aec`` of the above).
AEC_ENV_IDS: Mapping[str, str] = MappingProxyType(
    {"pointnav_core/MultiPointNav-v0": "pointnav_core.parallel:env"}
)


def register_envs() -> None:
    """Register every pointnav-core env with Gymnasium and PettingZoo; ids already
    registered are kept.

    Gymnasium: ``max_episode_steps`` is None, since the task's ``timeout`` condition owns
    truncation, so no ``TimeLimit`` wrapper is added. PettingZoo: the multi-robot env is
    registered in both the ``"parallel"`` and the ``"aec"`` registry with no registry
    ``max_cycles``, so the env's own default (500) applies unless ``make`` is given one.

    Examples
    --------
    >>> register_envs(); register_envs()  # idempotent
    >>> "pointnav_core/PointNav-v0" in gymnasium.registry
    True
    >>> "pointnav_core/MultiPointNav-v0" in pettingzoo.parallel_registry
    True
    """
    for env_id, entry_point in ENV_IDS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(id=env_id, entry_point=entry_point, max_episode_steps=None)
    # pettingzoo.register warns when it overrides an id, so register each one only once.
    for env_type, ids, registry in (
        ("parallel", PARALLEL_ENV_IDS, pettingzoo.parallel_registry),
        ("aec", AEC_ENV_IDS, pettingzoo.aec_registry),
    ):
        for env_id, entry_point in ids.items():
            if env_id not in registry:
                pettingzoo.register(env_type, env_id, entry_point=entry_point)
