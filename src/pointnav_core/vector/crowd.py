"""The pedestrians of a batch of worlds, stepped as arrays: each world's crowd is a single env's.

:class:`VectorCrowd` keeps every world's pedestrians in ``(W, P, ...)`` arrays (a world with
fewer pedestrians than ``P`` uses its first rows). Each world's crowd is exactly the one a
:class:`~pointnav_core.envs.pointnav.PointNavEnv` would walk beside the same robot, by one
definition for both engines:

- **Placing.** An episode's crowd is placed once, the first time a world starts it, by the
  single env's :meth:`Crowd.spawn <pointnav_core.crowds.Crowd.spawn>` on that episode's
  scene beside its robot's start: drawn from a generator seeded with ``(engine seed, pool
  generation, episode)``, or exactly the crowd a dataset episode records. Every later start
  of the episode gathers the placed crowd (:meth:`Crowd.start
  <pointnav_core.crowds.Crowd.start>`) as arrays. :meth:`VectorCrowd.record` gives a world's
  crowd as a dataset episode stores it, which a single env places again exactly.
- **Stepping.** One compiled call per scene steps all its worlds
  (``crowds._crowd_kernel.orca_crowd_worlds``), which runs the single env's compiled step
  (``orca_crowd_step``) world by world: the same floats.
- **Planning.** A pedestrian that arrives or is blocked plans again with
  :func:`~pointnav_core.crowds.walks.plan_walk`, the single env's planner, drawing from its
  own generator (``numpy.random.default_rng(seed)``). These plans
  are the step's events, as an arrival is in the single env: the exact search is per
  pedestrian by nature, so they run one by one, and only for the pedestrians that need one.
  Each pedestrian's own generator is made at its first plan, where the placing left it.

Several robots per world walk beside one crowd, as in the multi-robot env: it avoids every
robot present (with ``sees_robots``), and each robot's contacts are its own. With discrete
actions the crowd walks each control step of an action, as in the single env. Only ORCA
and ``"static"`` crowds, on numpy with numba (the ``fast`` extra); the scan sees them and
the local map marks them (code 4), as the single env's; the rest is refused by
:func:`check_vector_pedestrians` (docs/decisions.md, "Crowds in the batched engine").
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.crowds.config import PedestrianConfig
from pointnav_core.crowds.crowd import GOAL_REACHED, KERNEL, Crowd, CrowdStart
from pointnav_core.crowds.walks import Walk, padded, plan_walk
from pointnav_core.errors import ArgumentError
from pointnav_core.utils.compiled import kernel

__all__ = ["PROGRESS_CROWDS", "VectorCrowd", "check_vector_pedestrians", "crowd_map_high", "recorded_crowds"]

#: Crowds placed at once from which a progress bar shows (each takes its pedestrians' plans,
#: about 5-10 ms for 10 pedestrians on a house).
PROGRESS_CROWDS = 64


def crowd_map_high(high: NDArray[np.float64], sensors: Any) -> NDArray[np.float64]:
    """``high``, the observation's upper bounds (the last axis), with the local map's cells
    (the observation's last ``cells * cells`` values, where ``sensors`` has one) up to a
    pedestrian's code, 4: the single env's bounds with a crowd."""
    from pointnav_core.sensors.local_map import LOCAL_PEDESTRIAN
    from pointnav_core.vector.local_map import local_map_term

    term = local_map_term(sensors)
    if term is None:
        return high
    out = np.array(high, dtype=high.dtype)
    out[..., -term.size:] = np.maximum(out[..., -term.size:], LOCAL_PEDESTRIAN)
    return out


def check_vector_pedestrians(config: PedestrianConfig | None, device: str) -> None:
    """Refuse, naming ``pedestrians``, what the batched engine's crowds do not do yet."""
    if config is None:
        return
    if config.behaviour not in ("orca", "static"):
        raise ArgumentError(
            f"pedestrians['behaviour'] is {config.behaviour!r}, but the batched engine's crowds walk by 'orca' "
            f"or 'static' only: use PointNavEnv or parallel_env for the others"
        )
    if device != "numpy":
        raise ArgumentError(f"pedestrians need device='numpy' in the batched engine, got device={device!r}")
    if kernel(*KERNEL) is None:
        raise ArgumentError("pedestrians in the batched engine need numba (pip install 'pointnav-core[fast]')")


def recorded_crowds(engine: Any, recorded: dict[int, Any]) -> None:
    """Hand the crowds that fixed episodes record (pool index -> a dataset episode's
    ``pedestrians`` or None) to ``engine``'s crowd; ValueError naming the episode when
    one records a crowd and the engine has none (a single env would walk it with the
    default settings; here the engine's settings must be given)."""
    crowd = engine.crowd
    given = {e: tuple(r) for e, r in recorded.items() if r is not None}
    if crowd is None:
        if given:
            e = min(given)
            raise ArgumentError(
                f"options['episodes'][{e - engine.pool.n_sampled}] records a crowd, but this engine was built "
                f"without pedestrians: pass pedestrians={{...}} (e.g. {{'count': {len(given[e])}}})"
            )
        return
    crowd.record_episodes(given)


class VectorCrowd:
    """Every world's pedestrians (see the module notes).

    Parameters
    ----------
    config : PedestrianConfig
    scenes : sequence of Scene
        The engine's scenes.
    floor : int
        The floor the robots navigate.
    world_scene : ndarray of int, shape (W,)
        Each world's scene.
    robot_radius : ndarray, shape (R,)
        Each robot's radius (m), the same in every world.
    progress : bool, optional
        A tqdm bar on stderr while crowds are placed; default: from :data:`PROGRESS_CROWDS`
        at once (a first reset over many scenes), on a terminal.

    Attributes
    ----------
    positions, velocities : ndarray, shape (W, P, 2)
        Centres (m) and velocities (m/s) after the last step.
    headings, radius, speed : ndarray, shape (W, P)
        Walking directions (rad), disc radii (m), preferred speeds (m/s).
    count : ndarray of int, shape (W,)
        Each world's pedestrians (its first rows).
    collisions : ndarray of int, shape (W, R)
        Steps of each robot's episode on which it touched a pedestrian while acting.
    """

    def __init__(self, config: PedestrianConfig, scenes: Sequence[Any], floor: int, world_scene: NDArray[np.int64],
                 robot_radius: NDArray[np.float64], progress: bool | None = None) -> None:
        self.config, self.progress = config, progress
        self.scenes, self.floor = list(scenes), int(floor)
        self.robot_radius = np.asarray(robot_radius, dtype=np.float64).reshape(-1)
        self._crowds = [Crowd(config, scene) for scene in scenes]  # each scene's placer
        self.world_scene = np.asarray(world_scene, dtype=np.int64)
        self._groups = [np.flatnonzero(self.world_scene == s) for s in range(len(scenes))]
        self._seed, self._generation = 0, 0
        self._pool: Any = None
        self._starts: list[CrowdStart] = []
        self._stack: dict[str, Any] | None = None  # the placed crowds as arrays (_stacked)
        self._slot_of = np.zeros(0, np.int64)
        self._recorded: dict[int, Any] = {}
        self._resize(len(self.world_scene), 0, 1)
        self.count = np.zeros(len(self.world_scene), dtype=np.int64)
        self.collisions = np.zeros((len(self.world_scene), len(self.robot_radius)), dtype=np.int64)
        #: Whether each robot touched a pedestrian in the current env step (:meth:`begin`).
        self.touched = np.zeros(self.collisions.shape, dtype=np.bool_)
        self._present: NDArray[np.bool_] | None = None
        #: Called after each control step with the robots' motion and the worlds that stepped
        #: (:class:`~pointnav_core.vector.social.SocialTracker` records there).
        self.listeners: list[Any] = []
        self._start = np.empty(len(self.world_scene), dtype=object)  # each world's CrowdStart

    @classmethod
    def for_engine(cls, config: PedestrianConfig | None, engine: Any, robot_radius: Any,
                   progress: bool | None) -> VectorCrowd | None:
        """The crowds of a batched ``engine`` (its scenes, floor and worlds) for ``config``,
        or None without one."""
        if config is None:
            return None
        world_scene = engine.arrays.numpy(engine.world_scene)
        return cls(config, engine.scenes, engine.task.floor, world_scene, robot_radius, progress)

    def _resize(self, w: int, p: int, length: int) -> None:
        """Zeroed state arrays for ``w`` worlds of ``p`` pedestrians, paths of ``length`` points."""
        self.positions, self.velocities, self.goals = np.zeros((w, p, 2)), np.zeros((w, p, 2)), np.zeros((w, p, 2))
        self.headings, self.radius, self.speed = np.zeros((w, p)), np.zeros((w, p)), np.zeros((w, p))
        self._paths = np.zeros((w, p, length, 2))
        self._next, self._last = np.zeros((w, p), np.int64), np.zeros((w, p), np.int64)
        self._index = np.full((w, p), -1, np.int64)
        self._rngs = np.full((w, p), None, dtype=object)  # (W, P): each one's generator, once made

    # ------------------------------------------------------------------ placing
    def seed(self, seed: int) -> None:
        """Key the drawn crowds by ``seed`` (the engine draws it at each seeded reset)."""
        self._seed, self._pool = int(seed), None

    def record_episodes(self, records: dict[int, Any]) -> None:
        """The crowds that episodes of the pool fix (pool index -> records; a dataset
        episode's ``pedestrians``), placed as recorded from the next start on."""
        self._recorded = dict(records)
        self._pool = None

    def start_worlds(self, worlds: NDArray[np.int64], episodes: NDArray[np.int64], pool: Any) -> None:
        """Start the crowds of ``worlds`` for their pool ``episodes`` (placed at their first start)."""
        if pool is not self._pool:  # a new pool (or seed): its episodes' crowds are new ones
            self._pool, self._generation = pool, self._generation + 1
            self._starts, self._stack = [], None
            self._slot_of = np.full(len(pool), -1, np.int64)  # each pool episode's slot, once placed
        missing = self._slot_of[episodes] < 0
        if missing.any():
            from tqdm.auto import tqdm

            new, first = np.unique(episodes[missing], return_index=True)
            owners = worlds[missing][first]  # (an episode is of its world's scene)
            # None: tqdm's own choice (a terminal only) from PROGRESS_CROWDS crowds on.
            show = self.progress
            disable = (None if len(new) >= PROGRESS_CROWDS else True) if show is None else not show
            for e, w in tqdm(zip(new.tolist(), owners.tolist()), total=len(new), desc="placing crowds", unit="crowd",
                             disable=disable):
                self._slot_of[e] = self._place(pool, e, int(self.world_scene[w]))
        self._gather(worlds, self._slot_of[episodes])

    def _place(self, pool: Any, e: int, s: int) -> int:
        """Place episode ``e``'s crowd with scene ``s``'s single-env crowd, beside its robots'
        starts; its slot."""
        rng = np.random.default_rng([self._seed, self._generation, e])
        x, y = np.asarray(pool.sx[e], dtype=np.float64).reshape(-1), np.asarray(pool.sy[e], dtype=np.float64).reshape(-1)
        robots = np.column_stack([x, y, self.robot_radius])
        self._crowds[s].spawn(self.floor, rng, robots, self._recorded.get(e))
        self._starts.append(self._crowds[s].start())
        return len(self._starts) - 1

    _STACKED = (("positions", 2), ("goals", 2), ("headings", 0), ("radius", 0), ("speed", 0), ("next", 0),
                ("last", 0), ("goal_index", 0))

    def _stacked(self) -> dict[str, Any]:
        """The placed crowds stacked, slot by slot, room for all the pool's episodes (padded
        to the most pedestrians and the longest path): the crowds placed since the last
        call are written in, and the table widened only when one is larger."""
        starts, t = self._starts, self._stack
        done = 0 if t is None else t["done"]
        if t is not None and done == len(starts):
            return t
        p = max([len(st.radius) for st in starts] + ([t["radius"].shape[1]] if t else []))
        length = max([st.paths.shape[1] for st in starts[done:]] + ([t["paths"].shape[2]] if t else []))
        rows = max(len(starts), 0 if t is None else len(t["count"]), len(self._pool) + self.world_scene.shape[0])
        if t is None or p > t["radius"].shape[1] or length > t["paths"].shape[2] or rows > len(t["count"]):
            new = {"done": 0, "count": np.zeros(rows, np.int64), "start": np.empty(rows, dtype=object),
                   "paths": np.zeros((rows, p, length, 2))}
            for name, dim in self._STACKED:
                dtype = np.int64 if name in ("next", "last", "goal_index") else np.float64
                new[name] = np.zeros((rows, p, dim) if dim else (rows, p), dtype)
            self._stack = t = new  # written whole again: rare
            done = 0
        for k in range(done, len(starts)):
            st, m = starts[k], len(starts[k].radius)
            t["count"][k], t["start"][k] = m, st  # its CrowdStart: its walks and draws
            for name, _ in self._STACKED:
                t[name][k, :m] = getattr(st, name)
            t["paths"][k, :m] = padded(st.paths, t["paths"].shape[2])
        t["done"] = len(starts)
        return t

    def _gather(self, worlds: NDArray[np.int64], slots: NDArray[np.int64]) -> None:
        """Copy the placed crowds ``slots`` into ``worlds``, widening the arrays if needed."""
        t = self._stacked()
        p, length = t["radius"].shape[1], t["paths"].shape[2]
        self._widen(p, length)
        for mine, name in ((self.positions, "positions"), (self.goals, "goals"), (self.headings, "headings"),
                           (self.radius, "radius"), (self.speed, "speed"), (self._next, "next"), (self._last, "last"),
                           (self._index, "goal_index")):
            mine[worlds, :p] = t[name][slots]
        self._paths[worlds, :p] = padded(t["paths"][slots], self._paths.shape[2])
        self.velocities[worlds] = 0.0
        self.count[worlds] = t["count"][slots]
        self._start[worlds] = t["start"][slots]  # kept past a new pool's placing
        self.collisions[worlds] = 0
        self._rngs[worlds] = None  # each pedestrian's generator is made again at its first plan

    def _widen(self, p: int, length: int) -> None:
        """Room for ``p`` pedestrians a world and paths of ``length`` points."""
        w, p0, l0 = self._paths.shape[:3]
        if p <= p0 and length <= l0:
            return
        old = (self.positions, self.velocities, self.goals, self.headings, self.radius, self.speed, self._next,
               self._last, self._index, self._rngs, self._paths)
        self._resize(w, max(p, p0), max(length, l0))
        new = (self.positions, self.velocities, self.goals, self.headings, self.radius, self.speed, self._next,
               self._last, self._index, self._rngs)
        for dst, src in zip(new, old):
            dst[:, :p0] = src
        self._paths[:, :p0] = padded(old[-1], self._paths.shape[2])

    def record(self, world: int) -> tuple[Any, ...]:
        """World ``world``'s crowd as its episode placed it: the records a dataset episode
        stores (:class:`~pointnav_core.crowds.record.PedestrianRecord`), which a single
        env's reset with that episode places again exactly."""
        return self._start[world].record

    # ------------------------------------------------------------------ stepping
    def begin(self, present: NDArray[np.bool_] | None = None) -> None:
        """Start an env step, with ``present`` ``(W, R)`` the robots in the worlds (default:
        all): no robot has touched a pedestrian in it yet."""
        self.touched[:] = False
        self._present = present

    def step(self, motion: Any, dt: float, worlds: NDArray[np.bool_] | None = None) -> None:
        """Move the pedestrians of ``worlds`` (a ``(W,)`` mask, default all) one control step
        beside their robots as ``motion`` (a :class:`~pointnav_core.vector.state.Motion`,
        ``(W,)`` or ``(W, R)``) has them after theirs, of which those present (:meth:`begin`)
        are in the world; the robots touching a pedestrian after it are added to
        :attr:`touched`, and each of :attr:`listeners` is called with ``motion`` and the
        worlds that stepped."""
        x, y, vx, vy = motion.x, motion.y, motion.vx, motion.vy
        w, r, cfg, present = x.shape[0], len(self.robot_radius), self.config, self._present
        robots = np.stack([x.reshape(w, r), y.reshape(w, r), np.broadcast_to(self.robot_radius, (w, r))], -1)
        robot_vel = np.stack([vx.reshape(w, r), vy.reshape(w, r)], -1)
        present = np.ones((w, r), np.bool_) if present is None else np.asarray(present).reshape(w, r)
        order = None
        if not present.all():  # the kernel takes the robots present first (the multi-robot env's list)
            order = np.argsort(~present, axis=1, kind="stable")
            robots, robot_vel = np.take_along_axis(robots, order[..., None], 1), np.take_along_axis(robot_vel, order[..., None], 1)
        seen = present.sum(1, dtype=np.int64) if cfg.sees_robots else np.zeros(w, np.int64)
        contacts = np.zeros((w, r), dtype=np.bool_)
        stepping = np.ones(w, np.bool_) if worlds is None else np.asarray(worlds).reshape(w)
        if cfg.behaviour == "static" or not self.radius.shape[1]:
            self._touching(robots, contacts)
        else:
            self._orca(robots, robot_vel, seen, float(dt), contacts, stepping)
        if order is not None:  # back to the robots' order
            np.put_along_axis(contacts, order, contacts.copy(), 1)
        self.touched |= contacts & present & stepping[:, None]
        for listener in self.listeners:
            listener(motion, stepping)

    def finish(self, acting: NDArray[np.bool_] | None = None) -> NDArray[np.bool_]:
        """End an env step: the robots that touched a pedestrian in it, ``(W, R)``; those
        ``acting`` (default all) count it in :attr:`collisions`."""
        touched = self.touched.copy()
        self.collisions += touched if acting is None else touched & np.asarray(acting).reshape(touched.shape)
        return touched

    def _touching(self, robots: NDArray[np.float64], contacts: NDArray[np.bool_]) -> None:
        """A static crowd's contacts (it never moves): a robot's disc over a pedestrian's."""
        present = np.arange(self.radius.shape[1])[None] < self.count[:, None]
        d = np.hypot(robots[:, :, None, 0] - self.positions[:, None, :, 0], robots[:, :, None, 1] - self.positions[:, None, :, 1])
        contacts[:] = ((d < robots[:, :, None, 2] + self.radius[:, None]) & present[:, None]).any(-1)

    def _orca(self, robots: NDArray[np.float64], robot_vel: NDArray[np.float64], seen: NDArray[np.int64], dt: float,
              contacts: NDArray[np.bool_], stepping: NDArray[np.bool_]) -> None:
        """An ORCA step of the ``stepping`` worlds: one compiled call per scene, then the plans."""
        cfg, fn = self.config, kernel("pointnav_core.crowds._crowd_kernel", "orca_crowd_worlds")
        new_pos, new_vel = self.positions.copy(), self.velocities.copy()
        flags = np.zeros(self.radius.shape, np.int8)
        for s, group in enumerate(self._groups):
            worlds = group if stepping.all() else group[stepping[group]]
            if not len(worlds):
                continue
            collision = self.scenes[s].floors[self.floor].collision
            fn(worlds, self.count, self.positions, self.velocities, self.radius, self.speed, self.goals, self._paths,
               self._next, self._last, robots, robot_vel, seen, dt, cfg.neighbor_dist, cfg.max_neighbors,
               cfg.time_horizon, GOAL_REACHED, collision.kernel_arguments(cfg.radius[1]), new_pos, new_vel, flags,
               contacts)
        moving = (flags & 4) > 0
        self.headings = np.where(moving, np.arctan2(new_vel[..., 1], new_vel[..., 0]), self.headings)
        self.positions, self.velocities = new_pos, new_vel
        for w, i in zip(*(v.tolist() for v in np.nonzero(flags & 3))):
            self._replan(w, i, bool(flags[w, i] & 2))

    def _replan(self, w: int, i: int, arrived: bool) -> None:
        """Pedestrian ``i`` of world ``w`` plans again (:func:`plan_walk`, as the single env)."""
        st = self._start[w]
        walk = Walk(st.walks[i], st.loops[i], int(self._index[w, i]), self.goals[w, i].copy())
        rng = self._rngs[w, i]
        if rng is None:  # its own generator, where the placing left it
            rng = self._rngs[w, i] = np.random.default_rng(0)
            rng.bit_generator.state = st.draws[i]
        scene = self.scenes[int(self.world_scene[w])]
        planned = plan_walk(scene, self.floor, self.config.plan_radius, self.positions[w, i], walk, arrived, rng)
        self._index[w, i], self.goals[w, i] = walk.index, walk.goal
        points = planned.points
        if len(points) > self._paths.shape[2]:
            self._widen(self._paths.shape[1], max(len(points), 2 * self._paths.shape[2]))
        self._paths[w, i] = padded(points, self._paths.shape[2])
        self._last[w, i], self._next[w, i] = len(points) - 1, min(1, len(points) - 1)

    def discs(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
        """What the robots' scans see: centres ``x``, ``y`` and radii ``(W, P)`` (m), and
        each world's count."""
        return self.positions[..., 0], self.positions[..., 1], self.radius, self.count
