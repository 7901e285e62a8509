"""The batched engines' state: typed, immutable records of per-world (per-robot) arrays.

Every field is an array of the engine's namespace (numpy or torch, :mod:`.xp`) with one
entry per world, ``(num_envs,)``, or per robot, ``(num_envs, n_robots)`` in the fleet.
A step builds a new record with :func:`dataclasses.replace` instead of mutating a dict;
the arrays themselves stay writable, so an autoreset writes the reset worlds' entries in
place (which is why the engines copy what they hand out in ``info``).

Examples
--------
>>> import numpy as np
>>> from pointnav_core.vector.xp import make_arrays
>>> state = WorldState.zeros(make_arrays("numpy"), (2,))
>>> state.fall_speed.tolist(), state.steps.dtype.name
([0.0, 0.0], 'int64')
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

from pointnav_core.vector.xp import Arrays

__all__ = ["MOTION_FIELDS", "Motion", "WorldState", "motion_where"]


@dataclass(frozen=True)
class Motion:
    """One control step's outcome for every world (robot), not yet committed.

    Attributes
    ----------
    x, y : array of float64
        Position (m).
    yaw : array of float64
        Heading (rad, not wrapped).
    z : array of float64
        Height (m).
    vx, vy : array of float64
        World-frame planar velocity over the step (m/s).
    yaw_rate : array of float64
        Turn rate over the step (rad/s).
    vz : array of float64
        Vertical velocity over the step (m/s, negative while falling).
    fall_speed : array of float64
        Fall speed after the step (m/s); 0 while the robot stands (:mod:`.falls`).
    """

    x: Any
    y: Any
    yaw: Any
    z: Any
    vx: Any
    vy: Any
    yaw_rate: Any
    vz: Any
    fall_speed: Any


#: The names of :class:`Motion`'s fields, which a :class:`WorldState` shares.
MOTION_FIELDS = tuple(f.name for f in dataclasses.fields(Motion))


def motion_where(xp: Any, mask: Any, new: Motion, old: Motion) -> Motion:
    """``new`` where ``mask`` holds, else ``old``, field by field (``old`` may be a :class:`WorldState`)."""
    return Motion(*(xp.where(mask, getattr(new, name), getattr(old, name)) for name in MOTION_FIELDS))


@dataclass(frozen=True)
class WorldState(Motion):
    """The committed state of every world (robot) of a batched engine.

    The :class:`Motion` fields, then:

    Attributes
    ----------
    goal_x, goal_y : array of float64
        The episode's goal (m).
    start_distance : array of float64
        The start's geodesic distance to the goal (m; inf where the goal is unreachable).
    potential : array of float64
        The potential reward's distance at the last step (m: geodesic, or straight-line
        where the episode has no finite geodesic).
    path_length : array of float64
        Distance travelled this episode (m).
    goal_distance : array of float64
        Geodesic distance to the goal after the last step (m; inf where unreachable).
    goal_field : array of int64
        Index of the episode's goal field in the pool's :class:`~.fields.FieldTables`.
    geodesic_metric : array of bool
        Whether the potential is geodesic (``geodesic_reward`` and a finite start distance).
    steps : array of int64
        Control steps taken this episode.
    collisions : array of int64
        Steps this episode that touched a wall or another robot.
    """

    goal_x: Any
    goal_y: Any
    start_distance: Any
    potential: Any
    path_length: Any
    goal_distance: Any
    goal_field: Any
    geodesic_metric: Any
    steps: Any
    collisions: Any

    @classmethod
    def zeros(cls, arrays: Arrays, shape: tuple[int, ...]) -> WorldState:
        """A state of zeros (``False`` flags) of ``shape`` on ``arrays``' device."""
        typed = {"goal_field": arrays.i64, "geodesic_metric": arrays.boolean, "steps": arrays.i64,
                 "collisions": arrays.i64}
        return cls(**{f.name: arrays.zeros(shape, typed.get(f.name)) for f in dataclasses.fields(cls)})

    def moved(self, motion: Motion, **changes: Any) -> WorldState:
        """This state with ``motion``'s fields and ``changes`` in place of its own."""
        return dataclasses.replace(self, **{name: getattr(motion, name) for name in MOTION_FIELDS}, **changes)

    def start_episodes(self, xp: Any, idx: Any, pool: Any, episode: Any, height: Any, geodesic_reward: Any) -> None:
        """Begin pool episodes ``episode`` in entries ``idx``, in place (the arrays are the
        engine's own; ``info`` hands out copies).

        Parameters
        ----------
        xp : module
            ``numpy`` or ``torch``.
        idx : array of int, shape (k,)
            The worlds to reset.
        pool : EpisodePool or FleetPool
            Its start ``sx``, ``sy`` (m), ``syaw`` (rad), goal ``gx``, ``gy`` (m), ``d0`` (m),
            goal ``field`` and ``fields`` (distances) are read at ``episode``.
        episode : array of int, shape (k,)
            Each reset world's episode in ``pool``.
        height : array of float64, shape (k,)
            Each world's floor height (m); a fleet's robots all stand on it.
        geodesic_reward : bool or bool array
            Whether the potential is geodesic where the start's distance is finite.
        """
        e, p = episode, pool
        for array, src in ((self.x, p.sx), (self.y, p.sy), (self.yaw, p.syaw), (self.goal_x, p.gx),
                           (self.goal_y, p.gy), (self.start_distance, p.d0)):
            array[idx] = src[e]
        self.z[idx] = height if self.z.ndim == 1 else height[:, None] + 0.0 * self.x[idx]
        for array in (self.vx, self.vy, self.vz, self.yaw_rate, self.fall_speed, self.path_length):
            array[idx] = 0.0
        self.goal_field[idx] = p.field[e]
        self.steps[idx] = self.collisions[idx] = 0
        d0 = self.start_distance[idx]
        geo = geodesic_reward & (d0 < math.inf)
        self.geodesic_metric[idx] = geo
        x, y = self.x[idx], self.y[idx]
        dist = p.fields.distance(p.field[e], x, y)
        self.goal_distance[idx] = dist
        l2 = xp.sqrt((self.goal_x[idx] - x) ** 2 + (self.goal_y[idx] - y) ** 2)
        self.potential[idx] = xp.where(geo, xp.where(dist < math.inf, dist, d0), l2)
