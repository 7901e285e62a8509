"""The envs' side of a crowd (:mod:`pointnav_core.crowds`): building it from the
``pedestrians`` argument, the termination it adds, placing it at a reset, the robots it
walks beside, and the positions kept for an episode's social metrics. The single and the
multi-robot envs share it."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.backends.protocol import float_twin
from pointnav_core.envs.common import edit_task
from pointnav_core.transforms.planar import heading_of

__all__ = [
    "CrowdRobots", "CrowdTrack", "add_pedestrian_termination", "crowd_robots", "episode_crowd", "make_crowd", "pose_twins",
    "spawn_crowd",
]

def make_crowd(pedestrians: Any, scene: Any) -> Any:
    """The env's :class:`~pointnav_core.crowds.Crowd` for ``pedestrians={...}``, or None."""
    from pointnav_core.crowds import Crowd, make_pedestrians

    config = make_pedestrians(pedestrians)
    return None if config is None else Crowd(config, scene)


def add_pedestrian_termination(task: Any, crowd: Any, name: str = "task") -> Any:
    """``task`` (None, a dict, or a list of them) with
    :class:`~pointnav_core.task.PedestrianCollision` among its ``termination_conditions``
    when the crowd's contacts end episodes."""
    from pointnav_core.task import PedestrianCollision

    if crowd is None or not crowd.config.end_on_collision:
        return task

    def edit(entry: Mapping[str, Any], where: str) -> Mapping[str, Any]:
        given = list(entry.get("termination_conditions") or ())
        if any(getattr(term, "name", None) == PedestrianCollision.name for term in given):
            return entry
        return {**entry, "termination_conditions": [*given, PedestrianCollision()]}

    return edit_task(task, name, edit, (
        "pedestrians['end_on_collision'] cannot change a ready PointNavigationTask ({name}): pass "
        "the task as a dict of its arguments, or put PedestrianCollision() in its termination_conditions"
    ))


def pose_twins(backend: Any) -> tuple[Any, Any]:
    """``backend``'s bound ``get_pose_floats`` and ``get_velocity_floats`` twins, each None
    where it must not be read (:func:`~pointnav_core.backends.protocol.float_twin`). The env
    binds them at each reset, as the task binds its own at load: finding them costs more
    than reading them."""
    return float_twin(backend, "get_pose_floats"), float_twin(backend, "get_velocity_floats")


class CrowdRobots:
    """The env's robots as its crowd sees them at a control step, read once per step
    through the backend's float twins (:func:`pose_twins`, bound for the episode): the
    discs ``(x, y, radius)`` (m) and planar velocities (m/s) of those present on the
    crowd's floor, in rows kept from step to step, and every robot's pose, which its
    :class:`CrowdTrack` records (the crowd does not move the robots)."""

    def __init__(self, env: Any) -> None:
        self.twins = pose_twins(env.backend)
        n = len(env.robots)
        self._radius = [spec.radius for spec in env.robots]
        self._discs, self._velocities = np.empty((n, 3)), np.empty((n, 2))
        #: Each robot's ``(x, y, z, qx, qy, qz, qw)`` at the last :meth:`read`.
        self.poses: list[tuple[float, ...]] = [()] * n

    def read(self, env: Any) -> tuple[list[int], NDArray[np.float64], NDArray[np.float64]]:
        """The present robots on the crowd's floor now: their indices, ``(M, 3)`` discs and
        ``(M, 2)`` velocities (views of the kept rows, good until the next read)."""
        backend, floor = env.backend, env.crowd.floor
        pose, velocity = self.twins
        ids: list[int] = []
        discs, velocities = self._discs, self._velocities
        for j in range(len(self.poses)):
            if pose is not None:  # the same numbers as get_pose, without its arrays
                p = self.poses[j] = pose(j)
            else:
                position, quat = backend.get_pose(j)
                p = self.poses[j] = (*position.tolist(), *quat.tolist())
            if not backend.is_present(j) or backend.get_robot_floor(j) != floor:
                continue
            vx, vy = velocity(j)[:2] if velocity is not None else backend.get_velocity(j)[0][:2].tolist()
            m = len(ids)
            discs[m, 0], discs[m, 1], discs[m, 2] = p[0], p[1], self._radius[j]
            velocities[m, 0], velocities[m, 1] = vx, vy
            ids.append(j)
        return ids, discs[: len(ids)], velocities[: len(ids)]


