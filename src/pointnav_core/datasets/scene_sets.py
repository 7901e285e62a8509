"""Scene sets with train / val / test splits, and scenes addressed by a ``scene_id`` string.

A ``scene_id`` says how to build its scene:

=============================  ==========================================================
scene_id                       scene
=============================  ==========================================================
``rooms:<seed>``               generated house (:func:`pointnav_core.scenes.rooms`)
``maze:<seed>``                generated maze (:func:`pointnav_core.scenes.maze`)
``clutter:<seed>``             generated cluttered space (:func:`pointnav_core.scenes.clutter`)
``movingai:<path>``            MovingAI ``.map`` file (:meth:`Scene.from_movingai`)
``trav:<path>``                OmniGibson scene folder: its ``floor_trav_<n>.png`` images
                               (in the folder or its ``layout/``), one floor each, or
                               one ``floor_trav_<n>.png`` file
``ros:<path>``                 ROS map_server ``map.yaml`` (:meth:`Scene.from_ros_map`)
``procthor:<path>``            ProcTHOR ``house.json`` (:meth:`Scene.from_procthor`)
``houseexpo:<path>``           HouseExpo ``<id>.json`` (:meth:`Scene.from_houseexpo`)
``preset:<name>``              a crowd preset's scene, built with the preset's default
                               arguments (:data:`PRESET_SCENES`: ``circle_crossing``,
                               ``corridor``, ``doorway``; :mod:`pointnav_core.crowds.presets`)
=============================  ==========================================================

Relative paths are read relative to ``root`` (the working directory by default); with a
``root``, a path must stay under it once resolved (:func:`locate_scene`). A plain
path is accepted too: ``.map`` is a MovingAI map, ``.png`` a traversability image,
``.yaml``/``.yml`` a ROS map, ``.json`` a ProcTHOR house or a HouseExpo plan (told apart by
their keys), a folder an OmniGibson scene.

Named sets (:data:`SCENE_SETS`) are generated scenes whose seeds are split into
consecutive, disjoint blocks: train, then val, then test, so no scene is in two splits.
A folder of scene files (any of the above) is a set too (:func:`folder_scene_set`):
its scenes, sorted by name and shuffled by a seed, are cut into the three splits.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from pointnav_core import scenes
from pointnav_core.crowds import presets
from pointnav_core.errors import ArgumentError
from pointnav_core.floor.maps import BoundedCache
from pointnav_core.scenes import Scene

__all__ = [
    "PRESET_SCENES",
    "SCENE_SETS",
    "SPLITS",
    "SceneSet",
    "folder_scene_set",
    "generated_scene_set",
    "load_scene",
    "locate_scene",
    "scene_set",
]

#: Split names, in the order their seed blocks follow each other.
SPLITS = ("train", "val", "test")
#: Scene generators a ``scene_id`` may name.
GENERATORS = {"rooms": scenes.rooms, "maze": scenes.maze, "clutter": scenes.clutter}
#: Scene files a ``scene_id`` may name, by scheme (``trav`` is handled apart: a folder or a PNG).
FILE_SCHEMES = {
    "movingai": Scene.from_movingai,
    "ros": Scene.from_ros_map,
    "procthor": Scene.from_procthor,
    "houseexpo": Scene.from_houseexpo,
    "trav": Scene.from_png,
}
#: Crowd presets whose scene a ``preset:<name>`` scene_id builds (default arguments).
PRESET_SCENES = {"circle_crossing": presets.circle_crossing, "corridor": presets.corridor, "doorway": presets.doorway}
_TRAV = re.compile(r"floor_trav_(\d+)\.png$")


@dataclass(frozen=True)
class SceneSet:
    """Named scenes in disjoint splits.

    Attributes
    ----------
    name : str
    splits : dict
        Split name (``train``, ``val``, ``test``) -> tuple of scene ids.
    """

    name: str
    splits: Mapping[str, tuple[str, ...]]

    def __post_init__(self) -> None:
        seen: dict[str, str] = {}
        for split, ids in self.splits.items():
            for scene_id in ids:
                if scene_id in seen:
                    raise ArgumentError(
                        f"scene set {self.name!r}: scene {scene_id!r} is in both {seen[scene_id]!r} "
                        f"and {split!r}; splits must not share scenes"
                    )
                seen[scene_id] = split

    def scene_ids(self, split: str) -> tuple[str, ...]:
        """The scene ids of ``split``; ``ValueError`` naming the valid splits otherwise."""
        if split not in self.splits:
            raise ArgumentError(f"split must be one of {list(self.splits)}, got {split!r}")
        return self.splits[split]


def generated_scene_set(
    name: str, generator: str, sizes: tuple[int, int, int], first_seed: int = 0
) -> SceneSet:
    """A set of generated scenes: seeds ``first_seed, first_seed + 1, ...`` cut into
    consecutive train / val / test blocks of ``sizes`` scenes, so no seed is in two splits.

    Examples
    --------
    >>> generated_scene_set("tiny", "rooms", (2, 1, 1)).splits
    {'train': ('rooms:0', 'rooms:1'), 'val': ('rooms:2',), 'test': ('rooms:3',)}
    """
    if generator not in GENERATORS:
        raise ArgumentError(f"generator must be one of {sorted(GENERATORS)}, got {generator!r}")
    splits, seed = {}, first_seed
    for split, size in zip(SPLITS, sizes):
        splits[split] = tuple(f"{generator}:{s}" for s in range(seed, seed + size))
        seed += size
    return SceneSet(name, splits)


#: Named scene sets. ``houses``: 200 train, 20 val and 20 test generated houses (20 x 15 m).
SCENE_SETS: dict[str, SceneSet] = {
    "houses": generated_scene_set("houses", "rooms", (200, 20, 20)),
    "mazes": generated_scene_set("mazes", "maze", (200, 20, 20)),
    "clutter": generated_scene_set("clutter", "clutter", (200, 20, 20)),
}


def _trav_images(folder: str) -> list[str]:
    for where in (folder, os.path.join(folder, "layout")):
        if os.path.isdir(where):
            found = sorted((int(m.group(1)), f) for f in os.listdir(where) if (m := _TRAV.match(f)))
            if found:
                return [os.path.join(where, f) for _, f in found]
    return []


def _file_scheme(path: str) -> str | None:
    """The scene_id scheme of a scene file by its name (and a JSON file's keys), or None
    for a file that is no scene; a ``.json`` that is neither floor-plan format is an error."""
    if path.endswith(".map"):
        return "movingai"
    if path.endswith((".yaml", ".yml")):
        return "ros"
    if path.endswith(".json"):
        from pointnav_core.floorplans.files import sniff_plan_format

        return sniff_plan_format(path)
    return None


def folder_scene_set(
    folder: str | os.PathLike[str],
    seed: int = 0,
    fractions: tuple[float, float, float] = (0.8, 0.1, 0.1),
) -> SceneSet:
    """The scene files (MovingAI ``*.map``, map_server ``*.yaml``, ProcTHOR and HouseExpo
    ``*.json``) and OmniGibson scene folders (with ``floor_trav_*.png``) directly inside
    ``folder``, sorted by name, shuffled by ``seed`` and cut into train / val
    / test by ``fractions`` (val and test get at least one scene each when there are three or
    more). Scene ids are ``<scheme>:<folder>/<name>`` (``movingai``, ``ros``, ``procthor``,
    ``houseexpo`` or ``trav``), with ``folder`` as given.
    """
    folder = os.fspath(folder)
    if not os.path.isdir(folder):
        raise ArgumentError(f"scene folder {folder!r} does not exist or is not a folder")
    if (
        len(fractions) != 3
        or any(f < 0 for f in fractions)
        or not math.isclose(sum(fractions), 1.0)
    ):
        raise ArgumentError(f"fractions must be three numbers >= 0 summing to 1, got {fractions!r}")
    ids = []
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name).replace(os.sep, "/")
        scheme = _file_scheme(path) if os.path.isfile(path) else None
        if scheme is not None:
            ids.append(f"{scheme}:{path}")
        elif os.path.isdir(path) and _trav_images(path):
            ids.append(f"trav:{path}")
    if not ids:
        raise ArgumentError(
            f"scene folder {folder!r} holds no scene: no .map, map_server .yaml, ProcTHOR or "
            "HouseExpo .json file, and no folder with floor_trav_*.png"
        )
    order = np.random.default_rng(seed).permutation(len(ids))
    n = len(ids)
    n_val = round(n * fractions[1])
    n_test = round(n * fractions[2])
    if n >= 3:
        n_val, n_test = max(n_val, 1), max(n_test, 1)
    n_train = n - n_val - n_test
    shuffled = [ids[i] for i in order]
    splits = {
        "train": tuple(shuffled[:n_train]),
        "val": tuple(shuffled[n_train : n_train + n_val]),
        "test": tuple(shuffled[n_train + n_val :]),
    }
    return SceneSet(folder, splits)


def scene_set(spec: str, seed: int = 0) -> SceneSet:
    """A named set (:data:`SCENE_SETS`) or, for a folder path, :func:`folder_scene_set`."""
    if spec in SCENE_SETS:
        return SCENE_SETS[spec]
    if os.path.isdir(spec):
        return folder_scene_set(spec, seed=seed)
    raise ArgumentError(
        f"scene set must be one of {sorted(SCENE_SETS)} or a folder of scenes, got {spec!r}"
    )


#: Scenes built by :func:`load_scene`, by (scene_id, root); a house takes ~0.5 s to build.
_CACHE: BoundedCache = BoundedCache(16)


def load_scene(scene_id: str, root: str | os.PathLike[str] | None = None) -> Scene:
    """Build (or fetch from a small cache) the scene a ``scene_id`` names; see the module notes.

    Raises
    ------
    ValueError
        For a scene_id of no known form, naming the forms, or a path that leaves ``root``
        (see :func:`locate_scene`).
    FileNotFoundError
        For a path that does not exist.
    """
    key = (scene_id, None if root is None else os.fspath(root))
    return _CACHE.get_or_create(key, lambda: _named(_build(scene_id, root), scene_id))


def _named(scene: Scene, scene_id: str) -> Scene:
    # The envs check a dataset episode's scene_id against it (datasets.playback).
    scene.scene_id = scene_id
    return scene


_FORMS = (
    "rooms:<seed>, maze:<seed>, clutter:<seed>, movingai:<path>, trav:<path>, ros:<path>, "
    "procthor:<path>, houseexpo:<path>, preset:<name>, or a .map/.png/.yaml/.json/folder path"
)


def locate_scene(scene_id: Any, root: str | os.PathLike[str] | None = None) -> tuple[str, str | None]:
    """Check a ``scene_id`` without building its scene: ``(scheme, path)``.

    ``scheme`` is a generator name (``rooms``, ...; ``path`` None), ``preset`` (``path`` None), a file scheme of
    :data:`FILE_SCHEMES`, or ``""`` (a plain path). With ``root``, a path is resolved (links
    followed) and must stay under ``root``: a dataset cannot make the reader open files
    elsewhere.

    Raises
    ------
    ValueError
        For a scene_id of no known form, naming the forms, or a path outside ``root``.
    FileNotFoundError
        For a path that does not exist.
    """
    if not isinstance(scene_id, str) or not scene_id:
        raise ArgumentError(f"scene_id must be a non-empty string ({_FORMS}), got {scene_id!r}")
    scheme, _, rest = scene_id.partition(":")
    if scheme in GENERATORS:
        if not re.fullmatch(r"-?\d+", rest):
            raise ArgumentError(f"unknown scene_id {scene_id!r}: {scheme}: takes an integer seed")
        return scheme, None
    if scheme == "preset":
        if rest not in PRESET_SCENES:
            raise ArgumentError(f"unknown scene_id {scene_id!r}: preset: takes one of {sorted(PRESET_SCENES)}")
        return scheme, None
    if scheme in FILE_SCHEMES and rest:
        path = rest
    elif ":" not in scene_id or re.match(r"^[A-Za-z]:[\\/]", scene_id):  # a plain (or Windows) path
        path, scheme = scene_id, ""
    else:
        raise ArgumentError(f"unknown scene_id {scene_id!r}: expected one of {_FORMS}")
    if root is not None:
        base = os.path.realpath(root)
        path = os.path.realpath(os.path.join(base, path))
        if os.path.commonpath([base, path]) != base:
            raise ArgumentError(
                f"scene_id {scene_id!r}: the path leaves the scenes folder {os.fspath(root)!r} "
                "(scenes_root, --scenes-dir)"
            )
    if not os.path.exists(path):
        raise FileNotFoundError(f"scene_id {scene_id!r}: no such file or folder {path!r}")
    return scheme, path


def _build(scene_id: Any, root: str | os.PathLike[str] | None) -> Scene:
    scheme, path = locate_scene(scene_id, root)
    if scheme == "preset":
        return PRESET_SCENES[scene_id.partition(":")[2]]().scene
    if path is None:
        return GENERATORS[scheme](seed=int(scene_id.partition(":")[2]))
    if not scheme and os.path.isfile(path):
        scheme = _file_scheme(path) or ""
    if scheme in FILE_SCHEMES and scheme != "trav":
        return FILE_SCHEMES[scheme](path)
    if os.path.isdir(path):
        images = _trav_images(path)
        if not images:
            raise ArgumentError(f"scene_id {scene_id!r}: folder {path!r} has no floor_trav_<n>.png")
        return Scene.from_png(images)
    if path.endswith(".png"):
        return Scene.from_png(path)
    raise ArgumentError(f"unknown scene_id {scene_id!r}: expected one of {_FORMS}")
