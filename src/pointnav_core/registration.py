"""Gymnasium registration of the pointnav-core environments.

Gymnasium 1.x has no plugin discovery (the ``gymnasium.envs`` entry-point group of gym
0.2x was removed), so the ids exist once :func:`register_envs` has run: importing
``pointnav_core`` runs it, and ``gymnasium.make("pointnav_core:pointnav_core/PointNav-v0")``
imports the package first by itself.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

import gymnasium

__all__ = ["ENV_IDS", "register_envs"]

#: The registered ids, each with its lazy ``"module:Class"`` entry point.
ENV_IDS: Mapping[str, str] = MappingProxyType(
    {"pointnav_core/PointNav-v0": "pointnav_core.env:PointNavEnv"}
)


def register_envs() -> None:
    """Register every pointnav-core env with Gymnasium; ids already registered are kept.

    ``max_episode_steps`` is None: the task's ``timeout`` condition owns truncation, so no
    ``TimeLimit`` wrapper is added.

    Examples
    --------
    >>> register_envs(); register_envs()  # idempotent
    >>> "pointnav_core/PointNav-v0" in gymnasium.registry
    True
    """
    for env_id, entry_point in ENV_IDS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(id=env_id, entry_point=entry_point, max_episode_steps=None)
