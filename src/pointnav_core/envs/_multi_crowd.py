"""The pedestrians of a multi-robot env: one crowd beside every robot.

:class:`FleetCrowd` is what :class:`~pointnav_core.envs.multi_pointnav.MultiPointNavEnv`
keeps for ``pedestrians={...}``: the crowd walks on the first robot's floor beside every
robot present there (each seen, with ``sees_robots``), and each robot's contacts, count and
social metrics are its own, as in the single env (:mod:`pointnav_core.crowds`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from typing import Any

from pointnav_core.envs import _crowd

__all__ = ["FleetCrowd", "episode_fleet", "reset_fleet"]


class FleetCrowd:
    """The crowd of a multi-robot env and each robot's side of it.

    Attributes
    ----------
    crowd : Crowd
    touched : list of bool
        Whether each robot touched a pedestrian during the current action (its control steps).
    counts : list of int
        Each robot's pedestrian contact steps this episode.
    """

    def __init__(self, crowd: Any, n_robots: int) -> None:
        self.crowd = crowd
        self.n = n_robots
        self.touched = [False] * n_robots
        self.counts = [0] * n_robots
        self.tracks: list[_crowd.CrowdTrack] = []
        self.robots: _crowd.CrowdRobots | None = None

    def reset(self, env: Any, infos: list[dict[str, Any]], record: Any = None) -> None:
        """Place the crowd for new episodes (after the robots' resets, whose ``infos`` get
        their contact counts, 0): the first robot's dataset episode's recorded crowd
        ``record`` when it has one (on its floor), else drawn."""
        _crowd.spawn_crowd(env, record)
        for info in infos:
            info["pedestrian_collisions"] = 0
        self.touched = [False] * self.n
        self.counts = [0] * self.n
        self.tracks = [_crowd.CrowdTrack(env, i) for i in range(self.n)]
        self.robots = _crowd.CrowdRobots(env)

    def begin(self, env: Any) -> Callable[[], None]:
        """Start an action (no robot has touched a pedestrian yet); the call that walks the
        crowd after each of its control steps."""
        self.touched = [False] * self.n
        return functools.partial(self.step, env)

    def step(self, env: Any) -> None:
        """Move the crowd one control step beside the robots; note who touches a pedestrian."""
        ids, discs, velocities = self.robots.read(env)
        hits = self.crowd.step_contacts(1.0 / env.action_frequency, discs, velocities)
        for i, hit in zip(ids, hits.tolist()):
            self.touched[i] = self.touched[i] or hit
        for track in self.tracks:
            track.record(env, self.robots.poses[track.idn])

    def finish(self, env: Any, index: Mapping[str, int], returns: Any) -> None:
        """Add each acting robot's contact count, and its social metrics where its episode
        ended, to its info in ``returns`` (``step()``'s five dicts)."""
        _, _, terminations, truncations, infos = returns
        for agent, info in infos.items():
            i = index[agent]
            self.counts[i] += int(self.touched[i])
            info["pedestrian_collisions"] = self.counts[i]
            if terminations[agent] or truncations[agent]:
                info["social"] = self.tracks[i].metrics(env, info)


def episode_fleet(own: FleetCrowd | None, record: Any, scene: Any, n_robots: int) -> FleetCrowd | None:
    """The crowd a multi-robot env plays an episode with: its own (``own``), or, for a
    first robot's episode that records a crowd (``record``) in an env without one, a crowd
    of the default pedestrian settings, as the single env's (:func:`_crowd.episode_crowd`)."""
    if own is not None or record is None:
        return own
    return FleetCrowd(_crowd.episode_crowd(None, record, scene), n_robots)


def reset_fleet(env: Any, own: FleetCrowd | None, episode: Any, infos: list[dict[str, Any]]) -> FleetCrowd | None:
    """Place the crowd of a new episode (after the robots' resets, whose ``infos`` get their
    contact counts): the env's own (``own``) or :func:`episode_fleet`'s for the first
    robot's dataset ``episode`` (None: drawn), which becomes ``env.crowd``. Returns it."""
    record = getattr(episode, "pedestrians", None)
    fleet = episode_fleet(own, record, env.scene, len(env.tasks))
    env.crowd = None if fleet is None else fleet.crowd
    if fleet is not None:
        fleet.reset(env, infos, record)
    return fleet
