"""Reference policies: the privileged shortest-path follower (the oracle baseline).

:class:`ShortestPathFollower` plays the role of Habitat's greedy geodesic follower: it reads
the true robot pose and the goal from the environment (privileged state, not the
observation) and steers along the exact any-angle shortest path (pure pursuit).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.paths import resample_path
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
#: Chords of a driven arc checked for clearance.
_ARC_CHORDS = 4


def _wrap(angle: float) -> float:
    """Angle wrapped to (-pi, pi]."""
    return math.pi - (math.pi - angle) % (2.0 * math.pi)


def _nearest_usable(tmap: Any, xy: NDArray[np.float64], radius: float, reach: int = 3) -> NDArray[np.float64] | None:
    """Centre of the nearest cell within ``reach`` cells whose centre the disc fits at."""
    usable = tmap.usable(radius)
    row, col = (int(v) for v in tmap.world_to_cell(xy))
    h, w = usable.shape
    r0, r1, c0, c1 = max(row - reach, 0), min(row + reach + 1, h), max(col - reach, 0), min(col + reach + 1, w)
    cells = np.argwhere(usable[r0:r1, c0:c1]) + (r0, c0)
    if not len(cells):
        return None
    centres = tmap.cell_to_world(cells)
    return centres[int(np.argmin(np.hypot(*(centres - xy).T)))]


class ShortestPathFollower:
    """Drive one robot along the geodesic to its task's goal, without touching anything.

    Parameters
    ----------
    env : PointNavEnv or a multi-robot env
        Anything with ``scene``, ``backend``, ``robots`` and a ``task`` (or pass ``task``).
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
    exact shortest path that the disc can reach in a straight line (checked against the
    floor's blocked set), or else for the path's next vertex, so the robot never cuts a
    corner the path wraps. A holonomic robot translates there without turning. A
    differential robot drives the circular arc tangent to its heading that ends there,
    when that arc is clear (checked), and turns in place first otherwise. A robot
    whose disc overlaps something (a rigid-body solver's slop, a pose set by hand) heads for
    the nearest cell centre it fits at.

    Examples
    --------
    >>> from pointnav_core.env import PointNavEnv
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
        self.env = env
        self.task = task if task is not None else env.task
        if isinstance(margin, bool) or not isinstance(margin, (int, float)) or not math.isfinite(margin) or margin < 0:
            raise ValueError(f"margin must be a finite number >= 0 (m), got {margin!r}")
        if isinstance(lookahead, bool) or not isinstance(lookahead, (int, float)) or not math.isfinite(lookahead) or lookahead <= 0:
            raise ValueError(f"lookahead must be a finite number > 0 (m), got {lookahead!r}")
        self.margin = float(margin)
        self.lookahead = float(lookahead)

    def _carrot(self, xy: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """The point to head for from ``xy`` (see the class notes), or None if there is none."""
        env, task = self.env, self.task
        spec = env.robots[task.robot_idn]
        goal = np.asarray(task.get_goal_pos(), dtype=np.float64)[:2]
        tmap = env.scene.floors[task.floor]
        path = None
        # Wider first; then a hair wider than the robot, so that the path never quite
        # touches a wall (a rigid-body solver counts touching as contact); then exact.
        radii = sorted({spec.radius + self.margin, spec.radius + _HAIR, spec.radius}, reverse=True)
        for radius in radii:
            path, _ = env.scene.goal_field(task.floor, goal, robot=radius).path(xy, max_length=self.lookahead)
            if path is not None:
                break
        if path is None:
            centre = _nearest_usable(tmap, xy, spec.radius)
            if centre is None:
                return None
            path, _ = env.scene.goal_field(task.floor, goal, robot=spec.radius).path(centre)
            if path is None:
                return None
            return centre
        # Candidates, farthest first: points up to ``lookahead`` along the path, then the
        # path's next vertex. The drawn path circumscribes its arcs, so the straight move to
        # the next vertex is always clear, while a chord to a point further round an arc
        # would cut it.
        # A robot standing on a wrapped arc is its own first tangent point: skip repeats.
        path = path[np.r_[True, np.hypot(*np.diff(path, axis=0).T) > _SAME]]
        if len(path) < 2:
            return None
        ahead = np.vstack([resample_path(path, self.lookahead / 4, 5)[1:][::-1], path[1]])
        reach = min(radius, spec.radius + _HAIR)
        clear = tmap.collision.segments_clear(np.broadcast_to(xy, ahead.shape), ahead, reach)
        return ahead[int(np.argmax(clear))] if clear.any() else ahead[-1]

    def act(self) -> NDArray[np.float32]:
        """Action in [-1, 1] for the task's robot, from its current true pose."""
        env, task = self.env, self.task
        spec = env.robots[task.robot_idn]
        position, quat = env.backend.get_pose(task.robot_idn)
        xy = position[:2]
        action = np.zeros(spec.action_dim, dtype=np.float32)
        target = self._carrot(xy)
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
            action[0] = speed * math.cos(bearing)
            action[1] = speed * math.sin(bearing)
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
        # The driven arc, as chords whose sagitta the clearance test adds to the radius.
        u = np.linspace(0.0, s, _ARC_CHORDS + 1)
        pts = np.stack(
            [
                xy[0] + (np.sin(yaw + kappa * u) - math.sin(yaw)) / kappa,
                xy[1] - (np.cos(yaw + kappa * u) - math.cos(yaw)) / kappa,
            ],
            axis=1,
        )
        sagitta = (s / _ARC_CHORDS) ** 2 * abs(kappa) / 8.0
        tmap = self.env.scene.floors[self.task.floor]
        if not tmap.collision.segments_clear(pts[:-1], pts[1:], spec.radius + _HAIR + sagitta).all():
            return None
        v = s / (spec.max_linear_velocity * dt)
        w = kappa * s / (spec.max_angular_velocity * dt)
        return float(np.clip(v, 0.0, 1.0)), float(np.clip(w, -1.0, 1.0))
