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

from pointnav_core.geodesic import resample_path
from pointnav_core.transforms import quat2yaw

__all__ = ["ShortestPathFollower"]


def _wrap(angle: float) -> float:
    """Angle wrapped to (-pi, pi]."""
    return math.pi - (math.pi - angle) % (2.0 * math.pi)


class ShortestPathFollower:
    """Drive one robot along the geodesic to its task's goal.

    Parameters
    ----------
    env : PointNavEnv or a multi-robot env
        Anything with ``scene``, ``backend``, ``robots`` and a ``task`` (or pass ``task``).
    task : PointNavigationTask, optional
        The task whose robot this policy drives (default ``env.task``).
    margin : float
        Extra clearance (m) kept from obstacles: the follower plans for a robot this much
        wider, so that it does not graze corners, and falls back to the true radius where
        the wider robot does not fit. Default: one map cell.
    turn_threshold : float
        Heading error (rad) above which the robot turns in place before driving.
    lookahead : float
        The robot steers towards the point this far (m) along the path (pure pursuit), so
        it rounds corners smoothly and never turns back to a corner it has just passed.

    Notes
    -----
    Each step follows the goal field's cheap path (the root of the cell the robot stands
    in), which is optimal for the cell's centre but can be a detour for the robot's exact
    position. Two such paths in opposite directions from neighbouring points can trap a
    robot that moves at once (holonomic drive) in a two-step cycle; so when the point to
    steer towards turns back against the previous one, the follower asks for the exact
    path instead.

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
        margin: float | None = None,
        turn_threshold: float = 0.35,
        lookahead: float = 0.3,
    ) -> None:
        self.env = env
        self.task = task if task is not None else env.task
        if margin is not None and (not math.isfinite(margin) or margin < 0):
            raise ValueError(f"margin must be a finite number >= 0 (m), got {margin!r}")
        if not 0 < turn_threshold <= math.pi:
            raise ValueError(f"turn_threshold must be in (0, pi] rad, got {turn_threshold!r}")
        self.margin = margin
        self.turn_threshold = float(turn_threshold)
        if not math.isfinite(lookahead) or lookahead <= 0:
            raise ValueError(f"lookahead must be a finite number > 0 (m), got {lookahead!r}")
        self.lookahead = float(lookahead)
        self._last_target: NDArray[np.float64] | None = None

    def _carrot(
        self, xy: NDArray[np.float64], exact: bool = False
    ) -> NDArray[np.float64] | None:
        """The point ``lookahead`` metres along the shortest path from ``xy`` (or the goal).

        ``exact=False`` takes the goal field's cheap path, ``exact=True`` searches.
        """
        env, task = self.env, self.task
        spec = env.robots[task.robot_idn]
        goal = np.asarray(task.get_goal_pos(), dtype=np.float64)[:2]
        tmap = env.scene.floors[task.floor]
        margin = tmap.resolution if self.margin is None else self.margin
        path = None
        for radius in (spec.radius + margin, spec.radius):
            path, _ = env.scene.goal_field(task.floor, goal, robot=radius).path(xy, exact=exact)
            if path is not None:
                break
        if path is None:
            return None
        return resample_path(path, self.lookahead, 2)[1]

    def act(self) -> NDArray[np.float32]:
        """Action in [-1, 1] for the task's robot, from its current true pose."""
        env, task = self.env, self.task
        spec = env.robots[task.robot_idn]
        position, quat = env.backend.get_pose(task.robot_idn)
        xy = position[:2]
        action = np.zeros(spec.action_dim, dtype=np.float32)
        target = self._carrot(xy)
        last, self._last_target = self._last_target, target
        if target is not None and last is not None:
            ahead, before = target - xy, last - xy
            if float(ahead[0] * before[0] + ahead[1] * before[1]) < 0.0:
                # The cheap path turns back: confirm it (see the class notes).
                target = self._last_target = self._carrot(xy, exact=True)
        if target is None:
            return action
        dt = 1.0 / getattr(env, "action_frequency", 10.0)
        dx, dy = float(target[0] - xy[0]), float(target[1] - xy[1])
        dist = math.hypot(dx, dy)
        yaw = float(quat2yaw(quat))
        bearing = _wrap(math.atan2(dy, dx) - yaw)
        # Reach the waypoint in one step if it is that close, else go at full speed.
        speed = min(1.0, dist / (spec.max_linear_velocity * dt))
        turn = float(np.clip(bearing / (spec.max_angular_velocity * dt), -1.0, 1.0))
        if spec.drive == "holonomic":
            action[0] = speed * math.cos(bearing)
            action[1] = speed * math.sin(bearing)
            action[2] = turn
        else:
            action[0] = speed * max(0.0, math.cos(bearing)) if abs(bearing) < self.turn_threshold else 0.0
            action[1] = turn
        return action
