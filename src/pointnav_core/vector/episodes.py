"""Start/goal pools prepared ahead: episodes drawn by the single env's own sampler.

Each scene gets ``pool_size`` episodes, sampled by a :class:`~pointnav_core.env.PointNavEnv`
of that scene (the same rules: usable start, reachable goal, ``path_range``), each with its
goal field settled into a :class:`~pointnav_core.vector.fields.FieldTables`. An autoreset
draws from the pool, so no reset ever samples or plans during a batched step.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from pointnav_core.vector.fields import FieldTables
from pointnav_core.vector.xp import Arrays

__all__ = ["EpisodePool"]


class EpisodePool:
    """Episodes as arrays: start ``(sx, sy, syaw)``, goal ``(gx, gy)``, ``d0`` (m), scene and field.

    Parameters
    ----------
    samplers : sequence of PointNavEnv
        One per scene, with the task to sample.
    scene_ids : sequence of int
        For each sampler, its scene index.
    pool_size : int
        Episodes per scene.
    seeds : sequence of int
        ``pool_size * len(samplers)`` reset seeds, sampler by sampler.
    fixed : sequence of (start_xy, yaw, goal_xy, scene index), optional
        Given episodes, added after the sampled ones.
    arrays : Arrays
    """

    def __init__(
        self,
        samplers: Sequence[Any],
        pool_size: int,
        seeds: Sequence[int],
        arrays: Arrays,
        fixed: Sequence[tuple[Any, float, Any, int]] = (),
    ) -> None:
        rows, fields = [], []
        k = 0
        for s, env in enumerate(samplers):
            for _ in range(pool_size):
                env.reset(seed=int(seeds[k]))
                k += 1
                task = env.task
                x, y, yaw = env.backend._pose(env.backend._robots[task.robot_idn])
                gx, gy = task.goal_xy
                rows.append((x, y, yaw, gx, gy, task.geodesic_dist, s))
                fields.append(task._goal_field.field)
        for start, yaw, goal, s in fixed:
            env = samplers[s]
            ffield = env.scene.goal_field(env.task.floor, goal, robot=env.robot)
            d0 = ffield.exact_distance(start)
            rows.append((float(start[0]), float(start[1]), float(yaw), float(goal[0]), float(goal[1]), d0, s))
            fields.append(ffield.field)
        table = np.array(rows, dtype=np.float64).reshape(-1, 7)
        a = arrays
        self.sx, self.sy, self.syaw, self.gx, self.gy, self.d0 = (a.asarray(table[:, i]) for i in range(6))
        self.scene = a.asarray(table[:, 6], a.i64)
        self.fields = FieldTables(fields, arrays)
        self.n_sampled = pool_size * len(samplers)
        self.pool_size = pool_size

    def __len__(self) -> int:
        return int(self.sx.shape[0])