def crowd_robots(env: Any) -> tuple[list[int], NDArray[np.float64], NDArray[np.float64]]:
    """The env's robots present on its crowd's floor, read once (:meth:`CrowdRobots.read`,
    in fresh arrays): their indices, ``(M, 3)`` discs ``(x, y, radius)`` and ``(M, 2)``
    planar velocities (m, m/s)."""
    return CrowdRobots(env).read(env)


def spawn_crowd(env: Any, record: Any = None) -> None:
    """Place the env's pedestrians for a new episode on its task's floor, clear of its
    robots: exactly the crowd of ``record`` (a dataset episode's ``pedestrians``) when given,
    else drawn from a generator drawn from ``env.np_random`` (so the reset seed fixes the crowd)."""
    task = env.task if hasattr(env, "task") else env.tasks[0]
    env.crowd.floor = task.floor
    # A recorded crowd draws nothing here: the env's stream is the same with or without it.
    seed = 0 if record is not None else int(env.np_random.integers(2**63))
    _, robots, _ = crowd_robots(env)
    env.crowd.spawn(task.floor, np.random.default_rng(seed), robots, record)


def episode_crowd(given: Any, record: Any, scene: Any) -> Any:
    """The crowd an env plays an episode with: its own (``given``, from ``pedestrians=...``;
    None without), or, for an episode that records a crowd (``record``, its
    ``pedestrians``) in an env without one, a crowd of the default pedestrian settings
    (docs/decisions.md, "Crowds")."""
    if given is not None or record is None:
        return given
    return make_crowd({"count": len(record)}, scene)


class CrowdTrack:
    """A robot's and the pedestrians' positions at every control step of its episode, for
    its social metrics (:func:`pointnav_core.task.social_metrics`) at the end.

    ``idn`` is the robot's index (default: the single env's robot)."""

    def __init__(self, env: Any, idn: int | None = None) -> None:
        self.idn = env.task.robot_idn if idn is None else idn
        #: The backend's float twins (:func:`pose_twins`), bound for the episode.
        self.twins = pose_twins(env.backend)
        self.robot: list[tuple[float, float]] = []
        self.heading: list[float] = []
        self.pedestrians: list[NDArray[np.float64]] = []
        self.record(env)

    def record(self, env: Any, pose: tuple[float, ...] | None = None) -> None:
        """Add the env's positions now (after a control step, or at the reset): the robot's
        ``pose`` ``(x, y, z, qx, qy, qz, qw)`` where it was read already
        (:attr:`CrowdRobots.poses`), else read here."""
        if pose is None:
            twin = self.twins[0]
            if twin is not None:  # the same numbers as get_pose, without its arrays
                pose = twin(self.idn)
            else:
                position, quat = env.backend.get_pose(self.idn)
                pose = (*position.tolist(), *quat.tolist())
        x, y, _, qx, qy, qz, qw = pose
        self.robot.append((x, y))
        self.heading.append(heading_of(qx, qy, qz, qw))
        self.pedestrians.append(env.crowd.positions.copy())

    def metrics(self, env: Any, info: Mapping[str, Any]) -> dict[str, float | None]:
        """The episode's social metrics, from what was recorded and the task's ``info``."""
        from pointnav_core.task import recorded_social_metrics

        spec = env.robots[self.idn]
        task = env.tasks[self.idn] if hasattr(env, "tasks") else env.task
        return recorded_social_metrics(
            self.robot, self.heading, np.array(self.pedestrians).reshape(len(self.robot), env.crowd.n, 2),
            dt=1.0 / env.action_frequency, robot_radius=spec.radius, pedestrian_radii=env.crowd.radius,
            success=bool(info["success"]), geodesic_dist=float(info["geodesic_dist"]),
            max_speed=spec.max_linear_velocity, goal=task.get_goal_pos()[:2],
        )
