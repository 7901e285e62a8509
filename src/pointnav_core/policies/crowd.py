"""Classical baselines among pedestrians: an ORCA robot and the dynamic window approach.

Both read privileged state, as the oracle does (:mod:`pointnav_core.policies.oracle`): the
robot's true pose, the goal, the floor and the pedestrians' positions and velocities
(``env.crowd``). Both steer toward the oracle's *carrot*, the point up to 0.3 m ahead on the
exact shortest path (:meth:`ShortestPathFollower.carrot`; for the DWA, as far as a rollout
at full speed reaches), so that they differ from the
oracle, which ignores people, only in how they give way:

- :class:`OrcaRobot` (``pointnav eval --policy orca_robot``): the robot takes the velocity
  ORCA gives it among the pedestrians (:func:`~pointnav_core.crowds.orca_step`; its
  preferred velocity points at the carrot at full speed, the pedestrians keep theirs), as
  CrowdNav's ORCA robot does; a differential robot turns toward that velocity and drives
  when it faces it within 30 degrees.
- :class:`DynamicWindow` (``--policy dwa``): Fox, Burgard and Thrun (1997). Every (v, w) of
  a grid over the robot's speed limits is rolled out for ``horizon`` s at constant speed,
  and checked against the walls (the floor's exact clearance) and the pedestrians (moving
  at their current velocities). The robot's kinematics here have no acceleration limit, so
  the window is the whole range and a rollout is admissible when its first step is clear
  (the robot can stop after it). Admissible rollouts are scored by heading to the carrot
  and progress toward it where they stop being clear, how long they stay clear (scaled
  down within 0.5 m of a pedestrian), and speed, with weights ``(heading, clearance,
  speed)``. Where the best rollout stands still without progress and no pedestrian is
  within 0.5 m (DWA's local minimum at a passage it cannot line up with), the robot takes
  the oracle's step instead, as ROS's ``move_base`` falls back on a recovery behaviour.

Without pedestrians both reduce to following the carrot.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.crowds import orca_step
from pointnav_core.errors import ArgumentError
from pointnav_core.policies.oracle import ShortestPathFollower
from pointnav_core.transforms import quat2yaw

__all__ = ["DynamicWindow", "OrcaRobot"]

#: Heading error (rad) within which a differential ORCA robot drives while it turns.
_DRIVE_WITHIN = math.radians(30.0)


def _wrap(angle: NDArray[np.float64] | float) -> Any:
    return (np.asarray(angle) + math.pi) % (2.0 * math.pi) - math.pi


class _CrowdPolicy:
    """What both baselines share: the env, the robot's spec and pose, the carrot."""

    def __init__(self, env: Any, lookahead: float = 0.3) -> None:
        env = getattr(env, "unwrapped", env)
        self.env, self.task = env, env.task
        self.spec = env.robots[self.task.robot_idn]
        self.follower = ShortestPathFollower(env, lookahead=lookahead)
        self.dt = 1.0 / float(getattr(env, "action_frequency", 10.0))

    def pose(self) -> tuple[NDArray[np.float64], float]:
        position, quat = self.env.backend.get_pose(self.task.robot_idn)
        return np.asarray(position[:2], dtype=np.float64), float(quat2yaw(quat))

    def crowd(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Pedestrians' positions (P, 2), velocities (P, 2) and radii (P,); empty without them."""
        crowd = getattr(self.env, "crowd", None)
        if crowd is None or crowd.floor != self.task.floor:
            return np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0)
        return crowd.positions, crowd.velocities, crowd.radius

    def command(self, velocity: NDArray[np.float64], yaw: float) -> NDArray[np.float32]:
        """The action that drives the world-frame ``velocity`` (m/s) as well as the drive allows."""
        spec, action = self.spec, np.zeros(self.spec.action_dim, dtype=np.float32)
        speed = float(np.hypot(*velocity))
        if speed == 0.0:
            return action
        if spec.drive == "holonomic":
            c, s = math.cos(yaw), math.sin(yaw)
            local = np.array([c * velocity[0] + s * velocity[1], -s * velocity[0] + c * velocity[1]])
            action[:2] = np.clip(local / spec.max_linear_velocity, -1.0, 1.0)
            return action
        bearing = float(_wrap(math.atan2(velocity[1], velocity[0]) - yaw))
        action[1] = float(np.clip(bearing / (spec.max_angular_velocity * self.dt), -1.0, 1.0))
        if abs(bearing) <= _DRIVE_WITHIN:
            action[0] = float(np.clip(speed * math.cos(bearing) / spec.max_linear_velocity, 0.0, 1.0))
        return action


