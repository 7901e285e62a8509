"""The batched engines' arguments, read and checked once for both (one robot a world, and
:mod:`pointnav_core.vector.fleet_env`'s several): scenes, task arguments and actions."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from pointnav_core import scenes
from pointnav_core.errors import ArgumentError
from pointnav_core.utils import validation

__all__ = ["as_scene_list", "check_continuous_actions", "check_real_actions", "default_scene", "grid_scene", "task_arguments"]


def grid_scene(scene: scenes.Scene, floor: int = 0) -> scenes.Scene:
    """Floor ``floor`` of ``scene`` as a one-floor scene of grid cells only: its obstacle
    polygons as the cells they were rasterised to (what the batched scan sees)."""
    tmap = scene.floors[floor]
    return scenes.Scene.from_array(np.asarray(tmap.codes), tmap.resolution, origin=tuple(tmap.origin))


def default_scene() -> scenes.Scene:
    # The single env's default house, its floor as grid cells only (see docs/decisions.md).
    return grid_scene(scenes.rooms(seed=0))


def task_arguments(task: Mapping[str, Any] | None) -> dict[str, Any]:
    """A copy of the ``task`` arguments; ValueError for a non-dict, a custom termination or
    observation term, or a reward term the engine cannot run (see :func:`check_batched_rewards`)."""
    if task is not None and not isinstance(task, Mapping):
        raise ArgumentError(f"task must be None or a dict of PointNavigationTask arguments, got {task!r}")
    for key in ("termination_conditions", "observation_terms"):
        if task is not None and task.get(key) is not None:
            raise ArgumentError(f"task: {key} is not supported by the batched engine")
    if task is not None and task.get("reward_functions") is not None:
        check_batched_rewards(task["reward_functions"])
    return dict(task or {})


def check_batched_rewards(terms: Any) -> None:
    """ValueError unless every reward term is a new one (not named like a built-in) with a
    ``batched(task)`` method: the batched engine computes the built-in terms itself and calls
    the others on every robot at once (``vector.accounting.BatchedTask``)."""
    from pointnav_core.vector.accounting import BUILT_IN_REWARDS

    for term in terms if isinstance(terms, (list, tuple)) else [terms]:
        name = getattr(term, "name", None)
        if name in BUILT_IN_REWARDS:
            raise ArgumentError(f"task: reward_functions: the batched engine cannot replace the built-in {name!r} term")
        if not callable(getattr(term, "batched", None)):
            raise ArgumentError(
                f"task: reward_functions: {term!r} has no batched(task) method; the batched engine runs a custom "
                f"reward term on every robot at once through it (docs/extending.md)"
            )


def as_scene_list(scene: scenes.Scene | Sequence[scenes.Scene] | None) -> list[scenes.Scene]:
    """The worlds' scenes (default: the default house as a grid); ValueError if not Scenes."""
    scene_list = [scene] if isinstance(scene, scenes.Scene) else list(scene) if scene is not None else [default_scene()]
    if not scene_list or not all(isinstance(s, scenes.Scene) for s in scene_list):
        raise ArgumentError(f"scene must be a Scene or a non-empty sequence of Scenes, got {scene!r}")
    return scene_list


def check_real_actions(actions: Any) -> None:
    """ValueError naming ``actions`` unless they are real numbers (both engines; the single
    env's rule, :func:`pointnav_core.utils.validation.is_real_array`: no bools, complex numbers or strings)."""
    if not validation.is_real_array(actions):
        kind = getattr(actions, "dtype", type(actions).__name__)
        raise ArgumentError(f"actions must be real numbers in [-1, 1] (an integer or float array), got {kind}")


def check_continuous_actions(actions: Any, n: int, robot: Any, arrays: Any) -> Any:
    """The one-robot engine's continuous ``actions`` as a float64 array ``(n, action_dim)``
    (2 for a differential drive, 3 for a holonomic one); ValueError naming ``actions`` if bad."""
    shape = tuple(getattr(actions, "shape", np.shape(actions)))
    dim = robot.action_dim
    if shape not in ((n, dim), (n, 1, dim)):
        raise ArgumentError(
            f"actions must have shape ({n}, {dim}) or ({n}, 1, {dim}) for a {robot.drive} drive, got {shape}"
        )
    check_real_actions(actions)
    arr = arrays.asarray(actions).reshape(n, dim)
    if not bool(arrays.xp.isfinite(arr).all()):
        raise ArgumentError("actions must be finite (no NaN or infinity)")
    return arr
