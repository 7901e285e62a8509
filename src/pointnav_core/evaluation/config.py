"""The env an evaluation plays, from an env config: built per episode and checked.

``pointnav eval --env-config FILE`` (``evaluate(env_config=...)``) plays every episode in an
env built from the :class:`~pointnav_core.envs.config.EnvConfig` a policy was trained with;
the dataset still gives each episode's scene, floor, start, goal, goal radius and robot
radius. A dataset made for another robot radius is refused (:func:`check_robot_radius`),
as is a model whose spaces do not fit the env
(:func:`pointnav_core.policies.spaces.check_spaces`), each naming what to change.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

from pointnav_core.datasets.format import PointNavEpisode
from pointnav_core.envs.config import EnvConfig
from pointnav_core.errors import ArgumentError

__all__ = ["RADIUS_TOLERANCE", "check_beside_config", "check_robot_radius", "episode_config"]

def episode_config(config: EnvConfig, ep: PointNavEpisode) -> EnvConfig:
    """``config`` for playing ``ep``: the episode's floor and goal radius (when it records
    one) in the task, and its robot radius (:func:`check_robot_radius` has checked that it
    is the config's)."""
    task = {**config.task, "floor": ep.floor}
    if ep.goal_radius is not None:
        task["goal_tolerance"] = ep.goal_radius
    robot = dataclasses.replace(config.robot, radius=ep.robot_radius)
    return dataclasses.replace(config, task=task, robot=robot)


#: How far (m) an episode's robot radius may be from the env config's (float rounding).
RADIUS_TOLERANCE = 1e-9


def check_robot_radius(config: EnvConfig, episodes: Sequence[PointNavEpisode]) -> None:
    """ValueError naming the first episode made for a robot of another radius than the
    config's, with both radii: a policy must be played by the robot it was trained as."""
    for ep in episodes:
        if abs(ep.robot_radius - config.robot.radius) > RADIUS_TOLERANCE:
            raise ArgumentError(
                f"the env config's robot radius is {config.robot.radius:g} m, but episode "
                f"{ep.episode_id!r} (scene {ep.scene_id!r}) was made for a robot of radius "
                f"{ep.robot_radius:g} m: evaluate on a dataset made for this robot "
                f"(pointnav dataset generate --robot-radius {config.robot.radius:g})"
            )


def check_beside_config(config: Any, **given: Any) -> None:
    """ValueError naming the ``evaluate`` arguments the env config sets that were given
    other values than their defaults beside it."""
    if not isinstance(config, EnvConfig):
        raise ArgumentError(f"env_config must be an EnvConfig or None, got {config!r}")
    from pointnav_core.evaluation.run import DEFAULT_MAX_STEPS

    defaults = {"backend": "kinematic", "max_steps": DEFAULT_MAX_STEPS, "drive": "differential"}
    clash = [name for name, value in given.items() if value != defaults[name]]
    if clash:
        raise ArgumentError(
            f"{', '.join(clash)} given beside env_config, which sets them (backend, "
            f"max_steps, robot.drive): change the config instead"
        )
