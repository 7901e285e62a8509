"""The range scan: a planar lidar at the robot's centre, as an observation term.

:class:`RangeScan` (observation key ``"scan"``) casts ``n_rays`` rays from the robot's
centre, spread over ``fov`` around its heading, and reports for each the distance in metres
to the first thing it meets: the floor's OBSTACLE cells, the map's edge, the floor plan's
obstacle polygons (:class:`~pointnav_core.sensors.raycast.ScanGeometry`: the geometry the
backends collide with) and the discs of the other robots present on the same floor. VOID
(holes, stairwells) is not seen. Ranges are capped at ``max_range``.

Readings
--------
In order, for each ray:

1. the exact range ``d`` (:func:`~pointnav_core.sensors.raycast.cast_rays`), at most
   ``max_range``;
2. a return closer than ``min_range`` is no return: it reads ``max_range``, as a real lidar
   reports nothing inside its minimum range (a robot standing clear of walls, with a radius
   above ``min_range``, never sees one);
3. with ``noise_std > 0``, Gaussian noise of that standard deviation (m) is added to the
   readings below ``max_range``, and the result is clipped to ``[0, max_range]``;
4. with ``dropout > 0``, each reading is lost (reads ``max_range``) with that probability.

Noise and dropout are counter-based draws (:mod:`pointnav_core.sensors.noise`): a hash of
the env's seed (the entropy of ``np_random``'s seed sequence), the number of resets since
that seeding, the robot's index, the step within the episode, the ray and the channel. No
generator is drawn from, so the same seed gives the same noisy scans, turning noise on
changes no episode, and the batched engine's world ``w`` seeded with ``s`` reads the same
numbers as a single env reset with seed ``s + w`` (:class:`~pointnav_core.vector.scan.VectorScan`).

Examples
--------
>>> scan = RangeScan(n_rays=4, fov=2 * np.pi, max_range=3.0)
>>> scan.angles.round(4).tolist()  # robot frame: 0 ahead, positive to the left
[-3.1416, -1.5708, 0.0, 1.5708]
>>> RangeScan(n_rays=3, fov=np.pi).angles.round(4).tolist()  # both ends included
[-1.5708, 0.0, 1.5708]
>>> RangeScan(n_rays=0)
Traceback (most recent call last):
...
pointnav_core.errors.ArgumentError: n_rays must be an integer >= 1, got 0
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.backends.protocol import float_twin
from pointnav_core.errors import ArgumentError
from pointnav_core.sensors._checks import check_int, check_number
from pointnav_core.sensors.noise import episode_key, scan_noise, seed_entropy
from pointnav_core.sensors.raycast import ScanGeometry, cast_pose_compiled, cast_rays
from pointnav_core.task.observations import Frame, ObservationTerm
from pointnav_core.transforms.planar import heading_of

__all__ = ["RangeScan", "ScanShare", "other_robot_discs", "pedestrian_discs", "scan_angles"]

_TWO_PI = 2.0 * math.pi


def scan_angles(n_rays: int, fov: float) -> NDArray[np.float64]:
    """Ray bearings (rad, robot frame, 0 ahead, positive left), symmetric about ahead.

    ``n_rays`` evenly over ``[-fov/2, fov/2]`` with both ends when ``fov < 2 pi``; over a
    full turn the end that would repeat the start is left out. One ray points ahead.
    """
    if n_rays == 1:
        return np.zeros(1)
    if fov >= _TWO_PI - 1e-12:
        return -math.pi + _TWO_PI * np.arange(n_rays) / n_rays
    return np.linspace(-fov / 2.0, fov / 2.0, n_rays)


def other_robot_discs(env: Any, idn: int, floor: int) -> NDArray[np.float64]:
    """``(M, 3)`` discs ``(x, y, radius)`` of the robots other than ``idn`` present on ``floor``.

    Robots are read through the backend protocol (``is_present``, ``get_robot_floor``,
    ``get_pose``, or its float twin).
    """
    backend = env.backend
    robots = env.robots
    if len(robots) == 1:
        return np.zeros((0, 3))
    pose = float_twin(backend, "get_pose_floats")
    out = []
    for j, spec in enumerate(robots):
        if j == idn or not backend.is_present(j) or backend.get_robot_floor(j) != floor:
            continue
        if pose is not None:
            x, y = pose(j)[:2]
        else:
            x, y = backend.get_pose(j)[0][:2].tolist()
        out.append((x, y, spec.radius))
    return np.array(out, dtype=np.float64).reshape(-1, 3)


def pedestrian_discs(env: Any, floor: int) -> NDArray[np.float64]:
    """``(P, 3)`` discs ``(x, y, radius)`` of the env's pedestrians on ``floor`` (its
    ``crowd``, :mod:`pointnav_core.crowds`); empty without them."""
    crowd = getattr(env, "crowd", None)
    if crowd is None or crowd.floor != floor:
        return np.zeros((0, 3))
    return crowd.discs()


class RangeScan(ObservationTerm):
    """A planar range scan from the robot's centre (observation key ``"scan"``).

    Parameters
    ----------
    n_rays : int
        Number of rays, >= 1 (default 64).
    fov : float
        Field of view (rad) in ``(0, 2 pi]``, centred ahead (default ``2 pi``, a full turn).
    min_range : float
        Metres, >= 0 and below ``max_range``; a nearer return reads ``max_range``
        (default 0.05, OmniGibson's ScanSensor).
    max_range : float
        Metres, > 0: the longest reading (default 5.6, iGibson's scan).
    noise_std : float
        Standard deviation (m) of Gaussian noise on the readings, >= 0 (default 0).
    dropout : float
        Probability in ``[0, 1]`` that a reading is lost and reads ``max_range`` (default 0).

    Attributes
    ----------
    angles : ndarray of float64, shape (n_rays,)
        Ray bearings (rad) in the robot frame: 0 ahead, positive to the left (read-only).
    size : int
        ``n_rays``: the scan's values in the flat observation, in the order of ``angles``.

    Raises
    ------
    ValueError
        Naming the parameter, for a value of the wrong type or out of range.
    """

    name = "scan"
    array_values = True

    def __init__(
        self,
        n_rays: int = 64,
        fov: float = _TWO_PI,
        min_range: float = 0.05,
        max_range: float = 5.6,
        noise_std: float = 0.0,
        dropout: float = 0.0,
    ) -> None:
        self.n_rays = check_int("n_rays", n_rays, 1)
        self.fov = check_number("fov", fov, low=0.0, strict_low=True, high=_TWO_PI, unit="rad")
        self.max_range = check_number("max_range", max_range, low=0.0, strict_low=True, unit="m")
        self.min_range = check_number("min_range", min_range, low=0.0, unit="m")
        if self.min_range >= self.max_range:
            raise ArgumentError(
                f"min_range must be below max_range ({self.max_range} m), got {min_range!r}"
            )
        self.noise_std = check_number("noise_std", noise_std, low=0.0, unit="m")
        self.dropout = check_number("dropout", dropout, low=0.0, high=1.0)
        self.size = self.n_rays
        angles = scan_angles(self.n_rays, self.fov)
        angles.flags.writeable = False
        self.angles = angles
        self._geometry: ScanGeometry | None = None
        self._share: ScanShare | None = None
        # The noise keys: the seeding (its seed sequence), its base, the resets since, the episode's key.
        self._seeding: Any = None
        self._base = 0
        self._episode = -1
        self._key: Any = None
        # The pose goes in through small buffers (origin, yaw, the yaw's cosine and sine):
        # cheaper than converting tuples each step; the bearings' cosines and sines are fixed.
        self._pose = (np.zeros((1, 2)), np.zeros(1), np.zeros(2))
        self._directions = (np.cos(angles), np.sin(angles))
        #: ``(x, y, yaw, readings)`` of the last observation (renderers draw it), or None.
        self.last_scan: tuple[float, float, float, NDArray[np.float64]] | None = None

    @property
    def doc_rows(self) -> tuple[tuple[str, str, str], ...]:  # type: ignore[override]
        return tuple(
            (f"range along the ray at {math.degrees(a):+.1f} deg (m)", "0", f"{self.max_range:g}")
            for a in self.angles.tolist()
        )

    def bounds(self, task: Any, env: Any) -> tuple[Sequence[float], Sequence[float]]:
        return (0.0,) * self.n_rays, (self.max_range,) * self.n_rays

    def reset(self, task: Any, env: Any) -> None:
        tmap = env.scene.floors[task.floor]
        self._share = None
        tasks = getattr(env, "tasks", None)
        if isinstance(tasks, (list, tuple)) and len(tasks) > 1:
            # Robots of a multi-robot env with alike scans cast together (ScanShare).
            for other in tasks:
                peer = other.observation_terms.get(self.name)
                share = getattr(peer, "_share", None)
                if peer is not self and share is not None and share.fits(self, tmap):
                    self._share = share
                    break
            else:
                if self._geometry is None or self._geometry.tmap is not tmap:
                    self._geometry = ScanGeometry(tmap)
                self._share = ScanShare(self._geometry, self.angles, self.max_range)
            self._share.members[task.robot_idn] = self
            self._geometry = self._share.geometry
        if self._geometry is None or self._geometry.tmap is not tmap:
            self._geometry = ScanGeometry(tmap)
        if self.noise_std > 0.0 or self.dropout > 0.0:
            seeding, base = seed_entropy(env.np_random)
            if seeding is not self._seeding:  # a new seeding: episodes count from 0 again
                self._seeding, self._base, self._episode = seeding, base, -1
            self._episode += 1
            self._key = episode_key(self._base, self._episode)
        self.last_scan = None

    def ranges(self, frame: Frame) -> NDArray[np.float64]:
        """The exact ranges (m) at the frame's pose, before the min-range rule and noise."""
        task, env = frame.task, frame.env
        crowd = getattr(env, "crowd", None)
        if crowd is None and self._share is not None and self._share.geometry.tmap is env.scene.floors[task.floor]:
            shared = self._share.ranges(env, task.robot_idn, task.floor)
            if shared is not None:
                return shared
        if self._geometry is None or self._geometry.tmap is not env.scene.floors[task.floor]:
            self._geometry = ScanGeometry(env.scene.floors[task.floor])
        discs = other_robot_discs(env, task.robot_idn, task.floor) if len(env.robots) > 1 else None
        if crowd is not None:
            walkers = pedestrian_discs(env, task.floor)
            discs = walkers if discs is None else np.concatenate([discs, walkers])
        origin, yaw, heading = self._pose
        origin[0, 0] = frame.x
        origin[0, 1] = frame.y
        yaw[0] = math.atan2(frame.sin_yaw, frame.cos_yaw)
        np.cos(yaw, out=heading[:1])  # as cast_rays turns its rays
        np.sin(yaw, out=heading[1:])
        fast = cast_pose_compiled(self._geometry, origin, heading, self._directions, self.max_range,
                                  None if discs is None else np.ascontiguousarray(discs, dtype=np.float64))
        if fast is not None:
            return fast
        return cast_rays(
            self._geometry, origin, yaw, self.angles, self.max_range,
            discs=discs if discs is not None and len(discs) else None,
        )[0]

    def values(self, frame: Frame) -> NDArray[np.float64]:
        d = self._readings(frame)
        self.last_scan = (frame.x, frame.y, math.atan2(frame.sin_yaw, frame.cos_yaw), d)
        return d

    def _readings(self, frame: Frame) -> NDArray[np.float64]:
        d = self.ranges(frame)
        if self.min_range > 0.0:
            d[d < self.min_range] = self.max_range
        if self._key is not None:
            task = frame.task
            noise, lost = scan_noise(self._key, task.robot_idn, task.episode_length, self.n_rays,
                                     self.noise_std, self.dropout)
            if noise is not None:
                d = np.where(d < self.max_range, d + noise, d)
                np.clip(d, 0.0, self.max_range, out=d)
            if lost is not None:
                d[lost] = self.max_range
        return d

    def __repr__(self) -> str:
        return (
            f"RangeScan(n_rays={self.n_rays}, fov={self.fov:g}, min_range={self.min_range:g}, "
            f"max_range={self.max_range:g}, noise_std={self.noise_std:g}, dropout={self.dropout:g})"
        )


class ScanShare:
    """The scans of several robots of one env, cast together (one batch per step).

    The range scans of a multi-robot env's robots that are alike (same floor, bearings and
    ``max_range``) share one of these: the first robot observed after the world moved
    casts the rays of every robot still in an episode in one :func:`cast_rays` call, and
    the others read their row. The rows are the exact ranges; each scan then applies its
    own ``min_range`` rule, noise and dropout. The batch is keyed by every present robot's
    pose, so it is recast whenever any robot moved.
    """

    def __init__(self, geometry: ScanGeometry, angles: NDArray[np.float64], max_range: float) -> None:
        self.geometry = geometry
        self.angles = angles
        self.max_range = max_range
        self.members: dict[int, RangeScan] = {}
        self._key: tuple[Any, ...] | None = None
        self._rows: dict[int, NDArray[np.float64]] = {}

    def fits(self, scan: RangeScan, tmap: Any) -> bool:
        """Whether ``scan`` on floor ``tmap`` casts the same rays as this batch."""
        return (
            self.geometry.tmap is tmap
            and self.max_range == scan.max_range
            and np.array_equal(self.angles, scan.angles)
        )

    def ranges(self, env: Any, idn: int, floor: int) -> NDArray[np.float64] | None:
        """Robot ``idn``'s exact ranges (a fresh array), or None if it is not in the batch."""
        from pointnav_core.task.lifecycle import TaskState

        backend = env.backend
        pose = float_twin(backend, "get_pose_floats")
        robots = []
        for j, spec in enumerate(env.robots):
            if not backend.is_present(j) or backend.get_robot_floor(j) != floor:
                continue
            if pose is not None:
                x, y, _, qx, qy, qz, qw = pose(j)
            else:
                position, quat = backend.get_pose(j)
                x, y = position[:2].tolist()
                qx, qy, qz, qw = quat.tolist()
            robots.append((j, x, y, qx, qy, qz, qw, spec.radius))
        key = tuple(robots)
        if key != self._key:
            tasks = env.tasks
            cast = [
                k for k, r in enumerate(robots)
                if r[0] == idn or (r[0] in self.members and tasks[r[0]].state is TaskState.RUNNING)
            ]
            rows = cast_rays(
                self.geometry,
                [robots[k][1:3] for k in cast],
                [heading_of(*robots[k][3:7]) for k in cast],
                self.angles,
                self.max_range,
                discs=[(r[1], r[2], r[7]) for r in robots],
                own_disc=cast,
            )
            self._rows = {robots[k][0]: row for k, row in zip(cast, rows)}
            self._key = key
        row = self._rows.get(idn)
        return None if row is None else row.copy()

