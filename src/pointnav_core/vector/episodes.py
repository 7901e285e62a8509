"""Start/goal pools prepared ahead: episodes drawn by the single env's own sampler.

Each scene gets ``pool_size`` episodes, sampled by a :class:`~pointnav_core.env.PointNavEnv`
of that scene (the same rules: usable start, reachable goal, ``path_range``), each with its
goal field settled into a :class:`~pointnav_core.vector.fields.FieldTables`. An autoreset
draws from the pool, so no reset ever samples or plans during a batched step.

Settling a goal field costs seconds; a start costs next to nothing once its goal's field is
settled. With ``starts > 1`` each sampled goal gets ``starts - 1`` more starts, drawn by
the single env's sampler with that goal fixed (``sampling.sample_episode``: a usable start
within reach, a random heading, the geodesic in ``path_range``), all sharing its field.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from pointnav_core import validation
from pointnav_core.vector.fields import FieldTables
from pointnav_core.vector.xp import Arrays

__all__ = ["EpisodePool", "fixed_pose"]


def fixed_pose(where: str, episode: Any, scene: Any, floor: int, robot: Any) -> tuple[Any, float, Any]:
    """One robot's fixed episode for the batched engines, checked as the single env checks it.

    Parameters
    ----------
    where : str
        Names the episode in errors (``options['episodes'][i]``).
    episode : (start_xy, yaw, goal_xy) or PointNavEpisode
        A start and goal (m) and a finite yaw (rad), or a dataset episode: then its
        ``scene_id``, floor, heights, start and goal are checked against ``scene`` by
        :func:`~pointnav_core.datasets.playback.episode_poses`, as the single env does.
    scene, floor, robot
        The world's scene, the task's floor and the robot (its radius).

    Returns
    -------
    (start_xy, yaw, goal_xy)

    Raises
    ------
    ValueError
        Naming ``where`` (or the dataset episode) and what is wrong.
    """
    from pointnav_core.datasets.format import PointNavEpisode
    from pointnav_core.datasets.playback import episode_poses

    if isinstance(episode, PointNavEpisode):
        start, quat, goal = episode_poses(episode, scene, floor, robot)
        return start, 2.0 * math.atan2(quat[2], quat[3]), goal
    try:
        start, yaw, goal = episode
    except (TypeError, ValueError):
        raise ValueError(f"{where} must be a (start_xy, yaw, goal_xy) tuple or a PointNavEpisode, got {episode!r}") from None
    yaw = validation.real(f"{where}: yaw", yaw, unit="rad")
    for name, xy in (("start", start), ("goal", goal)):
        point = validation.vector(f"{where}: {name}", xy, sizes=(2, 3))[:2]
        if not scene.is_usable(floor, point, robot):
            raise ValueError(f"{where}: {name} {list(xy)} is not usable by the robot")
    return start, yaw, goal


class EpisodePool:
    """Episodes as arrays: start ``(sx, sy, syaw)``, goal ``(gx, gy)``, ``d0`` (m), scene and field.

    Parameters
    ----------
    samplers : sequence of PointNavEnv
        One per scene, with the task to sample.
    scene_ids : sequence of int
        For each sampler, its scene index.
    pool_size : int
        Goals per scene.
    seeds : sequence of int
        ``pool_size * len(samplers)`` reset seeds, sampler by sampler.
    fixed : sequence of (start_xy, yaw, goal_xy, scene index), optional
        Given episodes, added after the sampled ones.
    arrays : Arrays
    starts : int
        Episodes per sampled goal (>= 1), sharing its goal field.
    reach : float
        How far (m) a robot gets from its start in one episode: each field keeps the cells
        within it of its episodes' starts (:class:`~pointnav_core.vector.fields.FieldTables`).

    Attributes
    ----------
    field : array of int
        Each episode's goal field in :attr:`fields`.
    pool_size : int
        Episodes per scene (``pool_size * starts``).
    """

    def __init__(
        self,
        samplers: Sequence[Any],
        pool_size: int,
        seeds: Sequence[int],
        arrays: Arrays,
        fixed: Sequence[tuple[Any, float, Any, int]] = (),
        starts: int = 1,
        reach: float = math.inf,
    ) -> None:
        from pointnav_core.sampling import sample_episode

        rows, fields, field_of = [], [], []
        k = 0
        for s, env in enumerate(samplers):
            for _ in range(pool_size):
                env.reset(seed=int(seeds[k]))
                k += 1
                task = env.task
                x, y, yaw = env.backend._pose(env.backend._robots[task.robot_idn])
                gx, gy = task.goal_xy
                rows.append((x, y, yaw, gx, gy, task.geodesic_dist, s))
                field_of.append(len(fields))
                cfg = task._config
                for _ in range(starts - 1):
                    ep = sample_episode(
                        env, robot_idn=cfg.robot_idn, floor=cfg.floor, spec=env.robot,
                        floor_height=task._floor_height, initial_pos=None, initial_quat=None,
                        goal_pos=(gx, gy), goal_tolerance=cfg.goal_tolerance, path_range=cfg.path_range,
                        max_trials=task.max_trials,
                    )
                    qz, qw = ep.start_quat[2], ep.start_quat[3]
                    rows.append((ep.start_xy[0], ep.start_xy[1], 2.0 * np.arctan2(qz, qw), gx, gy, ep.geodesic, s))
                    field_of.append(len(fields))
                fields.append(task._goal_field.field)
        for start, yaw, goal, s in fixed:
            env = samplers[s]
            ffield = env.scene.goal_field(env.task.floor, goal, robot=env.robot)
            d0 = ffield.exact_distance(start)
            rows.append((float(start[0]), float(start[1]), float(yaw), float(goal[0]), float(goal[1]), d0, s))
            field_of.append(len(fields))
            fields.append(ffield.field)
        table = np.array(rows, dtype=np.float64).reshape(-1, 7)
        a = arrays
        self.sx, self.sy, self.syaw, self.gx, self.gy, self.d0 = (a.asarray(table[:, i]) for i in range(6))
        self.scene = a.asarray(table[:, 6], a.i64)
        self.field = a.asarray(field_of, a.i64)
        field_index = np.asarray(field_of, dtype=np.int64)
        per_field = [table[field_index == f, :2] for f in range(len(fields))]
        self.fields = FieldTables(fields, arrays, per_field, reach)
        self.pool_size = pool_size * starts
        self.n_sampled = self.pool_size * len(samplers)

    def __len__(self) -> int:
        return int(self.sx.shape[0])
