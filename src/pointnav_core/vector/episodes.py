"""Start/goal pools prepared ahead: episodes drawn by the single env's own sampler.

Each scene gets ``pool_size`` episodes, sampled by a :class:`~pointnav_core.envs.pointnav.PointNavEnv`
of that scene (the same rules: usable start, reachable goal, ``path_range``), each with its
goal field settled into a :class:`~pointnav_core.vector.fields.FieldTables`. An autoreset
draws from the pool, so no reset ever samples or plans during a batched step.

Settling a goal field costs seconds; a start costs next to nothing once its goal's field is
settled. With ``starts > 1`` each sampled goal gets ``starts - 1`` more starts, drawn by
the single env's sampler with that goal fixed (``sampling.sample_episode``: a usable start
within reach, a random heading, the geodesic in ``path_range``), all sharing its field.

A pool is built scene by scene: each scene's :class:`ScenePart` (its episodes and its goal
fields settled, as plain arrays) depends only on that scene's sampler and seeds, so the
parts can be built in worker processes (:mod:`pointnav_core.vector.pool_build`) and
assembled here into the same arrays as a build in this process.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from pointnav_core.errors import ArgumentError
from pointnav_core.utils import validation
from pointnav_core.vector.fields import (
    FieldPart,
    FieldTables,
    check_budget,
    field_part,
    reach_window,
)
from pointnav_core.vector.xp import Arrays

__all__ = ["EpisodePool", "ScenePart", "assemble_parts", "episode_reach", "fixed_pose", "sampler_field", "settle_part"]


def episode_reach(engine: Any, discrete: Any) -> float:
    """How far (m) a robot's centre can get from its start in one episode of ``engine`` (a
    batched engine, with its ``discrete`` plan or None): its steps (the most of any robot's ``max_steps``, and at most
    ``max_cycles`` with several robots) times the longest chord of a step (of each of a
    discrete action's control steps). Goal fields keep only the cells within it of their
    starts (:class:`~pointnav_core.vector.fields.FieldTables`)."""
    steps = engine.max_steps if isinstance(engine.max_steps, int) else int(engine.arrays.numpy(engine.max_steps).max())
    steps = min(steps, getattr(engine, "max_cycles", steps))
    per_step = engine.max_travel * (1 if discrete is None else discrete.max_steps)
    return steps * per_step


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
        raise ArgumentError(f"{where} must be a (start_xy, yaw, goal_xy) tuple or a PointNavEpisode, got {episode!r}") from None
    yaw = validation.real(f"{where}: yaw", yaw, unit="rad")
    for name, xy in (("start", start), ("goal", goal)):
        point = validation.vector(f"{where}: {name}", xy, sizes=(2, 3))[:2]
        if not scene.is_usable(floor, point, robot):
            raise ArgumentError(f"{where}: {name} {list(xy)} is not usable by the robot")
    return start, yaw, goal


@dataclass(frozen=True)
class ScenePart:
    """One scene's share of a pool, as plain numpy arrays (it pickles from a worker process).

    Attributes
    ----------
    table : ndarray (n, ...)
        Its episodes' rows, in the pool class's columns.
    field_of : ndarray of int64 (n, ...)
        Each episode's (each robot's) goal field, an index into :attr:`fields`.
    fields : list of FieldPart
        The goal fields, settled over their windows.
    cells : int
        The cells the fields keep (for the pool's byte budget).
    """

    table: np.ndarray
    field_of: np.ndarray
    fields: list[FieldPart]
    cells: int


def settle_part(table: np.ndarray, field_of: np.ndarray, fields: Sequence[Any], reach: float,
                cells_before: int = 0, goals_before: int = 0, lazy: bool = False,
                origins: Sequence[tuple[int, int]] | None = None) -> ScenePart:
    """Settle ``fields`` (GoalFields) over the cells within ``reach`` (m) of their episodes'
    starts (the first two columns of ``table``'s rows); with ``lazy``, keep the fields to
    settle their cells on the first lookups instead, or with ``origins`` (per field its
    scene and robot, in a worker) what makes each field again in the stepping process.

    Raises
    ------
    ValueError
        Before any field is settled, when the windows after ``cells_before`` cells of
        ``goals_before`` goals (the parts built before) pass the byte budget
        (:func:`~pointnav_core.vector.fields.check_budget`).
    """
    windows = [reach_window(f, table[field_of == i][:, :2], reach) for i, f in enumerate(fields)]
    check_budget(windows, cells_before, goals_before)
    parts = [field_part(f, w, lazy, None if origins is None else origins[i]) for i, (f, w) in enumerate(zip(fields, windows))]
    return ScenePart(table, field_of, parts, sum((r1 - r0) * (c1 - c0) for r0, r1, c0, c1 in windows))


def assemble_parts(parts: Sequence[ScenePart], arrays: Arrays,
                   resolve: Callable[..., Any] | None = None) -> tuple[np.ndarray, np.ndarray, FieldTables]:
    """The parts end to end: their rows, each row's field (a global index) and the tables
    (with ``resolve``, :attr:`FieldTables.resolve`, for parts built in workers)."""
    offsets = np.cumsum([0, *(len(p.fields) for p in parts)])
    table = np.concatenate([p.table for p in parts])
    field_of = np.concatenate([p.field_of + off for p, off in zip(parts, offsets)]).astype(np.int64)
    check_budget([], sum(p.cells for p in parts), int(offsets[-1]))
    tables = FieldTables.from_parts([f for p in parts for f in p.fields], arrays)
    tables.resolve = resolve
    return table, field_of, tables


def sampler_field(samplers: Sequence[Any], origin: tuple[int, int], goal: tuple[float, float]) -> Any:
    """The goal field of ``goal`` (m) for robot ``origin[1]`` of scene ``origin[0]``'s
    sampler (a single or a multi-robot env), as its task builds it: the field a worker
    built, made again here (the floor's geometry reloads from the disk cache)."""
    env = samplers[origin[0]]
    tasks = getattr(env, "tasks", None)
    if tasks is None:
        return env.scene.goal_field(env.task.floor, goal, robot=env.robot).field
    return env.scene.goal_field(tasks[origin[1]].floor, goal, robot=env.robots[origin[1]]).field


class EpisodePool:
    """Episodes as arrays: start ``(sx, sy, syaw)``, goal ``(gx, gy)``, ``d0`` (m), scene and field.

    Parameters
    ----------
    samplers : sequence of PointNavEnv
        One per scene, with the task to sample.
    pool_size : int
        Goals per scene.
    seeds : sequence of int
        ``pool_size * len(samplers)`` reset seeds, sampler by sampler.
    arrays : Arrays
    fixed : sequence of (start_xy, yaw, goal_xy, scene index), optional
        Given episodes, added after the sampled ones.
    starts : int
        Episodes per sampled goal (>= 1), sharing its goal field.
    reach : float
        How far (m) a robot gets from its start in one episode: each field keeps the cells
        within it of its episodes' starts (:class:`~pointnav_core.vector.fields.FieldTables`).
    parts : sequence of ScenePart, optional
        The scenes' parts, built already (by :meth:`scene_part`, in worker processes);
        default: built here, scene by scene.

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
        parts: Sequence[ScenePart] | None = None,
    ) -> None:
        parts = pool_parts(type(self), samplers, pool_size, seeds, starts, reach, fixed, parts)
        table, field_of, self.fields = assemble_parts(parts, arrays, functools.partial(sampler_field, list(samplers)))
        a = arrays
        self.sx, self.sy, self.syaw, self.gx, self.gy, self.d0 = (a.asarray(table[:, i]) for i in range(6))
        self.scene = a.asarray(table[:, 6], a.i64)
        self.field = a.asarray(field_of, a.i64)
        self.pool_size = pool_size * starts
        self.n_sampled = self.pool_size * len(samplers)

    @staticmethod
    def scene_part(env: Any, s: int, pool_size: int, seeds: Sequence[int], starts: int = 1, reach: float = math.inf,
                   cells_before: int = 0, goals_before: int = 0, lazy: bool = False,
                   portable: bool = False) -> ScenePart:
        """Scene ``s``'s part: ``pool_size`` episodes drawn by its sampler ``env`` from
        ``seeds`` (one per goal), each goal with ``starts`` starts, its fields settled (or
        left to settle lazily, in this process or, ``portable``, in the one it is sent to:
        :func:`settle_part`)."""
        from pointnav_core.task.sampling import sample_episode

        rows, fields, field_of = [], [], []
        for seed in seeds:
            env.reset(seed=int(seed))
            task = env.task
            x, y, yaw = env.backend.planar_pose(task.robot_idn)
            gx, gy = task.goal_xy
            rows.append((x, y, yaw, gx, gy, task.geodesic_dist, s))
            field_of.append(len(fields))
            cfg = task.config
            for _ in range(starts - 1):
                ep = sample_episode(
                    env, robot_idn=cfg.robot_idn, floor=cfg.floor, spec=env.robot,
                    floor_height=task.floor_height, initial_pos=None, initial_quat=None,
                    goal_pos=(gx, gy), goal_tolerance=cfg.goal_tolerance, path_range=cfg.path_range,
                    max_trials=task.max_trials,
                )
                qz, qw = ep.start_quat[2], ep.start_quat[3]
                rows.append((ep.start_xy[0], ep.start_xy[1], 2.0 * np.arctan2(qz, qw), gx, gy, ep.geodesic, s))
                field_of.append(len(fields))
            fields.append(task.goal_field.field)
        table = np.array(rows, dtype=np.float64).reshape(-1, 7)
        origins = [(s, 0)] * len(fields) if portable else None
        return settle_part(table, np.asarray(field_of, dtype=np.int64), fields, reach, cells_before, goals_before, lazy,
                           origins)

    def __len__(self) -> int:
        return int(self.sx.shape[0])


def build_in_process(kind: Any, samplers: Sequence[Any], pool_size: int, seeds: Sequence[int], starts: int,
                     reach: float, done: Callable[[int], Any] | None = None, lazy: bool = False) -> list[ScenePart]:
    """Every scene's part of a pool of ``kind`` (a class with ``scene_part``), here, in
    order; the byte budget is checked before each scene's fields are settled. ``done(1)``
    is called after each scene (a progress bar's ``update``); ``lazy``: see :func:`settle_part`."""
    parts: list[ScenePart] = []
    cells = goals = 0
    for s, env in enumerate(samplers):
        part = kind.scene_part(env, s, pool_size, seeds[s * pool_size:(s + 1) * pool_size], starts, reach, cells, goals,
                               lazy)
        cells, goals = cells + part.cells, goals + len(part.fields)
        parts.append(part)
        if done is not None:
            done(1)
    return parts


def pool_parts(kind: Any, samplers: Sequence[Any], pool_size: int, seeds: Sequence[int], starts: int, reach: float,
               fixed: Sequence[Any], parts: Sequence[ScenePart] | None,
               fixed_part: Callable[..., ScenePart] | None = None) -> list[ScenePart]:
    """A pool's parts: ``parts`` (built ahead, e.g. in workers) or every scene's built here,
    then the part of the ``fixed`` episodes, if any, made by ``fixed_part`` (default: one
    robot's; both pool kinds share this)."""
    parts = list(parts) if parts is not None else build_in_process(kind, samplers, pool_size, seeds, starts, reach)
    if fixed:
        parts.append((fixed_part or _fixed_part)(samplers, fixed, reach, parts))
    return parts


def _fixed_part(samplers: Sequence[Any], fixed: Sequence[tuple[Any, float, Any, int]], reach: float,
                before: Sequence[ScenePart]) -> ScenePart:
    """The given episodes' part: each with the goal field of its scene's sampler."""
    rows, fields = [], []
    for start, yaw, goal, s in fixed:
        env = samplers[s]
        ffield = env.scene.goal_field(env.task.floor, goal, robot=env.robot)
        d0 = ffield.exact_distance(start)
        rows.append((float(start[0]), float(start[1]), float(yaw), float(goal[0]), float(goal[1]), d0, s))
        fields.append(ffield.field)
    table = np.array(rows, dtype=np.float64).reshape(-1, 7)
    cells, goals = sum(p.cells for p in before), sum(len(p.fields) for p in before)
    return settle_part(table, np.arange(len(rows), dtype=np.int64), fields, reach, cells, goals, lazy=True)
