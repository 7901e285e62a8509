"""The crowd presets (:mod:`pointnav_core.crowds.presets`) written as a dataset.

:func:`dataset` makes ``episodes_per`` episodes of each named preset: the preset's robot
task (start, heading, goal) in its scene, ``scene_id`` ``preset:<name>``
(:data:`~pointnav_core.datasets.scene_sets.PRESET_SCENES`), and its crowd recorded
(:attr:`~pointnav_core.datasets.format.PointNavEpisode.pedestrians`): the preset's fixed
starts and goal lists, walked round and round, with each pedestrian's own seed (its heading,
and its speed or radius where the preset gives a range). Circle crossing's start noise is
drawn anew for every episode. ``pointnav eval`` plays such a file like any other::

    from pointnav_core.datasets import presets
    presets.dataset(["circle_crossing", "corridor", "doorway"], episodes_per=10, seed=0).save("crowds.json.gz")

The recorded crowd is played with the evaluating env's pedestrian settings, or the
defaults (docs/decisions.md, "Crowds"): ORCA, as the presets use.
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Sequence

import numpy as np

from pointnav_core.crowds import Crowd, make_pedestrians
from pointnav_core.datasets.format import EpisodeDataset, PointNavEpisode
from pointnav_core.datasets.scene_sets import PRESET_SCENES, load_scene
from pointnav_core.errors import ArgumentError
from pointnav_core.utils import validation

__all__ = ["ROBOT_RADIUS", "dataset"]

#: The robot radius (m) the presets' episodes are made for: the default ``RobotSpec``'s.
ROBOT_RADIUS = 0.18
#: Success distance (m) recorded with each goal (the generator's default).
GOAL_RADIUS = 0.5


def dataset(names: Sequence[str], episodes_per: int = 1, seed: int = 0) -> EpisodeDataset:
    """``episodes_per`` episodes of each preset in ``names``, ids ``"<name>_<k>"``, in that
    order; the same arguments give the same dataset.

    Parameters
    ----------
    names : sequence of str
        Keys of :data:`~pointnav_core.datasets.scene_sets.PRESET_SCENES`.
    episodes_per : int
        Episodes per preset (>= 1).
    seed : int
        Seeds every crowd (each preset's from ``seed`` and its name's place in
        :data:`PRESET_SCENES`, so a preset's episodes do not depend on the others named).

    Raises
    ------
    ValueError
        For an unknown name (naming the known ones) or a bad count or seed.
    """
    if isinstance(names, str) or not isinstance(names, Sequence) or not names:
        raise ArgumentError(f"names must be a non-empty list of {sorted(PRESET_SCENES)}, got {names!r}")
    for name in names:
        if name not in PRESET_SCENES:
            raise ArgumentError(f"names: unknown preset {name!r}, expected one of {sorted(PRESET_SCENES)}")
    episodes_per = validation.integer("episodes_per", episodes_per, minimum=1)
    seed = validation.integer("seed", seed, minimum=0)
    episodes = []
    for name in names:
        rng = np.random.default_rng([seed, list(PRESET_SCENES).index(name)])
        episodes += [_episode(name, k, rng) for k in range(episodes_per)]
    return EpisodeDataset(episodes, {"presets": list(names), "episodes_per": episodes_per, "seed": seed})


def _episode(name: str, k: int, rng: np.random.Generator) -> PointNavEpisode:
    """Episode ``k`` of preset ``name``, its crowd drawn from ``rng``."""
    make = PRESET_SCENES[name]
    # A preset with a seed of its own (circle crossing's start noise) gets a new one each time.
    seeded = "seed" in inspect.signature(make).parameters
    scenario = make(seed=int(rng.integers(2**31))) if seeded else make()
    scene = load_scene(f"preset:{name}")  # the scene the scene_id builds, cached
    task = scenario.task
    start, goal = task["initial_pos"], task["goal_pos"]
    z = scene.floors[0].height
    _, _, qz, qw = task["initial_quat"]
    crowd = Crowd(make_pedestrians(scenario.pedestrians), scene)
    crowd.spawn(0, rng, np.array([[start[0], start[1], ROBOT_RADIUS]]))
    geodesic = scene.geodesic_distance(0, start, goal, robot=ROBOT_RADIUS)
    if not math.isfinite(geodesic):  # a preset whose robot cannot reach its goal is a bug
        raise ArgumentError(f"preset {name!r}: the robot's goal {goal} is not reachable from {start}")
    return PointNavEpisode(
        episode_id=f"{name}_{k}",
        scene_id=f"preset:{name}",
        floor=0,
        start_position=(float(start[0]), float(start[1]), float(z)),
        start_rotation=(0.0, 0.0, float(qz), float(qw)),
        goal_position=(float(goal[0]), float(goal[1]), float(z)),
        goal_radius=GOAL_RADIUS,
        geodesic_distance=float(geodesic),
        robot_radius=ROBOT_RADIUS,
        pedestrians=crowd.record(),
    )
