"""Registration of the pointnav-core environments with Gymnasium and PettingZoo.

Neither library discovers plugins (Gymnasium 1.x removed the ``gymnasium.envs`` entry-point
group of gym 0.2x; PettingZoo 1.27's registry is filled only by ``pettingzoo.register``
calls), so the ids exist once :func:`register_envs` has run. The core of the package
imports neither library, so importing ``pointnav_core`` does not register anything by
itself; it calls :func:`register_when_imported`, which registers the ids with each library
as soon as that library is imported (at once, if it already is). Hence, in either order,

>>> import pointnav_core, gymnasium                                   # doctest: +SKIP
>>> gymnasium.make("pointnav_core/PointNav-v0")                        # doctest: +SKIP

works, and so does ``gymnasium.make("pointnav_core:pointnav_core/PointNav-v0")`` without
importing the package first. Calling :func:`register_envs` registers explicitly.
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import sys
from collections.abc import Callable, Mapping, Sequence
from types import MappingProxyType, ModuleType
from typing import Any

__all__ = ["AEC_ENV_IDS", "ENV_IDS", "PARALLEL_ENV_IDS", "VECTOR_ENV_IDS", "register_envs", "register_when_imported"]

#: The Gymnasium (single-robot) ids, each with its lazy ``"module:Class"`` entry point.
ENV_IDS: Mapping[str, str] = MappingProxyType(
    {"pointnav_core/PointNav-v0": "pointnav_core.envs.pointnav:PointNavEnv"}
)

#: The batched engine's id: ``gymnasium.make_vec(id, num_envs=N)`` builds a
#: ``VectorPointNavEnv`` (its ``vector_entry_point``); ``gymnasium.make(id)`` one world, a
#: ``PointNavEnv``. It is an id of its own because Gymnasium 1.2 refuses a vector entry
#: point on an id with additional wrappers, and ``PointNav-v0`` needs its ``TaskStepLimit``.
VECTOR_ENV_IDS: Mapping[str, str] = MappingProxyType(
    {"pointnav_core/VectorPointNav-v0": "pointnav_core.vector:VectorPointNavEnv"}
)

#: The PettingZoo parallel (multi-robot) ids, each with its lazy ``"module:function"``.
PARALLEL_ENV_IDS: Mapping[str, str] = MappingProxyType(
    {"pointnav_core/MultiPointNav-v0": "pointnav_core.envs.multi_pointnav:parallel_env"}
)

#: The same multi-robot envs in PettingZoo's AEC form (``parallel_to_aec`` of the above).
AEC_ENV_IDS: Mapping[str, str] = MappingProxyType(
    {"pointnav_core/MultiPointNav-v0": "pointnav_core.envs.multi_pointnav:env"}
)


def register_gymnasium() -> None:
    """Register the Gymnasium ids.

    ``max_episode_steps=None``: the task's ``timeout`` owns truncation. A
    ``max_episode_steps`` given to ``gymnasium.make`` reaches the task through the
    :class:`~pointnav_core.envs.pointnav.TaskStepLimit` wrapper each id adds after the ``TimeLimit``.
    """
    import gymnasium
    from gymnasium.envs.registration import WrapperSpec

    step_limit = WrapperSpec("TaskStepLimit", "pointnav_core.envs.pointnav:TaskStepLimit", kwargs={})
    for env_id, entry_point in ENV_IDS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(
                id=env_id,
                entry_point=entry_point,
                max_episode_steps=None,
                additional_wrappers=(step_limit,),
            )

    for env_id, vector_entry in VECTOR_ENV_IDS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(
                id=env_id,
                entry_point=ENV_IDS["pointnav_core/PointNav-v0"],
                max_episode_steps=None,
                vector_entry_point=vector_entry,
            )


def register_pettingzoo() -> None:
    """Register the multi-robot env in PettingZoo's ``"parallel"`` and ``"aec"`` registries.

    No registry ``max_cycles`` is set, so the env's own default (500) applies unless
    ``make`` is given one.
    """
    import pettingzoo

    # pettingzoo.register warns when it overrides an id, so register each one only once.
    for env_type, ids, registry in (
        ("parallel", PARALLEL_ENV_IDS, pettingzoo.parallel_registry),
        ("aec", AEC_ENV_IDS, pettingzoo.aec_registry),
    ):
        for env_id, entry_point in ids.items():
            if env_id not in registry:
                pettingzoo.register(env_type, env_id, entry_point=entry_point)


def register_envs() -> None:
    """Register every pointnav-core env with Gymnasium and PettingZoo; ids already
    registered are kept.

    Examples
    --------
    >>> register_envs(); register_envs()  # idempotent
    >>> import gymnasium, pettingzoo
    >>> "pointnav_core/PointNav-v0" in gymnasium.registry
    True
    >>> "pointnav_core/MultiPointNav-v0" in pettingzoo.parallel_registry
    True
    """
    register_gymnasium()
    register_pettingzoo()


#: What to run once each library has been imported.
_REGISTRARS: dict[str, Callable[[], None]] = {"gymnasium": register_gymnasium, "pettingzoo": register_pettingzoo}


def register_when_imported() -> None:
    """Register with each library now if it is imported, else right after its import."""
    waiting = []
    for name, registrar in _REGISTRARS.items():
        if name in sys.modules:
            registrar()
        else:
            waiting.append(name)
    if waiting and not any(isinstance(f, _AfterImport) for f in sys.meta_path):
        sys.meta_path.insert(0, _AfterImport())


class _AfterImport(importlib.abc.MetaPathFinder):
    """Finds nothing itself; wraps the loader of a waiting library to register after it runs."""

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        if fullname not in _REGISTRARS:
            return None
        for finder in sys.meta_path:
            if finder is self or not hasattr(finder, "find_spec"):
                continue
            spec = finder.find_spec(fullname, path, target)
            if spec is not None:
                if spec.loader is not None and hasattr(spec.loader, "exec_module"):
                    spec.loader = _RegisteringLoader(spec.loader, _REGISTRARS[fullname])
                return spec
        return None


class _RegisteringLoader(importlib.abc.Loader):
    """A library's own loader, then its registrar."""

    def __init__(self, loader: Any, registrar: Callable[[], None]) -> None:
        self.loader = loader
        self.registrar = registrar

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType | None:
        return self.loader.create_module(spec)

    def exec_module(self, module: ModuleType) -> None:
        self.loader.exec_module(module)
        self.registrar()
        if all(name in sys.modules for name in _REGISTRARS):  # nothing left to wait for
            sys.meta_path[:] = [f for f in sys.meta_path if not isinstance(f, _AfterImport)]

    def __getattr__(self, name: str) -> Any:  # get_resource_reader, is_package, ...
        return getattr(self.loader, name)
