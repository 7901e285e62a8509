"""Episode datasets: Habitat's PointNav format, a generator with its rules, scene sets.

=====================  ===================================================================
module                 what it holds
=====================  ===================================================================
``format``             :class:`EpisodeDataset`, :class:`PointNavEpisode`: gzip JSON files
``generator``          :func:`generate_episodes`: Habitat's sampling rules, seeded
``scene_sets``         named scene sets with train / val / test splits, ``scene_id`` lookup
``playback``           :class:`EpisodeSchedule`: a dataset's episodes in order or shuffled
``crowd_records``      an episode's recorded crowd in the file (``info["pedestrians"]``)
``presets``            the crowd presets as a dataset (:func:`presets.dataset`)
=====================  ===================================================================

Nothing here imports Gymnasium, PettingZoo or a backend.

A validation dataset ships with the package (:data:`VALIDATION_DATASET`, read by
:func:`validation_dataset`): 300 episodes on the 20 ``val`` houses of the ``houses`` set,
made by::

    pointnav dataset generate --scenes houses --split val --episodes 300 --seed 0 \
        --out src/pointnav_core/datasets/data/houses_val_300.json.gz

which gives the same bytes again.
"""

from pathlib import Path

from pointnav_core.datasets.format import EpisodeDataset, PointNavEpisode
from pointnav_core.datasets.generator import (
    GeneratorConfig,
    generate_episodes,
    generate_split,
    island_radius,
)
from pointnav_core.datasets.scene_sets import (
    SCENE_SETS,
    SceneSet,
    load_scene,
    locate_scene,
    scene_set,
)

#: The shipped validation dataset: 300 episodes on the ``val`` houses (see the module notes).
VALIDATION_DATASET = Path(__file__).parent / "data" / "houses_val_300.json.gz"


def validation_dataset() -> EpisodeDataset:
    """The shipped validation dataset (:data:`VALIDATION_DATASET`)."""
    return EpisodeDataset.load(VALIDATION_DATASET)


__all__ = [
    "SCENE_SETS",
    "VALIDATION_DATASET",
    "EpisodeDataset",
    "GeneratorConfig",
    "PointNavEpisode",
    "SceneSet",
    "generate_episodes",
    "generate_split",
    "island_radius",
    "load_scene",
    "locate_scene",
    "scene_set",
    "validation_dataset",
]
