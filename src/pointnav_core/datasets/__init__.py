"""Episode datasets: Habitat's PointNav format, a generator with its rules, scene sets.

=====================  ===================================================================
module                 what it holds
=====================  ===================================================================
``format``             :class:`EpisodeDataset`, :class:`PointNavEpisode`: gzip JSON files
``generator``          :func:`generate_episodes`: Habitat's sampling rules, seeded
``scene_sets``         named scene sets with train / val / test splits, ``scene_id`` lookup
``playback``           :class:`EpisodeSchedule`: a dataset's episodes in order or shuffled
=====================  ===================================================================

Nothing here imports Gymnasium, PettingZoo or a backend.
"""

from pointnav_core.datasets.format import EpisodeDataset, PointNavEpisode
from pointnav_core.datasets.generator import GeneratorConfig, generate_episodes, generate_split, island_radius
from pointnav_core.datasets.scene_sets import SCENE_SETS, SceneSet, load_scene, scene_set

__all__ = [
    "SCENE_SETS",
    "EpisodeDataset",
    "GeneratorConfig",
    "PointNavEpisode",
    "SceneSet",
    "generate_episodes",
    "generate_split",
    "island_radius",
    "load_scene",
    "scene_set",
]
