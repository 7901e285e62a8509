"""A crowd of pedestrians walking a scene's floor along its geodesic paths.

:class:`Crowd` places pedestrians where they fit (clear of the walls, the robots and each
other), gives each a goal in its part of the floor and the exact shortest path there
(:meth:`Planner.shortest_path <pointnav_core.geodesic.Planner.shortest_path>`, for the
crowd's largest radius, its arcs drawn in pieces of
:data:`~pointnav_core.crowds.walks.WALK_PIECE`), and advances them one control step at a time:

1. each pedestrian's *preferred velocity* points at its next waypoint at its preferred speed
   (slowing to arrive on the last one); a waypoint nearer than one step is passed when the
   one after it is in plain sight;
2. the behaviour turns the preferred velocities into new ones: ORCA (:func:`orca_step`, among
   the pedestrians and the robots they see, as CrowdNav puts the robot in RVO2's simulator),
   the social force model (:func:`social_force_step`, pysocialforce's, pulled toward the
   next waypoint), ``"static"`` (they never move) or the user's callable;
3. every pedestrian moves by its velocity for the step, unless that would take a disc of the
   crowd's largest radius into a wall: then it takes its preferred velocity instead; if
   that too is blocked, a step onto its next waypoint and no farther (the preferred
   velocity overshoots a waypoint nearer than a step, which it may not pass while the one
   after is out of sight, as at a corner's arc); and if that too is blocked it stands
   still for the step and plans again from where it is (ORCA
   here has no wall lines; the paths keep that radius plus
   :data:`~pointnav_core.crowds.config.PATH_MARGIN` from the walls, and a push by a
   neighbour is undone by the new plan);
4. a pedestrian within 0.1 m of its goal gets a new goal and path.

Each pedestrian draws from its own generator (its seed is drawn at :meth:`Crowd.spawn`):
its radius, speed and heading, and every goal after its first (see
:mod:`pointnav_core.crowds.record`), so one pedestrian's replans never shift another's
draws. :meth:`Crowd.record` is the crowd as placed; :meth:`Crowd.spawn` with a record
places exactly that crowd again.

Robots are not pushed by pedestrians (there is no physics): a robot's disc that overlaps a
pedestrian's is a *pedestrian contact*, which the env counts apart from its collisions, as
iGibson's social navigation task and CrowdNav do.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from pointnav_core.crowds.config import CrowdView, PedestrianConfig
from pointnav_core.crowds.orca import orca_step
from pointnav_core.crowds.record import SEED_LIMIT, PedestrianRecord
from pointnav_core.crowds.social_force import SocialForceParams, social_force_step
from pointnav_core.crowds.walks import Walk, padded, plan_walk
from pointnav_core.errors import ArgumentError, SamplingError
from pointnav_core.utils.compiled import kernel

__all__ = ["Crowd", "CrowdStart"]

#: Tries to place one pedestrian before the crowd is declared not to fit.
PLACE_TRIES = 200
#: How near (m) a pedestrian must come to its goal to draw the next one.
GOAL_REACHED = 0.1
#: Social force: the speed limit over the preferred speed (pysocialforce's 1.3).
MAX_SPEED_FACTOR = 1.3
#: Social force: a robot's goal is where its velocity takes it in this many seconds.
ROBOT_LOOKAHEAD = 10.0
# pysocialforce's parameters without its stops near the goal: a pedestrian's goal in the
# model is its next waypoint, and the crowd passes waypoints and draws new goals itself.
_SOCIAL_FORCE = SocialForceParams(goal_threshold=0.0, stop_distance=0.0)
#: The compiled step of ORCA crowds (``utils.compiled.kernel``'s module and function).
KERNEL = ("pointnav_core.crowds._crowd_kernel", "orca_crowd_step")
_NO_ROWS = np.zeros(0, np.int64)  # no pedestrian to plan for (read only)
_NO_ROWS.flags.writeable = False


class CrowdStart(NamedTuple):
    """A freshly placed crowd of ``P`` pedestrians, as :meth:`Crowd.start` gives it (m, rad, m/s)."""

    positions: NDArray[np.float64]  #: (P, 2)
    headings: NDArray[np.float64]  #: (P,)
    radius: NDArray[np.float64]  #: (P,)
    speed: NDArray[np.float64]  #: (P,)
    goals: NDArray[np.float64]  #: (P, 2)
    paths: NDArray[np.float64]  #: (P, L, 2), each padded with its last point
    next: NDArray[np.int64]  #: (P,) each one's next waypoint
    last: NDArray[np.int64]  #: (P,) each path's last point
    goal_index: NDArray[np.int64]  #: (P,) where each is in its fixed goal list
    walks: tuple[tuple[tuple[float, float], ...], ...]  #: each one's fixed goals
    loops: tuple[bool, ...]  #: whether each walks them round and round
    draws: tuple[dict[str, Any], ...]  #: each one's own generator's state (``bit_generator.state``)
    record: tuple[PedestrianRecord, ...]  #: :meth:`Crowd.record`


class Crowd:
    """The pedestrians of one env's scene (see the module notes for how they move).

    Parameters
    ----------
    config : PedestrianConfig
        The crowd's settings; a spawn from a record widens its radius range to the
        recorded radii for that episode.
    scene : Scene
        The scene they walk; pedestrians are on one floor at a time (the robot's).

    Attributes
    ----------
    positions, velocities : ndarray, shape (P, 2)
        Centres (m) and velocities (m/s) after the last step.
    headings : ndarray, shape (P,)
        Walking directions (rad, world frame): of the velocity, kept while standing.
    radius, speed : ndarray, shape (P,)
        Disc radii (m) and preferred speeds (m/s).
    goals : ndarray, shape (P, 2)
        The goal each walks to now (m).
    floor : int
        The floor they are on.
    """

    def __init__(self, config: PedestrianConfig, scene: Any) -> None:
        self.config = self._given = config
        self.scene = scene
        self.floor = 0
        self._rng = np.random.default_rng(0)
        self._set_count(0)
        self._record: tuple[PedestrianRecord, ...] = ()

    def _set_count(self, n: int) -> None:
        self.positions = np.zeros((n, 2))
        self.velocities = np.zeros((n, 2))
        self.headings = np.zeros(n)
        self.radius = np.zeros(n)
        self.speed = np.zeros(n)
        self.goals = np.zeros((n, 2))
        self._paths = np.zeros((n, 1, 2))  # each path padded with its last point
        self._last = np.zeros(n, dtype=np.int64)  # index of each path's last point
        self._next = np.zeros(n, dtype=np.int64)  # index of each one's next waypoint
        self._rngs = [np.random.default_rng(0)] * n  # each one's own draws
        self._seeds = [0] * n
        self._walks = [Walk((), False, -1, self.goals[i]) for i in range(n)]  # each one's fixed goals
        self._drawn = np.zeros(n, dtype=bool)  # whether each one's goal was drawn

    @property
    def n(self) -> int:
        """Number of pedestrians."""
        return len(self.radius)

    def discs(self) -> NDArray[np.float64]:
        """``(P, 3)`` discs ``(x, y, radius)`` of the pedestrians (m)."""
        out = np.empty((self.n, 3))
        out[:, :2] = self.positions
        out[:, 2] = self.radius
        return out

    # ------------------------------------------------------------------ placing
    def spawn(self, floor: int, rng: np.random.Generator, robots: NDArray[np.float64],
              record: Sequence[PedestrianRecord] | None = None) -> None:
        """Place a new crowd on ``floor``, clear of the ``(M, 3)`` robot discs ``robots``:
        drawn from ``rng`` (each pedestrian's seed, where it stands, its first goal), or
        exactly the crowd of ``record`` (:meth:`record`'s) when given.

        Raises
        ------
        SamplingError
            When the crowd's count does not fit: naming the count and the pedestrian that
            found no place after :data:`PLACE_TRIES` tries; or when a fixed or recorded
            start is not clear, naming it.
        """
        given, scene = self._given, self.scene
        self.floor, self._rng = int(floor), rng
        if record is None:
            tmap = scene.floors[self.floor]
            n = given.number(float(tmap.free.sum()) * tmap.resolution**2)
            self.config = given
            seeds = rng.integers(SEED_LIMIT, size=n).tolist()
            walks = list(given.goals) if given.goals is not None else [()] * n
            loops = [given.goals is not None] * n
        else:
            record = tuple(record)
            n, seeds = len(record), [r.seed for r in record]
            walks, loops = [r.goals for r in record], [r.loop for r in record]
            widest = max([r.radius for r in record], default=0.0)
            # The walls are kept from the largest radius: widened to the recorded ones.
            self.config = given if widest <= given.radius[1] else dataclasses.replace(given, radius=(given.radius[0], widest))
        self._set_count(n)
        self._seeds = [int(v) for v in seeds]
        self._walks = [Walk(tuple(walk), bool(loop), -1, self.goals[i]) for i, (walk, loop) in enumerate(zip(walks, loops))]
        self._draw_own(record)
        robots = np.asarray(robots, dtype=np.float64).reshape(-1, 3)
        for i in range(n):
            if record is not None:
                # Its own disc must fit: the crowd's paths start from the nearest cell they fit.
                self.positions[i] = self._fixed(i, robots, record[i].start, f"pedestrians[{i}].start", record[i].radius)
            elif given.starts is not None:
                self.positions[i] = self._fixed(
                    i, robots, given.starts[i], f"pedestrians['starts'][{i}]", self.config.plan_radius
                )
            else:
                self.positions[i] = self._place(i, robots)
        # A drawn crowd's first goals come from ``rng`` and are recorded; a recorded crowd
        # without goals draws its first from its own generators, as later ones.
        paths = [self._plan(i, True, rng if record is None else self._rngs[i]) for i in range(n)]
        self._set_paths(range(n), paths)
        self._record = record if record is not None else tuple(
            PedestrianRecord(
                start=(float(x), float(y)), loop=self._walks[i].loop, seed=self._seeds[i],
                goals=self._walks[i].walk if self._walks[i].walk or not self._drawn[i] else (tuple(self.goals[i].tolist()),),
                radius=float(self.radius[i]), speed=float(self.speed[i]),
            ) for i, (x, y) in enumerate(self.positions.tolist())
        )

    def _draw_own(self, record: Sequence[PedestrianRecord] | None) -> None:
        """Each pedestrian's generator from its seed and its first three draws: radius and
        speed in the config's ranges (a record's own instead), heading in [-pi, pi)."""
        (r_lo, r_hi), (s_lo, s_hi) = self.config.radius, self.config.speed
        for i, seed in enumerate(self._seeds):
            self._rngs[i] = own = np.random.default_rng(seed)
            u_radius, u_speed, u_heading = own.random(3).tolist()
            if record is None:
                self.radius[i] = r_lo + (r_hi - r_lo) * u_radius
                self.speed[i] = s_lo + (s_hi - s_lo) * u_speed
            else:
                self.radius[i], self.speed[i] = record[i].radius, record[i].speed
            self.headings[i] = -math.pi + 2.0 * math.pi * u_heading

    def record(self) -> tuple[PedestrianRecord, ...]:
        """The crowd as the last :meth:`spawn` placed it: one record per pedestrian (its
        start, fixed goals or first drawn goal, seed, radius and speed), which
        ``spawn(..., record=...)`` places again exactly."""
        return self._record

    def start(self) -> CrowdStart:
        """The crowd as the last :meth:`spawn` placed it, as arrays (copies): where the
        batched engine's worlds start theirs (:mod:`pointnav_core.vector.crowd`)."""
        return CrowdStart(
            self.positions.copy(), self.headings.copy(), self.radius.copy(), self.speed.copy(), self.goals.copy(),
            self._paths.copy(), self._next.copy(), self._last.copy(), np.array([w.index for w in self._walks], np.int64),
            tuple(w.walk for w in self._walks), tuple(w.loop for w in self._walks),
            tuple(rng.bit_generator.state for rng in self._rngs), self.record(),
        )

    def _place(self, i: int, robots: NDArray[np.float64]) -> NDArray[np.float64]:
        """A usable point for pedestrian ``i`` that overlaps no robot and no pedestrian before it."""
        r = self.radius[i]
        others = np.concatenate([robots, self.discs()[:i]])
        for _ in range(PLACE_TRIES):
            _, point = self.scene.get_random_point(self.floor, robot=self.config.plan_radius, rng=self._rng)
            gap = np.hypot(others[:, 0] - point[0], others[:, 1] - point[1]) - others[:, 2] - r
            if not len(gap) or gap.min() >= 0.0:
                return point[:2]
        what = f"count={self.n}" if self.config.count is not None else f"{self.n} pedestrians (density={self.config.density})"
        raise SamplingError(
            f"pedestrians: {what} do not fit on floor {self.floor}: pedestrian {i} found no place clear of "
            f"the walls, the robots and the pedestrians before it in {PLACE_TRIES} tries; ask for fewer"
        )

    def _fixed(self, i: int, robots: NDArray[np.float64], start: Any, name: str, clearance: float) -> NDArray[np.float64]:
        """Pedestrian ``i``'s fixed or recorded ``start`` (m), checked: a disc of ``clearance`` m
        must fit there, and its own overlap no robot and no pedestrian before it; errors name
        the field ``name``."""
        point = np.array(start, dtype=np.float64)
        others = np.concatenate([robots, self.discs()[:i]])
        gap = np.hypot(others[:, 0] - point[0], others[:, 1] - point[1]) - others[:, 2] - self.radius[i]
        tmap = self.scene.floors[self.floor]
        if not tmap.is_usable(point, clearance) or (len(gap) and gap.min() < 0.0):
            raise SamplingError(
                f"{name} {point.tolist()} is not clear on floor {self.floor}: a disc of "
                f"{clearance} m must fit there, apart from the robots and the pedestrians before it"
            )
        return point

    # ------------------------------------------------------------------ paths
    def _plan(self, i: int, new_goal: bool, rng: np.random.Generator) -> NDArray[np.float64]:
        """Pedestrian ``i``'s path from where it stands to its goal (:func:`plan_walk`)."""
        walk = self._walks[i]
        walk.goal = self.goals[i].copy()  # set_route may have changed it
        planned = plan_walk(self.scene, self.floor, self.config.plan_radius, self.positions[i], walk, new_goal, rng)
        self.goals[i] = walk.goal
        self._drawn[i] |= planned.drawn
        return planned.points

    def set_route(self, i: int, points: Any) -> None:
        """Send pedestrian ``i`` along the polyline ``points`` ``(N, 2)`` (m) to its last
        point, its new goal (the path is taken as given: it is not checked against the walls)."""
        pts = np.asarray(points, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[1] != 2 or not len(pts) or not np.isfinite(pts).all():
            raise ArgumentError(f"points must be an (N, 2) array of finite numbers (m), N >= 1, got {points!r}")
        self.goals[i] = pts[-1]
        self._set_paths([i], [pts])

    def _set_paths(self, rows: Any, paths: list[NDArray[np.float64]]) -> None:
        """Store ``paths`` for the pedestrians ``rows``, widening the padded table if needed."""
        rows = list(rows)
        longest = max([len(p) for p in paths], default=1)
        if longest > self._paths.shape[1]:
            self._paths = padded(self._paths, longest)
        for i, path in zip(rows, paths):
            self._paths[i] = padded(path, self._paths.shape[1])
            self._last[i] = len(path) - 1
            self._next[i] = min(1, len(path) - 1)

    # ------------------------------------------------------------------ stepping
    def preferred(self, dt: float) -> NDArray[np.float64]:
        """``(P, 2)`` velocities toward each next waypoint at the preferred speeds (m/s),
        passing waypoints nearer than one step and slowing to stop on the last one."""
        rows = np.arange(self.n)
        reach = np.maximum(self.speed * dt, 0.05)
        collision, radius = self.scene.floors[self.floor].collision, self.config.radius[1]
        for _ in range(4):  # arcs are drawn as short pieces: pass a few per step
            gap = np.linalg.norm(self._paths[rows, self._next] - self.positions, axis=1)
            near = np.flatnonzero((gap < reach) & (self._next < self._last))
            if not len(near):
                break
            # Passed only where the one after is in plain sight: a pedestrian pushed off its
            # path must not cut a corner into a wall.
            ahead = self._paths[near, self._next[near] + 1]
            self._next[near] += collision.segments_clear(self.positions[near], ahead, radius)
        return self._toward_next(dt, self._next == self._last)

    def landing(self, dt: float) -> NDArray[np.float64]:
        """``(P, 2)`` velocities (m/s) toward each next waypoint at the preferred speeds, but
        no faster than reaches it in ``dt`` s: the wall rule's last try before standing."""
        return self._toward_next(dt, True)

    def _toward_next(self, dt: float, stop: Any) -> NDArray[np.float64]:
        """Velocities (m/s) toward each next waypoint at the preferred speeds, no faster than
        reaches it in ``dt`` s where ``stop`` (a ``(P,)`` mask, or True for all)."""
        delta = self._paths[np.arange(self.n), self._next] - self.positions
        dist = np.linalg.norm(delta, axis=1)
        speed = np.where(stop, np.minimum(self.speed, dist / dt), self.speed)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(dist[:, None] > 0, delta * (speed / dist)[:, None], 0.0)

    def step(self, dt: float, robots: NDArray[np.float64], robot_velocities: NDArray[np.float64]) -> None:
        """Advance the crowd by ``dt`` s beside the ``(M, 3)`` robot discs ``robots`` moving
        at ``(M, 2)`` ``robot_velocities`` (see the module notes)."""
        if self.n:
            self._advance(dt, robots, robot_velocities)

    def step_contacts(self, dt: float, robots: NDArray[np.float64],
                      robot_velocities: NDArray[np.float64]) -> NDArray[np.bool_]:
        """:meth:`step`, then :meth:`contacts` of the same ``robots``: ``(M,)`` whether each
        robot's disc overlaps a pedestrian after the step. An ORCA crowd does both in one
        compiled call where numba is installed (the env's per-step path)."""
        touched = self._advance(dt, robots, robot_velocities) if self.n else None
        return self.contacts(robots) if touched is None else touched

    def _advance(self, dt: float, robots: NDArray[np.float64],
                 robot_velocities: NDArray[np.float64]) -> NDArray[np.bool_] | None:
        """One step of a crowd of at least one pedestrian: the robots' contacts after it
        where the compiled path ran (and computed them), else None."""
        fn = kernel(*KERNEL) if self.config.behaviour == "orca" else None
        collision = self.scene.floors[self.floor].collision
        if fn is None or not collision.compiled_polygons:
            self._step_arrays(dt, robots, robot_velocities)
            return None
        return self._step_compiled(fn, collision, dt, robots, robot_velocities)

    def _step_compiled(self, fn: Any, collision: Any, dt: float, robots: NDArray[np.float64],
                       robot_velocities: NDArray[np.float64]) -> NDArray[np.bool_]:
        """An ORCA step by the compiled kernel ``fn`` (``_crowd_kernel.orca_crowd_step``): the
        same floats as :meth:`_step_arrays` without its dozen array operations per step."""
        cfg, n = self.config, self.n
        robots = np.ascontiguousarray(robots, dtype=np.float64).reshape(-1, 3)
        robot_velocities = np.ascontiguousarray(robot_velocities, dtype=np.float64).reshape(-1, 2)
        new_pos, new_vel = np.empty((n, 2)), np.empty((n, 2))
        flags, contacts = np.empty(n, np.int8), np.empty(len(robots), np.bool_)
        replans = fn(self.positions, self.velocities, self.radius, self.speed, self.goals, self._paths, self._next,
                     self._last, robots, robot_velocities, len(robots) if cfg.sees_robots else 0, float(dt),
                     cfg.neighbor_dist, cfg.max_neighbors, cfg.time_horizon, GOAL_REACHED,
                     collision.kernel_arguments(cfg.radius[1]), new_pos, new_vel, flags, contacts)
        # Most steps plan nothing: the masks of who does are made only when someone does.
        replan = np.flatnonzero(flags & 3) if replans else _NO_ROWS
        self._moved(new_pos, new_vel, flags & 4, replan, flags & 2 if replans else None)
        return contacts

    def _step_arrays(self, dt: float, robots: NDArray[np.float64], robot_velocities: NDArray[np.float64]) -> None:
        """A step on the general path: numpy, any behaviour."""
        cfg = self.config
        pref = self.preferred(dt)
        if cfg.behaviour == "static":
            return
        if not cfg.sees_robots:
            robots, robot_velocities = np.zeros((0, 3)), np.zeros((0, 2))
        if cfg.behaviour == "orca":
            vel = self._orca(pref, dt, robots, robot_velocities)
        elif cfg.behaviour == "social_force":
            vel = self._social_force(dt, robots, robot_velocities)
        else:
            vel = self._called(pref, dt, robots, robot_velocities)
        tmap = self.scene.floors[self.floor]
        blocked = ~np.asarray(tmap.is_usable(self.positions + vel * dt, cfg.radius[1]))
        if blocked.any():  # ORCA knows no walls: its way there is the path's way
            vel[blocked] = pref[blocked]
            blocked &= ~np.asarray(tmap.is_usable(self.positions + vel * dt, cfg.radius[1]))
        if blocked.any():  # onto the next waypoint, no farther
            vel[blocked] = self.landing(dt)[blocked]
            blocked &= ~np.asarray(tmap.is_usable(self.positions + vel * dt, cfg.radius[1]))
            vel[blocked] = 0.0
        new = np.where(blocked[:, None], self.positions, self.positions + vel * dt)
        moving = np.hypot(vel[:, 0], vel[:, 1]) > 1e-9
        arrived = np.linalg.norm(self.goals - new, axis=1) < GOAL_REACHED
        self._moved(new, vel, moving, np.flatnonzero(blocked | arrived), arrived)

    def _moved(self, positions: NDArray[np.float64], velocities: NDArray[np.float64], moving: NDArray[Any],
               replan: NDArray[np.int64], arrived: NDArray[Any] | None) -> None:
        """Take a step's new ``(P, 2)`` positions (m) and velocities (m/s): the headings of
        the ``moving`` (a ``(P,)`` mask, nonzero where moving), and new plans for the
        pedestrians ``replan``: from where they stand, to a new goal where ``arrived``
        (a ``(P,)`` mask; None when ``replan`` is empty)."""
        self.positions, self.velocities = positions, velocities
        self.headings = np.where(moving, np.arctan2(velocities[:, 1], velocities[:, 0]), self.headings)
        if len(replan):
            assert arrived is not None
            paths = [self._plan(int(i), bool(arrived[i]), self._rngs[int(i)]) for i in replan]
            self._set_paths(replan, paths)

    def _orca(self, pref: NDArray[np.float64], dt: float, robots: NDArray[np.float64],
              robot_velocities: NDArray[np.float64]) -> NDArray[np.float64]:
        """ORCA among the pedestrians and the robots they see; the robots keep their own
        velocities (they are agents that do not react), and only the pedestrians' are kept."""
        cfg, n = self.config, self.n
        pos = np.concatenate([self.positions, robots[:, :2]])
        vel = np.concatenate([self.velocities, robot_velocities])
        pref = np.concatenate([pref, robot_velocities])
        radius = np.concatenate([self.radius, robots[:, 2]])
        top = np.concatenate([self.speed, np.hypot(robot_velocities[:, 0], robot_velocities[:, 1])])
        _, new = orca_step(pos, vel, pref, radius, top, dt, cfg.neighbor_dist, cfg.max_neighbors, cfg.time_horizon)
        return new[:n]

    def _social_force(self, dt: float, robots: NDArray[np.float64],
                      robot_velocities: NDArray[np.float64]) -> NDArray[np.float64]:
        """The social force model among the pedestrians and the robots they see, each
        pedestrian pulled toward its next waypoint; the robots pull toward where their
        velocities take them in :data:`ROBOT_LOOKAHEAD` s, and only the pedestrians' results
        are kept. The crowd decides arrival itself, so the model's stops near a goal are off."""
        n = self.n
        rows = np.arange(n)
        pos = np.concatenate([self.positions, robots[:, :2]])
        vel = np.concatenate([self.velocities, robot_velocities])
        goals = np.concatenate([self._paths[rows, self._next], robots[:, :2] + ROBOT_LOOKAHEAD * robot_velocities])
        speed = np.concatenate([self.speed, np.hypot(robot_velocities[:, 0], robot_velocities[:, 1])])
        _, new = social_force_step(pos, vel, goals, speed, speed * MAX_SPEED_FACTOR, dt, params=_SOCIAL_FORCE)
        return new[:n]

    def _called(self, pref: NDArray[np.float64], dt: float, robots: NDArray[np.float64],
                robot_velocities: NDArray[np.float64]) -> NDArray[np.float64]:
        """The user's behaviour's velocities, checked and clipped to each preferred speed."""
        view = CrowdView(self.positions.copy(), self.velocities.copy(), pref.copy(), self.radius.copy(),
                         self.speed.copy(), robots.copy(), robot_velocities.copy(), float(dt))
        got = self.config.behaviour(view)  # type: ignore[operator]
        try:
            vel = np.array(got, dtype=np.float64)
        except (TypeError, ValueError):
            vel = None
        if vel is None or vel.shape != (self.n, 2) or not np.isfinite(vel).all():
            raise ArgumentError(
                f"pedestrians['behaviour'] must return an array of shape ({self.n}, 2) of finite velocities (m/s), got {got!r}"
            )
        norm = np.hypot(vel[:, 0], vel[:, 1])
        scale = np.where(norm > self.speed, self.speed / np.maximum(norm, 1e-300), 1.0)
        return vel * scale[:, None]

    # ------------------------------------------------------------------ the robots' side
    def contacts(self, robots: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Whether each of the ``(M, 3)`` robot discs ``robots`` overlaps a pedestrian."""
        robots = np.asarray(robots, dtype=np.float64).reshape(-1, 3)
        if not self.n or not len(robots):
            return np.zeros(len(robots), dtype=bool)
        d = np.hypot(robots[:, None, 0] - self.positions[None, :, 0], robots[:, None, 1] - self.positions[None, :, 1])
        return (d < robots[:, None, 2] + self.radius[None, :]).any(axis=1)