class OrcaRobot(_CrowdPolicy):
    """The robot as an ORCA agent among the pedestrians (see the module notes).

    Parameters
    ----------
    env : PointNavEnv
    neighbor_dist, max_neighbors, time_horizon : float, int, float
        ORCA's (iGibson's social navigation values by default: 5 m, 10, 2 s).
    """

    def __init__(self, env: Any, neighbor_dist: float = 5.0, max_neighbors: int = 10, time_horizon: float = 2.0) -> None:
        super().__init__(env)
        self.orca = (neighbor_dist, max_neighbors, time_horizon)

    def act(self) -> NDArray[np.float32]:
        xy, yaw = self.pose()
        carrot = self.follower.carrot(xy)
        if carrot is None:
            return np.zeros(self.spec.action_dim, dtype=np.float32)
        gap = carrot - xy
        dist = float(np.hypot(*gap))
        top = self.spec.max_linear_velocity
        preferred = gap / dist * min(top, dist / self.dt) if dist > 0 else np.zeros(2)
        positions, velocities, radii = self.crowd()
        if not len(radii):
            return self.command(preferred, yaw)
        linear, _ = self.env.backend.get_velocity(self.task.robot_idn)
        _, new = orca_step(
            np.vstack([xy, positions]), np.vstack([linear[:2], velocities]), np.vstack([preferred, velocities]),
            np.concatenate([[self.spec.radius], radii]), np.concatenate([[top], np.hypot(*velocities.T)]),
            self.dt, *self.orca,
        )
        return self.command(new[0], yaw)


