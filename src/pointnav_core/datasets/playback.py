"""Playing a dataset's episodes in an environment: order, shuffling, and per-episode checks.

Both environments take a dataset episode at reset::

    env = PointNavEnv(scene=load_scene(scene_id))
    schedule = EpisodeSchedule(dataset, scene_id=scene_id, shuffle=True, seed=0)
    obs, info = env.reset(options={"episode": next(schedule)})

    multi = MultiPointNavEnv(scene=load_scene(scene_id), num_robots=2)
    obs, infos = multi.reset(options={"episodes": schedule.take(2)})  # one per robot

The episode's start, start orientation and goal replace the task's for that episode; the
task keeps its own ``goal_tolerance``, rewards and limits. An episode that records a crowd
(:attr:`PointNavEpisode.pedestrians`) has exactly that crowd placed, with the env's
pedestrian settings (the defaults in a single-robot env built without them). An env holds one scene, so a
schedule is usually restricted to one ``scene_id`` (the env cannot tell scenes apart).
:func:`episode_poses` checks an episode against the env and names the episode and the field
in every error.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Iterable, Iterator
from typing import Any

import numpy as np

from pointnav_core.datasets.format import PointNavEpisode
from pointnav_core.errors import ArgumentError
from pointnav_core.scenes import Scene

__all__ = ["EpisodeSchedule", "episode_poses", "episode_seed"]

#: How far (m) a recorded start or goal height may be from its floor's height.
_HEIGHT_TOL = 1e-6


def episode_seed(episode: PointNavEpisode) -> int:
    """A seed (0 <= seed < 2**63) for one episode, from its scene id and episode id only, so
    that whatever plays the episode does the same whatever the order or the process."""
    digest = hashlib.sha256(f"{episode.scene_id}\0{episode.episode_id}".encode()).digest()
    return int.from_bytes(digest[:8], "little") >> 1


class EpisodeSchedule:
    """An endless stream of episodes: in the dataset's order, or shuffled by a seed.

    Parameters
    ----------
    episodes : iterable of PointNavEpisode
        A dataset, or any episodes.
    scene_id : str, optional
        Keep only this scene's episodes.
    shuffle : bool
        False: the episodes in order, then again from the first. True: every pass is a new
        permutation drawn from ``seed``.
    seed : int, optional
        Seed of the shuffling (the same seed gives the same sequence).

    Examples
    --------
    >>> eps = [PointNavEpisode(str(i), "s", 0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0),
    ...                        (1.0, 0.0, 0.0), None, 1.0, 0.1) for i in range(3)]
    >>> [e.episode_id for e in EpisodeSchedule(eps).take(4)]
    ['0', '1', '2', '0']
    >>> sorted(e.episode_id for e in EpisodeSchedule(eps, shuffle=True, seed=1).take(3))
    ['0', '1', '2']
    """

    def __init__(
        self,
        episodes: Iterable[PointNavEpisode],
        scene_id: str | None = None,
        shuffle: bool = False,
        seed: int | None = None,
    ) -> None:
        if not isinstance(shuffle, (bool, np.bool_)):
            raise ArgumentError(f"shuffle must be True or False, got {shuffle!r}")
        self.episodes = [ep for ep in episodes if scene_id is None or ep.scene_id == scene_id]
        if not self.episodes:
            where = "" if scene_id is None else f" for scene_id {scene_id!r}"
            raise ArgumentError(f"the schedule has no episodes{where}")
        self.shuffle = bool(shuffle)
        self._rng = np.random.default_rng(seed)
        self._order: list[int] = []
        self._next = 0

    def __iter__(self) -> Iterator[PointNavEpisode]:
        return self

    def __next__(self) -> PointNavEpisode:
        if self._next == len(self._order):
            n = len(self.episodes)
            self._order = self._rng.permutation(n).tolist() if self.shuffle else list(range(n))
            self._next = 0
        episode = self.episodes[self._order[self._next]]
        self._next += 1
        return episode

    def take(self, n: int) -> list[PointNavEpisode]:
        """The next ``n`` episodes."""
        return [next(self) for _ in range(n)]


def episode_poses(
    episode: Any, scene: Scene, floor: int, robot: Any, robot_idn: int = 0
) -> tuple[tuple[float, float], tuple[float, float, float, float], tuple[float, float]]:
    """Start ``(x, y)``, start quaternion and goal ``(x, y)`` of ``episode`` for a task.

    Parameters
    ----------
    episode : PointNavEpisode
    scene : Scene
        The env's scene.
    floor : int
        The task's floor; the episode must be on it.
    robot : RobotSpec
        The robot that plays it; it must fit at the start and at the goal.
    robot_idn : int
        For error messages.

    Raises
    ------
    ValueError
        Naming the episode and the field (``scene_id``: not the scene's own
        :attr:`~pointnav_core.scenes.Scene.scene_id`, when it has one; ``info.floor``,
        ``start_position``, ``goals[0].position``) that does not suit the env.
    """
    if not isinstance(episode, PointNavEpisode):
        raise ArgumentError(f"episode must be a PointNavEpisode, got {episode!r}")
    name = f"episode {episode.episode_id!r} (scene {episode.scene_id!r})"
    here = getattr(scene, "scene_id", None)
    if here is not None and episode.scene_id != here:  # another house: its geodesics mean nothing here
        raise ArgumentError(
            f"{name}: field 'scene_id' is {episode.scene_id!r}, but the env's scene is {here!r}; "
            "play it on an env of its own scene (datasets.load_scene)"
        )
    if episode.floor != floor:
        raise ArgumentError(
            f"{name}: field 'info.floor' is {episode.floor}, but robot {robot_idn}'s task navigates "
            f"floor {floor}; build the env with task={{'floor': {episode.floor}}}"
        )
    if floor >= scene.n_floors:
        raise ArgumentError(
            f"{name}: field 'info.floor' is {floor}, but the scene has {scene.n_floors} floor(s)"
        )
    height = scene.get_floor_height(floor)
    radius = getattr(robot, "radius", robot)
    for field_name, xyz in (
        ("start_position", episode.start_position),
        ("goals[0].position", episode.goal_position),
    ):
        if not all(math.isfinite(v) for v in xyz):
            raise ArgumentError(f"{name}: field '{field_name}' must be 3 finite numbers (m), got {list(xyz)}")
        if abs(xyz[2] - height) > _HEIGHT_TOL:
            raise ArgumentError(
                f"{name}: field '{field_name}' has z = {xyz[2]} m, but floor {floor} is at {height} m"
            )
        if not scene.is_usable(floor, xyz[:2], robot):
            raise ArgumentError(
                f"{name}: field '{field_name}' {list(xyz)} is not valid for robot {robot_idn} "
                f"(radius {radius} m) on floor {floor}: off the map, on an obstacle or void, or closer "
                f"than the radius to one (the episode was made for radius {episode.robot_radius} m)"
            )
    _, _, qz, qw = episode.start_rotation
    norm = math.hypot(qz, qw)
    if not (math.isfinite(norm) and norm > 0.0):  # a NaN yaw would reach every observation
        raise ArgumentError(
            f"{name}: field 'start_rotation' must be a finite yaw quaternion "
            f"(0, 0, sin(yaw/2), cos(yaw/2)), got {list(episode.start_rotation)}"
        )
    return episode.start_xy, (0.0, 0.0, qz / norm, qw / norm), episode.goal_xy
