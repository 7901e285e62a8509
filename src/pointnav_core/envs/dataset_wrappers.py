"""Wrappers that make an env play a dataset's episodes at every reset.

:class:`DatasetEpisodes` (Gymnasium, one robot) and :class:`ParallelDatasetEpisodes`
(PettingZoo, one episode per robot) take the next episodes of an
:class:`~pointnav_core.datasets.playback.EpisodeSchedule`, in the dataset's order or
shuffled by a seed, at every ``reset``, so a trainer that only calls ``reset()`` (SB3,
RLlib) plays fixed episodes. :func:`dataset_env` builds the env for one scene of a
dataset: the scene from its ``scene_id``, a robot of the episodes' radius, a task on their
floor.

A ``reset(seed=...)`` still seeds the env; the schedule has its own seed. An episode passed
explicitly (``options={"episode": ...}``) is played instead of the schedule's next one.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import gymnasium as gym
from pettingzoo.utils.wrappers import BaseParallelWrapper

from pointnav_core.datasets.format import PointNavEpisode
from pointnav_core.datasets.playback import EpisodeSchedule
from pointnav_core.datasets.scene_sets import load_scene
from pointnav_core.errors import ArgumentError

__all__ = ["DatasetEpisodes", "ParallelDatasetEpisodes", "dataset_env"]


class DatasetEpisodes(gym.Wrapper):
    """Play the next dataset episode at every reset of a :class:`PointNavEnv`.

    Parameters
    ----------
    env : PointNavEnv (or a wrapper of one)
    episodes : iterable of PointNavEpisode
        Episodes of the env's scene (see :class:`EpisodeSchedule`'s ``scene_id``).
    shuffle : bool
        In order (False) or a new permutation every pass (True).
    seed : int, optional
        Seed of the shuffling.
    """

    def __init__(
        self,
        env: gym.Env,
        episodes: Iterable[PointNavEpisode],
        shuffle: bool = False,
        seed: int | None = None,
    ) -> None:
        super().__init__(env)
        self.schedule = EpisodeSchedule(episodes, shuffle=shuffle, seed=seed)
        self.episode: PointNavEpisode | None = None

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        """Reset the env into the schedule's next episode (or ``options["episode"]``)."""
        options = dict(options or {})
        if options.get("episode") is None:
            options["episode"] = next(self.schedule)
        self.episode = options["episode"]
        return self.env.reset(seed=seed, options=options)


class ParallelDatasetEpisodes(BaseParallelWrapper):
    """Play the schedule's next episodes, one per robot, at every reset of a multi-robot env.

    Parameters are those of :class:`DatasetEpisodes`. Episodes whose starts overlap another
    robot's raise ``ValueError`` naming the episode; goals are taken as given.
    """

    def __init__(
        self,
        env: Any,
        episodes: Iterable[PointNavEpisode],
        shuffle: bool = False,
        seed: int | None = None,
    ) -> None:
        super().__init__(env)
        self.schedule = EpisodeSchedule(episodes, shuffle=shuffle, seed=seed)
        self.episodes: list[PointNavEpisode] = []

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, dict[str, Any]]]:
        """Reset every robot into the schedule's next episodes (or ``options["episodes"]``)."""
        options = dict(options or {})
        if options.get("episodes") is None:
            options["episodes"] = self.schedule.take(len(self.env.possible_agents))
        given = options["episodes"]
        self.episodes = list(given.values()) if isinstance(given, Mapping) else list(given)
        return self.env.reset(seed=seed, options=options)


def dataset_env(
    episodes: Iterable[PointNavEpisode],
    scene_id: str,
    *,
    shuffle: bool = False,
    seed: int | None = None,
    n_robots: int | None = None,
    scenes_root: str | None = None,
    **env_kwargs: Any,
) -> Any:
    """An env on ``scene_id``'s scene that plays that scene's episodes at every reset.

    Parameters
    ----------
    episodes : iterable of PointNavEpisode
        A dataset; only ``scene_id``'s episodes are played. They must share one floor and
        one robot radius (the env's robot and task are made from them).
    scene_id : str
    shuffle, seed
        See :class:`DatasetEpisodes`.
    n_robots : int, optional
        None: a :class:`PointNavEnv` in :class:`DatasetEpisodes`; a number: a
        :class:`MultiPointNavEnv` with that many robots in :class:`ParallelDatasetEpisodes`.
    scenes_root : str, optional
        Folder relative scene paths are read from.
    **env_kwargs
        More env arguments; ``robot`` and ``task`` dicts are merged over the ones made here.

    Examples
    --------
    >>> from pointnav_core.datasets import validation_dataset
    >>> env = dataset_env(validation_dataset(), "rooms:200", shuffle=True, seed=0)
    >>> obs, info = env.reset(seed=0)
    >>> env.episode.scene_id, round(info["geodesic_dist"] - env.episode.geodesic_distance, 6)
    ('rooms:200', 0.0)
    """
    mine = [ep for ep in episodes if ep.scene_id == scene_id]
    if not mine:
        raise ArgumentError(f"no episode has scene_id {scene_id!r}")
    for field_name, values in (
        ("info.floor", {ep.floor for ep in mine}),
        ("info.robot_radius", {ep.robot_radius for ep in mine}),
    ):
        if len(values) > 1:
            raise ArgumentError(
                f"the episodes of scene {scene_id!r} differ in field '{field_name}' ({sorted(values)}); "
                f"one env plays one floor with one robot: split them"
            )
    robot = {"radius": mine[0].robot_radius, **dict(env_kwargs.pop("robot", None) or {})}
    task = {"floor": mine[0].floor, **dict(env_kwargs.pop("task", None) or {})}
    scene = load_scene(scene_id, scenes_root)
    if n_robots is None:
        from pointnav_core.envs.pointnav import PointNavEnv

        return DatasetEpisodes(
            PointNavEnv(scene=scene, robot=robot, task=task, **env_kwargs), mine, shuffle, seed
        )
    from pointnav_core.envs.multi_pointnav import MultiPointNavEnv

    multi = MultiPointNavEnv(scene=scene, n_robots=n_robots, robot=robot, task=task, **env_kwargs)
    return ParallelDatasetEpisodes(multi, mine, shuffle, seed)
