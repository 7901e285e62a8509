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
=============================  ==========================================================

Relative paths are read relative to ``root`` (the working directory by default). A plain
path is accepted too: ``.map`` is a MovingAI map, ``.png`` a traversability image, a folder
an OmniGibson scene.

Named sets (:data:`SCENE_SETS`) are generated scenes whose seeds are split into
consecutive, disjoint blocks: train, then val, then test, so no scene is in two splits.
A folder of MovingAI maps and OmniGibson scenes is a set too (:func:`folder_scene_set`):
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
from pointnav_core.maps import BoundedCache
from pointnav_core.scenes import Scene

__all__ = [
    "SCENE_SETS",
    "SPLITS",
    "SceneSet",
    "folder_scene_set",
    "generated_scene_set",
    "load_scene",
    "scene_set",
]

#: Split names, in the order their seed blocks follow each other.
SPLITS = ("train", "val", "test")
#: Scene generators a ``scene_id`` may name.
GENERATORS = {"rooms": scenes.rooms, "maze": scenes.maze, "clutter": scenes.clutter}
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
                    raise ValueError(
                        f"scene set {self.name!r}: scene {scene_id!r} is in both {seen[scene_id]!r} "
                        f"and {split!r}; splits must not share scenes"
                    )
                seen[scene_id] = split

    def scene_ids(self, split: str) -> tuple[str, ...]:
        """The scene ids of ``split``; ``ValueError`` naming the valid splits otherwise."""
        if split not in self.splits:
            raise ValueError(f"split must be one of {list(self.splits)}, got {split!r}")
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
        raise ValueError(f"generator must be one of {sorted(GENERATORS)}, got {generator!r}")
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


def folder_scene_set(
    folder: str | os.PathLike[str],
    seed: int = 0,
    fractions: tuple[float, float, float] = (0.8, 0.1, 0.1),
) -> SceneSet:
    """The MovingAI maps (``*.map``) and OmniGibson scene folders (with ``floor_trav_*.png``)
    directly inside ``folder``, sorted by name, shuffled by ``seed`` and cut into train / val
    / test by ``fractions`` (val and test get at least one scene each when there are three or
    more). Scene ids are ``movingai:<folder>/<name>`` and ``trav:<folder>/<name>``, with
    ``folder`` as given.
    """
    folder = os.fspath(folder)
    if not os.path.isdir(folder):
        raise ValueError(f"scene folder {folder!r} does not exist or is not a folder")
    if (
        len(fractions) != 3
        or any(f < 0 for f in fractions)
        or not math.isclose(sum(fractions), 1.0)
    ):
        raise ValueError(f"fractions must be three numbers >= 0 summing to 1, got {fractions!r}")
    ids = []
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name).replace(os.sep, "/")
        if name.endswith(".map") and os.path.isfile(path):
            ids.append(f"movingai:{path}")
        elif os.path.isdir(path) and _trav_images(path):
            ids.append(f"trav:{path}")
    if not ids:
        raise ValueError(
            f"scene folder {folder!r} holds no .map file and no folder with floor_trav_*.png"
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
    raise ValueError(
        f"scene set must be one of {sorted(SCENE_SETS)} or a folder of scenes, got {spec!r}"
    )


#: Scenes built by :func:`load_scene`, by (scene_id, root); a house takes ~0.5 s to build.
_CACHE: BoundedCache = BoundedCache(16)


def load_scene(scene_id: str, root: str | os.PathLike[str] | None = None) -> Scene:
    """Build (or fetch from a small cache) the scene a ``scene_id`` names; see the module notes.

    Raises
    ------
    ValueError
        For a scene_id of no known form, naming the forms.
    FileNotFoundError
        For a path that does not exist.
    """
    key = (scene_id, None if root is None else os.fspath(root))
    return _CACHE.get_or_create(key, lambda: _named(_build(scene_id, root), scene_id))


def _named(scene: Scene, scene_id: str) -> Scene:
    # The envs check a dataset episode's scene_id against it (datasets.playback).
    scene.scene_id = scene_id
    return scene


def _build(scene_id: Any, root: str | os.PathLike[str] | None) -> Scene:
    forms = "rooms:<seed>, maze:<seed>, clutter:<seed>, movingai:<path>, trav:<path>, or a .map/.png/folder path"
    if not isinstance(scene_id, str) or not scene_id:
        raise ValueError(f"scene_id must be a non-empty string ({forms}), got {scene_id!r}")
    scheme, _, rest = scene_id.partition(":")
    if scheme in GENERATORS:
        if not re.fullmatch(r"-?\d+", rest):
            raise ValueError(f"unknown scene_id {scene_id!r}: {scheme}: takes an integer seed")
        return GENERATORS[scheme](seed=int(rest))
    if scheme in ("movingai", "trav") and rest:
        path = rest
    elif ":" not in scene_id or re.match(r"^[A-Za-z]:[\\/]", scene_id):  # a plain (or Windows) path
        path, scheme = scene_id, ""
    else:
        raise ValueError(f"unknown scene_id {scene_id!r}: expected one of {forms}")
    if root is not None and not os.path.isabs(path):
        path = os.path.join(os.fspath(root), path)
    if not os.path.exists(path):
        raise FileNotFoundError(f"scene_id {scene_id!r}: no such file or folder {path!r}")
    if scheme == "movingai" or (not scheme and path.endswith(".map")):
        return Scene.from_movingai(path)
    if os.path.isdir(path):
        images = _trav_images(path)
        if not images:
            raise ValueError(f"scene_id {scene_id!r}: folder {path!r} has no floor_trav_<n>.png")
        return Scene.from_png(images)
    if path.endswith(".png"):
        return Scene.from_png(path)
    raise ValueError(f"unknown scene_id {scene_id!r}: expected one of {forms}")