class DynamicWindow(_CrowdPolicy):
    """The dynamic window approach toward the carrot (see the module notes).

    Parameters
    ----------
    env : PointNavEnv
    horizon : float
        Seconds each (v, w) is rolled out, > 0.
    samples : (int, int)
        Linear and angular speeds in the grid (holonomic: speeds and directions).
    weights : (float, float, float)
        Heading, clearance and speed weights, >= 0.
    """

    def __init__(self, env: Any, horizon: float = 2.5, samples: tuple[int, int] = (6, 21),
                 weights: tuple[float, float, float] = (1.0, 2.0, 0.2)) -> None:
        if isinstance(horizon, bool) or not isinstance(horizon, (int, float)) or not horizon > 0 or not math.isfinite(horizon):
            raise ArgumentError(f"horizon must be a finite number > 0 (s), got {horizon!r}")
        # The aim is as far along the path as a rollout at full speed reaches.
        spec = getattr(env, "unwrapped", env).robots[getattr(env, "unwrapped", env).task.robot_idn]
        super().__init__(env, lookahead=max(0.3, spec.max_linear_velocity * float(horizon)))
        self.horizon, self.weights = float(horizon), tuple(float(w) for w in weights)
        spec, n_v, n_w = self.spec, *samples
        steps = max(2, round(self.horizon / self.dt))
        t = np.arange(1, steps + 1) * self.dt
        if spec.drive == "holonomic":
            speed, angle = np.meshgrid(np.linspace(0.0, spec.max_linear_velocity, n_v),
                                       np.linspace(-math.pi, math.pi, n_w, endpoint=False), indexing="ij")
            self._speed = speed.ravel()
            vx, vy = speed.ravel() * np.cos(angle.ravel()), speed.ravel() * np.sin(angle.ravel())
            # Offsets in the robot frame, (K, T, 2): straight lines.
            self._local = np.stack([vx[:, None] * t, vy[:, None] * t], axis=-1)
            self._velocity = np.stack([vx, vy], axis=1)
        else:
            v, w = np.meshgrid(np.linspace(0.0, spec.max_linear_velocity, n_v),
                               np.linspace(-spec.max_angular_velocity, spec.max_angular_velocity, n_w), indexing="ij")
            v, w = v.ravel(), w.ravel()
            self._speed = v
            turn = w[:, None] * t
            with np.errstate(divide="ignore", invalid="ignore"):
                radius = np.where(w[:, None] != 0, v[:, None] / w[:, None], 0.0)
                x = np.where(w[:, None] != 0, radius * np.sin(turn), v[:, None] * t)
                y = np.where(w[:, None] != 0, radius * (1.0 - np.cos(turn)), 0.0)
            self._local = np.stack([x, y], axis=-1)  # exact arcs of the differential drive
            self._velocity = np.stack([v, w], axis=1)
        self._t = t

    def act(self) -> NDArray[np.float32]:
        xy, yaw = self.pose()
        carrot = self.follower.carrot(xy)
        if carrot is None:
            return np.zeros(self.spec.action_dim, dtype=np.float32)
        c, s = math.cos(yaw), math.sin(yaw)
        local = self._local
        world = np.stack([xy[0] + c * local[..., 0] - s * local[..., 1], xy[1] + s * local[..., 0] + c * local[..., 1]], axis=-1)
        tmap = self.env.scene.floors[self.task.floor]
        clear = np.asarray(tmap.is_usable(world.reshape(-1, 2), self.spec.radius)).reshape(world.shape[:2])
        positions, velocities, radii = self.crowd()
        nearest = np.full(len(world), np.inf)
        if len(radii):
            future = positions[None] + self._t[:, None, None] * velocities[None]  # (T, P, 2)
            gaps = (np.linalg.norm(world[:, :, None] - future[None], axis=-1) - radii - self.spec.radius).min(axis=2)
            clear &= gaps > 0.0
            nearest = gaps.min(axis=1)
        # The robot stops at once (no acceleration limit): a rollout is admissible when its
        # first step is clear, and it scores by how long it stays clear (DWA's "dist").
        ok = clear[:, 0]
        if not ok.any():  # boxed in: turn in place toward the carrot
            return self._turn(carrot, xy, yaw)
        steps = clear.shape[1]
        free = np.where(clear.all(axis=1), steps, np.argmin(clear, axis=1))  # steps before the first hit
        last = world[np.arange(len(world)), np.maximum(free - 1, 0)]
        clearance = free / steps * np.clip(nearest / 0.5, 0.0, 1.0)
        heading_error = np.zeros(len(world))
        if self.spec.drive != "holonomic":
            aim = np.arctan2(carrot[1] - last[:, 1], carrot[0] - last[:, 0])
            heading_error = np.abs(_wrap(aim - (yaw + self._velocity[:, 1] * self._t[np.maximum(free - 1, 0)])))
        progress = np.hypot(*(carrot - xy)) - np.hypot(carrot[0] - last[:, 0], carrot[1] - last[:, 1])
        w_heading, w_clear, w_speed = self.weights
        reach = self.spec.max_linear_velocity * self._t[-1]
        score = (w_heading * ((np.pi - heading_error) / np.pi + progress / reach)
                 + w_clear * clearance + w_speed * self._speed / self.spec.max_linear_velocity)
        best = int(np.argmax(np.where(ok, score, -np.inf)))
        if progress[best] <= 0.0 and self._speed[best] == 0.0 and nearest[best] > 0.5:
            # DWA's local minimum (a passage it cannot line up with): with no pedestrian
            # near, recover as ROS's move_base does, here by the oracle's own step.
            return self.follower.act()
        action = np.zeros(self.spec.action_dim, dtype=np.float32)
        if self.spec.drive == "holonomic":  # the grid's velocities are in the robot's frame
            action[:2] = np.clip(self._velocity[best] / self.spec.max_linear_velocity, -1.0, 1.0)
            return action
        v, w = self._velocity[best]
        action[0] = v / self.spec.max_linear_velocity
        action[1] = w / self.spec.max_angular_velocity
        return action

    def _turn(self, carrot: NDArray[np.float64], xy: NDArray[np.float64], yaw: float) -> NDArray[np.float32]:
        action = np.zeros(self.spec.action_dim, dtype=np.float32)
        bearing = float(_wrap(math.atan2(carrot[1] - xy[1], carrot[0] - xy[0]) - yaw))
        action[-1] = float(np.clip(bearing / (self.spec.max_angular_velocity * self.dt), -1.0, 1.0))
        return action
