"""Episode pools for several robots per world, drawn by the multi-robot env's own reset.

Each scene gets ``pool_size`` episodes of ``n_robots`` robots, sampled by a
:class:`~pointnav_core.envs.multi_pointnav.MultiPointNavEnv` of that scene on the kinematic backend,
so its rules hold: starts that do not overlap, goals kept
:func:`~pointnav_core.envs.fleet.goal_separation` apart, the derived ``path_range``. Every
robot's goal field is settled into one :class:`~pointnav_core.vector.fields.FieldTables`
(``field[episode, robot]`` is its entry).

With ``starts > 1`` each sampled episode gets ``starts - 1`` more sets of starts for the
same goals (and goal fields), drawn robot by robot in the multi-robot env's reset order by
its sampler with the goal fixed (``sampling.sample_episode``: a start usable and clear of
the robots placed before it, a random heading, the geodesic in ``path_range``).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from pointnav_core.errors import ArgumentError
from pointnav_core.vector.episodes import (
    ScenePart,
    assemble_parts,
    fixed_pose,
    pool_parts,
    sampler_field,
    settle_part,
)
from pointnav_core.vector.xp import Arrays

__all__ = ["FleetEpisode", "FleetPool", "check_fixed_episode"]

#: One robot's fixed episode: start ``(x, y)`` (m), yaw (rad), goal ``(x, y)`` (m).
FleetEpisode = tuple[Any, float, Any]


def check_fixed_episode(sampler: Any, episode: Sequence[FleetEpisode], where: str) -> list[tuple[Any, float, Any]]:
    """One world's fixed robots, checked by the multi-robot env's rules; ValueError naming ``where``.

    Each start and goal must be usable by its robot, starts at least the sum of the two
    robots' radii apart and goals :func:`~pointnav_core.envs.fleet.goal_separation` apart.
    """
    n = len(sampler.tasks)
    try:
        entries = list(episode)
    except TypeError:
        raise ArgumentError(f"{where} must hold {n} (start_xy, yaw, goal_xy) tuples or PointNavEpisodes, got {episode!r}") from None
    if len(entries) != n:
        raise ArgumentError(f"{where} must hold one (start_xy, yaw, goal_xy) per robot ({n}), got {len(entries)}")
    scene, floor, specs = sampler.scene, sampler.tasks[0].floor, sampler.robots
    robots = [fixed_pose(f"{where}[{r}]", entry, scene, floor, specs[r]) for r, entry in enumerate(entries)]
    sep = sampler.separation
    for i in range(n):
        for j in range(i + 1, n):
            (si, _, gi), (sj, _, gj) = robots[i], robots[j]
            if math.dist(si[:2], sj[:2]) < specs[i].radius + specs[j].radius:
                raise ArgumentError(f"{where}: robots {i} and {j} start overlapping ({math.dist(si[:2], sj[:2]):.3g} m apart)")
            if math.dist(gi[:2], gj[:2]) < sep[i][j]:
                raise ArgumentError(
                    f"{where}: robots {i} and {j} have goals {math.dist(gi[:2], gj[:2]):.3g} m apart, "
                    f"closer than the multi-robot env's {sep[i][j]:.3g} m"
                )
    return robots


class FleetPool:
    """Episodes of ``n_robots`` robots as ``(episodes, n_robots)`` arrays.

    Attributes ``sx, sy, syaw`` (start, m and rad), ``gx, gy`` (goal, m), ``d0`` (the
    start's geodesic distance, m; inf if unreachable), ``fields`` and ``field`` (each
    robot's entry in ``fields``), all ``(episodes, n_robots)`` but ``fields``. The first
    ``pool_size * starts * len(samplers)`` episodes are sampled, scene by scene (each
    goal set's extra starts right after it); fixed ones follow, and ``pool_size`` counts
    the sampled episodes per scene (``pool_size * starts``).

    Parameters
    ----------
    samplers : sequence of MultiPointNavEnv
        One per scene (kinematic backend), with the robots and tasks to sample.
    pool_size : int
        Episodes per scene.
    seeds : sequence of int
        ``pool_size * len(samplers)`` reset seeds, sampler by sampler.
    arrays : Arrays
    fixed : sequence of (robots, scene index)
        Given episodes (``robots`` as :func:`check_fixed_episode` returns them).
    starts : int
        Sets of starts per sampled set of goals (>= 1), sharing its goal fields.
    reach : float
        How far (m) a robot gets from its start in one episode: each field keeps the cells
        within it of its robots' starts (:class:`~pointnav_core.vector.fields.FieldTables`).
    """

    def __init__(
        self,
        samplers: Sequence[Any],
        pool_size: int,
        seeds: Sequence[int],
        arrays: Arrays,
        fixed: Sequence[tuple[Sequence[tuple[Any, float, Any]], int]] = (),
        starts: int = 1,
        reach: float = math.inf,
        parts: Sequence[ScenePart] | None = None,
    ) -> None:
        n_robots = len(samplers[0].tasks)
        parts = pool_parts(type(self), samplers, pool_size, seeds, starts, reach, fixed, parts, _fixed_part)
        table, field_index, self.fields = assemble_parts(parts, arrays, functools.partial(sampler_field, list(samplers)))
        table = table.reshape(-1, n_robots, 6)
        a = arrays
        self.sx, self.sy, self.syaw, self.gx, self.gy, self.d0 = (a.asarray(table[..., i]) for i in range(6))
        self.field = a.asarray(field_index.reshape(-1, n_robots), a.i64)
        self.pool_size = pool_size * starts
        self.n_sampled = self.pool_size * len(samplers)
        self.n_robots = n_robots

    @staticmethod
    def scene_part(env: Any, s: int, pool_size: int, seeds: Sequence[int], starts: int = 1, reach: float = math.inf,
                   cells_before: int = 0, goals_before: int = 0, lazy: bool = False,
                   portable: bool = False) -> ScenePart:
        """Scene ``s``'s part: ``pool_size`` episodes drawn by its multi-robot env ``env``
        from ``seeds``, each with ``starts`` sets of starts, every robot's field settled."""
        rows: list[list[tuple[float, ...]]] = []
        fields = []
        field_of: list[list[int]] = []
        backend = env.backend
        for seed in seeds:
            env.reset(seed=int(seed))
            episode = []
            field_of.extend([[len(fields) + i for i in range(len(env.tasks))]] * starts)
            for i, task in enumerate(env.tasks):
                x, y, yaw = backend.planar_pose(i)
                gx, gy = task.goal_xy
                episode.append((x, y, yaw, gx, gy, task.geodesic_dist))
                fields.append(task.goal_field.field)
            rows.append(episode)
            rows.extend(_more_starts(env, [row[3:5] for row in episode]) for _ in range(starts - 1))
        n_robots = len(env.tasks)
        table = np.array(rows, dtype=np.float64).reshape(-1, n_robots, 6)
        index = np.array(field_of, dtype=np.int64).reshape(-1, n_robots)
        origins = [(s, i % n_robots) for i in range(len(fields))] if portable else None
        return settle_part(table, index, fields, reach, cells_before, goals_before, lazy, origins)

    def __len__(self) -> int:
        return int(self.sx.shape[0])


def _more_starts(env: Any, goals: Sequence[tuple[float, float]]) -> list[tuple[float, ...]]:
    """One more set of starts for ``goals`` (one per robot), by ``env``'s own sampler: the
    robots are placed one by one in its reset order, each clear of those placed before."""
    from pointnav_core.task.sampling import sample_episode

    env.backend.reset()  # every robot unplaced: none blocks until it lands
    rows: dict[int, tuple[float, ...]] = {}
    for i in env.reset_order:
        task = env.tasks[i]
        cfg = task.config
        gx, gy = goals[i]
        ep = sample_episode(
            env, robot_idn=cfg.robot_idn, floor=cfg.floor, spec=env.robots[i], floor_height=task.floor_height,
            initial_pos=None, initial_quat=None, goal_pos=(gx, gy), goal_tolerance=cfg.goal_tolerance,
            path_range=cfg.path_range, max_trials=task.max_trials,
        )
        yaw = 2.0 * math.atan2(ep.start_quat[2], ep.start_quat[3])
        rows[i] = (float(ep.start_xy[0]), float(ep.start_xy[1]), yaw, gx, gy, ep.geodesic)
    return [rows[i] for i in range(len(env.tasks))]


def _fixed_part(samplers: Sequence[Any], fixed: Sequence[tuple[Sequence[tuple[Any, float, Any]], int]], reach: float,
                before: Sequence[ScenePart]) -> ScenePart:
    """The given episodes' part: each robot with the goal field of its own radius, as its task reads it."""
    rows, fields = [], []
    for robots, s in fixed:
        env = samplers[s]
        episode = []
        for i, (start, yaw, goal) in enumerate(robots):
            field = env.scene.goal_field(env.tasks[0].floor, goal, robot=env.robots[i])
            episode.append((float(start[0]), float(start[1]), yaw, float(goal[0]), float(goal[1]), field.exact_distance(start)))
            fields.append(field.field)
        rows.append(episode)
    n_robots = len(samplers[0].tasks)
    table = np.array(rows, dtype=np.float64).reshape(-1, n_robots, 6)
    index = np.arange(len(fields), dtype=np.int64).reshape(-1, n_robots)
    cells, goals = sum(p.cells for p in before), sum(len(p.fields) for p in before)
    return settle_part(table, index, fields, reach, cells, goals, lazy=True)
