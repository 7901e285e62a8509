"""Generated scenes: houses, mazes and open clutter, named as datasets name them.

``rooms(seed=3)`` builds the scene that the dataset id ``rooms:3`` names (what
:func:`pointnav_core.datasets.load_scene` builds for it), so it carries that
:attr:`~pointnav_core.scenes.Scene.scene_id` and every env checks a dataset episode's
``scene_id`` against it. Other arguments (no seed, another resolution, generator options)
make another scene, which has no name. They are also ``pointnav_core.scenes.rooms``,
``maze`` and ``clutter``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from pointnav_core import floorplans
from pointnav_core.floorplans import FloorPlan

if TYPE_CHECKING:
    from pointnav_core.scenes import Scene

__all__ = ["clutter", "maze", "rooms"]


def rooms(seed: int | None = None, resolution: float = 0.1, **kwargs: Any) -> Scene:
    """A generated house: rooms with walls, doors and furniture (see ``floorplans.rooms``)."""
    return _generated("rooms", floorplans.rooms(seed, **kwargs), seed, resolution, kwargs)


def maze(seed: int | None = None, resolution: float = 0.1, **kwargs: Any) -> Scene:
    """A generated maze of corridors (see ``floorplans.maze``)."""
    return _generated("maze", floorplans.maze(seed, **kwargs), seed, resolution, kwargs)


def clutter(seed: int | None = None, resolution: float = 0.1, **kwargs: Any) -> Scene:
    """A generated open space cluttered with obstacles (see ``floorplans.clutter``)."""
    return _generated("clutter", floorplans.clutter(seed, **kwargs), seed, resolution, kwargs)


def _generated(name: str, plan: FloorPlan, seed: Any, resolution: float, kwargs: dict[str, Any]) -> Scene:
    """The plan's scene, named ``<name>:<seed>`` when it is the one that id names."""
    from pointnav_core.scenes import Scene  # scenes imports this module last

    plain = isinstance(seed, (int, np.integer)) and not isinstance(seed, bool) and resolution == 0.1 and not kwargs
    scene_id = f"{name}:{int(seed)}" if plain else None
    return Scene.from_polygons(plan.outline, plan.obstacles, resolution=resolution, scene_id=scene_id)
