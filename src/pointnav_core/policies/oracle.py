"""Reference policies: the privileged shortest-path follower (the oracle baseline).

:class:`ShortestPathFollower` plays the role of Habitat's greedy geodesic follower: it reads
the true robot pose and the goal from the environment (privileged state, not the
observation) and steers along the exact any-angle shortest path (pure pursuit).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from dataclasses import field as member
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.floor.draw import nearest_usable
from pointnav_core.geodesic.paths import resample_path
from pointnav_core.transforms import quat2yaw

__all__ = ["ShortestPathFollower"]


#: Heading error (rad) below which a differential robot drives instead of turning; float32
#: actions round a turn to about 1e-7 of its size, so the robot faces the point to ~1e-7.
_FACING = 1e-6
#: Clearance (m) beyond the robot's radius the follower keeps where it can: far below any
#: passage that matters (the planner opens passages 1 mm wider than the robot), far above a
#: rigid-body solver's contact skin.
_HAIR = 1e-4
#: Path points closer than this (m) are one point (the robot lands on a point to ~1e-10).
_SAME = 1e-6
#: Widest heading error (rad) a differential robot drives out on an arc instead of turning.
_ARC_BEARING = 0.6
#: Share of a holonomic step the follower may give up, and in how many roundings it
#: looks for the float32 action that strays least sideways (see _float32_move).
_SHORTEN = 1e-3
_ROUNDINGS = 512
#: Directions tried when stepping out of a contact to where a wider robot fits.
_OUT_DIRECTIONS = 16
#: Metres a wider robot's way may add to the true robot's before the follower takes the
#: true robot's way, which can run through a passage exactly as wide as the robot.
_DETOUR = 0.5
#: Chords of a driven arc checked for clearance.
_ARC_CHORDS = 4
#: Metres off its plan a robot may be and still follow it; further, the follower plans
#: afresh (a shortest path from a point that far off is at most twice as much longer).
_LEAVE = 0.05
#: Legs of the plan ahead of the last one the robot was on that it may be found on.
_WINDOW = 16
#: Metres short of a leg's end that a proven chord stops (a leg ends tangent to an obstacle
#: at exactly the planned radius; 1 cm back the gap is ~1e-4 m), and how far (m) off a
#: proven chord the robot may be for it to stay proven (a straight drive strays ~1e-7 m).
_SHORT = 0.01
_ON_CHORD = 1e-5
#: Metres off its first leg the robot may be for the plan's candidates near a turn to be a
#: fresh plan's (a straight drive strays ~1e-7 m; a fresh tangent from 0.1 mm off moves
#: the turn by less).
_ON_LEG = 1e-4


def _wrap(angle: float) -> float:
    """Angle wrapped to (-pi, pi]."""
    return math.pi - (math.pi - angle) % (2.0 * math.pi)


def _ring(centre: NDArray[np.float64], radius: float) -> NDArray[np.float64]:
    """``_OUT_DIRECTIONS`` points evenly round a circle of ``radius`` (m) about ``centre``."""
    angles = np.linspace(0.0, 2.0 * math.pi, _OUT_DIRECTIONS, endpoint=False)
    return centre + radius * np.stack([np.cos(angles), np.sin(angles)], axis=1)


def _off_segment(p: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    """Distance (m) from point ``p`` to the segment from ``a`` to ``b``."""
    d = b - a
    length2 = float(d @ d)
    t = min(max(float((p - a) @ d) / length2, 0.0), 1.0) if length2 > 0.0 else 0.0
    return math.dist(p, a + t * d)


def _float32_move(dx: float, dy: float, yaw: float, scale: float) -> NDArray[np.float32]:
    """The float32 body-frame action ``(a0, a1)`` of a holonomic robot heading ``yaw`` (rad)
    whose world motion ``scale * R(yaw) a`` (m) strays least sideways from ``(dx, dy)`` (m).

    Rounding the ideal action to float32 moves the robot up to ~2e-9 m sideways on a 0.05 m
    step, more than the 1e-9 m that a passage exactly as wide as the robot leaves. Along
    the motion a thousandth of the step does not matter, so among the roundings of the
    ideal action shortened by up to that much, one strays a thousand times less.
    """
    c, s = math.cos(yaw), math.sin(yaw)
    ideal = np.array([c * dx + s * dy, -s * dx + c * dy]) / scale
    shorter = 1.0 - np.linspace(0.0, _SHORTEN, _ROUNDINGS)[:, None]
    a = np.clip(ideal * shorter, -1.0, 1.0).astype(np.float32).astype(np.float64)
    ex = scale * (a[:, 0] * c - a[:, 1] * s) - dx
    ey = scale * (a[:, 0] * s + a[:, 1] * c) - dy
    norm = math.hypot(dx, dy)
    side = np.abs(ex * dy - ey * dx) / norm if norm > 0.0 else np.hypot(ex, ey)
    return a[int(np.argmin(side))].astype(np.float32)


@dataclass
class _Plan:
    """The beginning of a shortest path, kept while the robot follows it.

    ``points`` (N, 2) m is the drawn path (clear at ``radius`` m, its arcs circumscribed)
    up to its first vertex ``2 * lookahead + _SHORT`` or more along; ``leg`` is the leg the robot was
    last found on (it only moves forward); ``goal`` is the ``(x, y, floor)`` it leads to.
    """

    points: NDArray[np.float64]
    radius: float
    goal: tuple[float, float, int]
    #: Whether ``points`` reach the goal (else they stop at a vertex on the way).
    whole: bool = False
    leg: int = 0
    #: ``(start, leg)``: the chord from ``start`` to the end of ``leg`` (less _SHORT) was
    #: found clear for a disc _ON_CHORD wider than ``radius``.
    chord: tuple[NDArray[np.float64], int] | None = None
    xy: list[list[float]] = member(init=False, repr=False)

    def __post_init__(self) -> None:
        # The vertices as Python floats, read every step by locate (numpy scalars are slower).
        self.xy = self.points.tolist()

    def locate(self, xy: NDArray[np.float64]) -> tuple[int, float] | None:
        """``(leg, distance)``: the nearest of the next :data:`_WINDOW` legs to ``xy`` and
        its distance (m); None when that is over :data:`_LEAVE` (the robot left the path)."""
        x, y = float(xy[0]), float(xy[1])
        pts = self.xy
        best, where = math.inf, self.leg
        # A few legs at most: plain floats are several times quicker than numpy here.
        for i in range(self.leg, min(self.leg + _WINDOW, len(pts) - 1)):
            ax, ay = pts[i]
            dx, dy = pts[i + 1][0] - ax, pts[i + 1][1] - ay
            length2 = dx * dx + dy * dy
            t = min(max(((x - ax) * dx + (y - ay) * dy) / length2, 0.0), 1.0) if length2 > 0.0 else 0.0
            off = math.hypot(ax + t * dx - x, ay + t * dy - y)
            if off < best:
                best, where = off, i
        if best > _LEAVE:
            return None
        self.leg = where
        return where, best

    def ahead(self, xy: NDArray[np.float64]) -> float:
        """Metres of the plan left from ``xy`` on its first leg (``inf`` if it reaches the goal)."""
        if self.whole:
            return math.inf
        rest = np.hypot(*np.diff(self.points[1:], axis=0).T).sum() if len(self.points) > 2 else 0.0
        return math.dist(xy, self.points[1]) + float(rest)


class ShortestPathFollower:
    """Drive one robot along the geodesic to its task's goal, without touching anything.

    Parameters
    ----------
    env : PointNavEnv or a multi-robot env
        Anything with ``scene``, ``backend``, ``robots`` and a ``task`` (or pass ``task``);
        a wrapped env (``gymnasium.make``) is unwrapped.
    task : PointNavigationTask, optional
        The task whose robot this policy drives (default ``env.task``).
    margin : float
        Extra clearance (m) kept from obstacles where there is room: the follower plans for
        a robot this much wider and falls back to the true radius where the wider robot does
        not fit. Default 0.02 m: a path that wraps a corner at a little more than the robot's
        radius can be driven in a few straight chords that keep the true radius.
    lookahead : float
        How far (m) along the path the follower looks for the point to head for.

    Notes
    -----
    Every step heads straight for the farthest of four points up to ``lookahead`` along the
    shortest path that the disc can reach in a straight line (checked against the floor's
    blocked set), else a full step along the path's first leg (which leaves a wrapped arc
    on its tangent), else the path's next vertex, so the robot never cuts a corner the path
    wraps. The path is that of the wider robot where it has one: a start that touches a
    wall is first left by a short clear step, and a goal against a wall is replaced, for
    the wider robot, by the nearest point within half the goal tolerance where it fits.
    Only where the wider robot has no way (or one over 0.5 m longer) does the follower
    take the true robot's, which may run through a passage exactly as wide as the robot.
    A holonomic robot translates there without turning, with the float32 action that
    strays least sideways. A differential robot drives the circular arc tangent to its
    heading that ends there, when that arc is clear (checked), and turns in place first
    otherwise. A robot whose disc overlaps something (a rigid-body solver's slop, a pose set
    by hand) heads for the nearest cell centre it fits at.

    Examples
    --------
    >>> from pointnav_core.envs.pointnav import PointNavEnv
    >>> env = PointNavEnv()
    >>> _ = env.reset(seed=0)
    >>> oracle = ShortestPathFollower(env)
    >>> action = oracle.act()
    >>> action.shape, action.dtype
    ((2,), dtype('float32'))
    """

    def __init__(
        self,
        env: Any,
        task: Any = None,
        margin: float = 0.02,
        lookahead: float = 0.3,
    ) -> None:
        # gymnasium.make's wrappers do not forward ``task``: drive the env they wrap.
        env = getattr(env, "unwrapped", env)
        self.env = env
        self.task = task if task is not None else env.task
        if isinstance(margin, bool) or not isinstance(margin, (int, float)) or not math.isfinite(margin) or margin < 0:
            raise ArgumentError(f"margin must be a finite number >= 0 (m), got {margin!r}")
        if isinstance(lookahead, bool) or not isinstance(lookahead, (int, float)) or not math.isfinite(lookahead) or lookahead <= 0:
            raise ArgumentError(f"lookahead must be a finite number > 0 (m), got {lookahead!r}")
        self.margin = float(margin)
        self.lookahead = float(lookahead)
        self._aims: dict[tuple[float, float, float], NDArray[np.float64] | None] = {}
        self._plan: _Plan | None = None
        # Metres the carrot's chord leaves beyond the robot's radius for the step's arc (the
        # chord was proven clear that much wider); None: the arc is tested.
        self._room: float | None = None

    def carrot(self, xy: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """The point (m, world frame) to head for from ``xy`` along the geodesic (see the
        class notes), or None if there is none. The crowd baselines steer toward it too."""
        self._room = None
        goal = np.asarray(self.task.get_goal_pos(), dtype=np.float64)[:2]
        plan = self._plan
        same_goal = plan is not None and plan.goal == (float(goal[0]), float(goal[1]), self.task.floor)
        if same_goal and (carrot := self._follow(plan, xy)) is not None:
            return carrot
        self._plan = None
        return self._replan(xy, goal)

    def _follow(self, plan: _Plan, xy: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """The carrot from ``xy`` along the stored plan; None when the robot has left it or
        nears its next turn (the plan is then made again from where the robot is)."""
        at = plan.locate(xy)
        if at is None:
            return None
        # Mid-leg, the shortest way from a point near the path heads for the leg's end, as
        # a fresh plan from there would; round a turn only a fresh plan knows the tangent.
        leg, off = at
        turn = plan.points[leg + 1]
        span = math.dist(xy, turn)
        if span < self.lookahead + _SHORT:
            # Still on the plan's first leg, straight towards the turn, a fresh plan from
            # here wraps the same arc: the plan's own candidates, tested, decide.
            if leg == 0 and off <= _ON_LEG and span > _SAME and plan.ahead(xy) >= self.lookahead:
                tmap = self.env.scene.floors[self.task.floor]
                return self._pick(xy, np.vstack([xy, plan.points[1:]]), plan.radius, tmap, fallback=False)
            return None
        ahead = xy + (turn - xy) * (self.lookahead / span)
        if plan.chord is None or plan.chord[1] != leg or _off_segment(xy, plan.chord[0], turn) > _ON_CHORD:
            # Every candidate lies on the chord from here to the turn: if the chord up to a
            # little short of the turn is clear for a disc _ON_CHORD wider, so is the way to
            # the farthest candidate from any point within _ON_CHORD of it (no more tests
            # while the robot drives along it).
            tmap = self.env.scene.floors[self.task.floor]
            short = turn + (xy - turn) * (_SHORT / span)
            if not tmap.collision.segments_clear(xy, short, plan.radius + _ON_CHORD):
                return self._pick(xy, np.vstack([xy, plan.points[leg + 1 :]]), plan.radius, tmap, fallback=False)
            plan.chord = (xy.copy(), leg)
        self._room = plan.radius - self.env.robots[self.task.robot_idn].radius
        return ahead

    def _replan(self, xy: NDArray[np.float64], goal: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """The carrot from a fresh shortest path from ``xy``, which is kept as the plan."""
        env, task = self.env, self.task
        spec = env.robots[task.robot_idn]
        tmap = env.scene.floors[task.floor]
        # Wider first; then a hair wider than the robot, so that the path never quite
        # touches a wall (a rigid-body solver counts touching as contact); then exact. A
        # robot that touches something (a start in a corner) first steps out to where the
        # wider robot fits: the exact robot's way may run through a passage exactly its
        # width, which float32 actions cannot thread without grazing a side.
        radii = sorted({spec.radius + self.margin, spec.radius + _HAIR, spec.radius}, reverse=True)
        exact = None  # the true robot's distance to the goal, found once if needed
        for radius in radii:
            aim = self._aim(goal, radius)
            if aim is None:
                continue
            field = env.scene.goal_field(task.floor, aim, robot=radius)
            # Twice the lookahead: the plan still covers a lookahead from where the robot
            # will be as it nears the turn.
            path, _ = field.path(xy, max_length=2.0 * self.lookahead + _SHORT)
            if path is not None:
                break
            if radius > spec.radius:
                if exact is None:
                    exact = env.scene.goal_field(task.floor, goal, robot=spec.radius).exact_distance(xy)
                if (out := self._step_out(xy, exact, field, radius)) is not None:
                    return out
        if path is None:
            centre = nearest_usable(tmap, xy, spec.radius)
            if centre is None:
                return None
            path, _ = env.scene.goal_field(task.floor, goal, robot=spec.radius).path(centre)
            if path is None:
                return None
            return centre
        whole = math.dist(path[-1], aim) == 0.0
        self._plan = _Plan(path, radius, (float(goal[0]), float(goal[1]), task.floor), whole)
        return self._pick(xy, path, radius, tmap, fallback=True)

    def _pick(
        self, xy: NDArray[np.float64], path: NDArray[np.float64], radius: float, tmap: Any, fallback: bool
    ) -> NDArray[np.float64] | None:
        """The farthest clear candidate on ``path`` (which starts at ``xy``); with no clear
        one, the path's next vertex if ``fallback`` (a fresh shortest path's first leg is
        clear), else None."""
        # Candidates, farthest first: points up to ``lookahead`` along the path, then the
        # path's next vertex. The drawn path circumscribes its arcs, so the straight move to
        # the next vertex is always clear, while a chord to a point further round an arc
        # would cut it. Chords are checked at the planned radius, so the robot stays where
        # the path it follows is defined.
        # A robot standing on a wrapped arc is its own first tangent point: skip repeats.
        path = path[np.r_[True, np.hypot(*np.diff(path, axis=0).T) > _SAME]]
        if len(path) < 2:
            return None
        # On a wrapped arc no further point of the arc is in a straight line (every chord
        # cuts the corner), only the next vertex a hair ahead. The tangent there stays
        # outside the arc, so the robot goes on along its first leg instead, up to a full
        # step: it leaves the arc a little, and the next step's path wraps back to it.
        first = path[1] - path[0]
        span = float(np.hypot(*first))
        along = path[0] + first * (max(self._step_length(), span) / span)
        ahead = np.vstack([resample_path(path, self.lookahead / 4, 5)[1:][::-1], along, path[1]])
        clear = tmap.collision.segments_clear(np.broadcast_to(xy, ahead.shape), ahead, radius)
        if clear.any():
            return ahead[int(np.argmax(clear))]
        return ahead[-1] if fallback else None

    def _aim(self, goal: NDArray[np.float64], radius: float) -> NDArray[np.float64] | None:
        """Where a robot of ``radius`` plans to: the goal, or for a wider robot that does not
        fit there (a goal against a wall), the nearest point within half the goal tolerance
        where it fits; None if there is none.

        Success needs only the goal tolerance, so the wider robot's way ends in time.
        """
        spec = self.env.robots[self.task.robot_idn]
        if radius == spec.radius:
            return goal
        key = (float(goal[0]), float(goal[1]), radius)
        if key not in self._aims:
            tmap = self.env.scene.floors[self.task.floor]
            away = 2.0 * (radius - spec.radius)
            points = np.vstack([goal, _ring(goal, away)])
            fits = tmap.collision.points_clear(points, radius)
            tolerance = float(getattr(self.task, "goal_tolerance", 0.0))
            self._aims[key] = points[int(np.argmax(fits))] if fits.any() and (fits[0] or away < tolerance / 2) else None
        return self._aims[key]

    def _step_length(self) -> float:
        """Metres the robot covers in one step at full speed."""
        spec = self.env.robots[self.task.robot_idn]
        return spec.max_linear_velocity / getattr(self.env, "action_frequency", 10.0)

    def _step_out(self, xy: NDArray[np.float64], exact: float, field: Any, radius: float) -> NDArray[np.float64] | None:
        """A point a little away from ``xy``, in a clear straight line, where a robot of
        ``radius`` fits and whose way to the goal costs at most ``_DETOUR`` m more than the
        true robot's, ``exact`` m from ``xy``; None if there is none."""
        spec = self.env.robots[self.task.robot_idn]
        tmap = self.env.scene.floors[self.task.floor]
        away = min(2.0 * (radius - spec.radius), self._step_length())
        points = _ring(xy, away)
        clear = tmap.collision.segments_clear(np.broadcast_to(xy, points.shape), points, spec.radius)
        best, best_cost = None, exact + _DETOUR
        for point in points[clear]:
            cost = away + field.exact_distance(point)
            if cost <= best_cost:
                best, best_cost = point, cost
        return best

    def act(self) -> NDArray[np.float32]:
        """Action in [-1, 1] for the task's robot, from its current true pose."""
        env, task = self.env, self.task
        spec = env.robots[task.robot_idn]
        position, quat = env.backend.get_pose(task.robot_idn)
        xy = position[:2]
        action = np.zeros(spec.action_dim, dtype=np.float32)
        target = self.carrot(xy)
        if target is None:
            return action
        dt = 1.0 / getattr(env, "action_frequency", 10.0)
        dx, dy = float(target[0] - xy[0]), float(target[1] - xy[1])
        dist = math.hypot(dx, dy)
        if dist == 0.0:
            return action
        yaw = float(quat2yaw(quat))
        bearing = _wrap(math.atan2(dy, dx) - yaw)
        # Reach the point in one step if it is that close, else go at full speed.
        speed = min(1.0, dist / (spec.max_linear_velocity * dt))
        if spec.drive == "holonomic":
            scale = spec.max_linear_velocity * dt
            action[:2] = _float32_move(speed * dx / dist * scale, speed * dy / dist * scale, yaw, scale)
        elif abs(bearing) <= _FACING:
            action[0] = speed
        elif (arc := self._arc_step(xy, yaw, dist, bearing, dt)) is not None:
            action[0], action[1] = arc
        else:
            action[1] = float(np.clip(bearing / (spec.max_angular_velocity * dt), -1.0, 1.0))
        return action

    def _arc_step(
        self, xy: NDArray[np.float64], yaw: float, dist: float, bearing: float, dt: float
    ) -> tuple[float, float] | None:
        """(v, w) actions that drive one step along the circular arc from the pose to the
        point ``dist`` m ahead at ``bearing`` rad, tangent to the heading; None when the
        bearing is too wide, the turn too fast, or the arc not clear.
        """
        spec = self.env.robots[self.task.robot_idn]
        if abs(bearing) > _ARC_BEARING:
            return None
        kappa = 2.0 * math.sin(bearing) / dist  # curvature (1/m) of the arc through both
        length = dist * bearing / math.sin(bearing)
        s = min(length, spec.max_linear_velocity * dt, spec.max_angular_velocity * dt / abs(kappa))
        # The driven arc, as chords whose sagitta the clearance test adds to the radius (a few
        # points: plain floats, not arrays).
        x0, y0, step = float(xy[0]), float(xy[1]), s / _ARC_CHORDS
        sin0, cos0 = math.sin(yaw), math.cos(yaw)
        pts = [
            (x0 + (math.sin(yaw + kappa * (k * step)) - sin0) / kappa, y0 - (math.cos(yaw + kappa * (k * step)) - cos0) / kappa)
            for k in range(_ARC_CHORDS + 1)
        ]
        sagitta = (s / _ARC_CHORDS) ** 2 * abs(kappa) / 8.0
        # Along a proven chord (see _follow) the arc and its chords bulge at most ``bulge``
        # off the chord to the carrot (the whole arc's sagitta), which left ``_room``.
        bulge = 0.5 * dist * math.tan(0.5 * abs(bearing))
        if self._room is None or bulge + sagitta + _HAIR > self._room:
            geo = self.env.scene.floors[self.task.floor].collision
            reach = spec.radius + _HAIR + sagitta
            if not all(geo.segment_clear(*a, *b, reach) for a, b in zip(pts, pts[1:])):
                return None
        v = s / (spec.max_linear_velocity * dt)
        w = kappa * s / (spec.max_angular_velocity * dt)
        return float(np.clip(v, 0.0, 1.0)), float(np.clip(w, -1.0, 1.0))
