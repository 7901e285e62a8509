"""Observation terms: each names itself, declares its size and bounds, and computes its values.

A task's observation is the concatenation of its terms, in order: the Gymnasium ``Dict``
space has one ``Box`` per term (keyed by its name), the flat ``low_dim`` observation is the
terms' values end to end. Spaces, flat order, bounds and the tables in the docs are all
built from the terms (:class:`ObservationLayout`), so a new term is one class.

=======================  ===================  ====  ==============================================
class                    name                 size  values
=======================  ===================  ====  ==============================================
GoalVector               ``xy_pos_to_goal``   2     goal in the robot's heading frame (m), or
                                                    ``(rho, phi)`` (m, rad) when ``polar``
LinearVelocity           ``robot_lin_vel``    3     world linear velocity in the robot frame (m/s)
AngularVelocity          ``robot_ang_vel``    3     world angular velocity in the robot frame
                                                    (rad/s)
=======================  ===================  ====  ==============================================

What a term may read
--------------------
:meth:`ObservationTerm.values` gets a :class:`Frame`: the pose the task recorded at the
last reset or step (the one its rewards and metrics saw), the robot-to-world rotation, the
heading, the goal, and the velocities read from the backend this step, plus ``task`` and
``env`` for anything else (the floor's collision geometry for a range sensor, say). The
frame is refreshed in place before each observation; a term must not keep it.

Examples
--------
>>> import math
>>> frame = Frame()
>>> frame.x, frame.y, frame.cos_yaw, frame.sin_yaw = 1.0, 1.0, 0.0, 1.0  # facing +y
>>> frame.goal_x, frame.goal_y = 1.0, 3.0
>>> GoalVector().values(frame)
(2.0, 0.0)
>>> rho, phi = GoalVector(polar=True).values(frame)
>>> rho, round(phi, 12)
(2.0, 0.0)
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from pointnav_core.errors import ArgumentError

__all__ = [
    "Frame",
    "ObservationTerm",
    "GoalVector",
    "LinearVelocity",
    "AngularVelocity",
    "ObservationLayout",
    "default_observation_terms",
    "markdown_table",
]


class Frame:
    """The per-step snapshot every observation term reads (plain floats, refreshed in place).

    Attributes
    ----------
    x, y, z : float
        Robot position (m) recorded by the task at the last reset or step.
    quat : tuple of 4 floats
        Its orientation ``(x, y, z, w)``.
    rot : tuple of 9 floats
        Robot-to-world rotation matrix of the normalised quaternion, row-major ``R``;
        ``R^T`` maps world vectors into the robot frame.
    cos_yaw, sin_yaw : float
        The heading (the robot's +x axis projected on the floor).
    goal_x, goal_y : float
        This episode's goal (m).
    lin_vel, ang_vel : tuple of 3 floats
        World linear (m/s) and angular (rad/s) velocity read from the backend.
    task, env : object
        The task and its environment, for terms that need more.
    """

    __slots__ = ("x", "y", "z", "quat", "rot", "cos_yaw", "sin_yaw", "goal_x", "goal_y",
                 "lin_vel", "ang_vel", "task", "env")

    def __init__(self) -> None:
        self.x = self.y = self.z = 0.0
        self.quat: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)
        self.rot: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
        self.cos_yaw, self.sin_yaw = 1.0, 0.0
        self.goal_x = self.goal_y = 0.0
        self.lin_vel: tuple[float, float, float] = (0.0, 0.0, 0.0)
        self.ang_vel: tuple[float, float, float] = (0.0, 0.0, 0.0)
        self.task: Any = None
        self.env: Any = None

    def set_pose(self, x: float, y: float, z: float, quat: Sequence[float]) -> None:
        """Record the pose and derive the rotation and the heading from the quaternion."""
        qx, qy, qz, qw = quat
        self.x, self.y, self.z, self.quat = x, y, z, (qx, qy, qz, qw)
        s = 2.0 / (qx * qx + qy * qy + qz * qz + qw * qw)
        r00 = 1.0 - s * (qy * qy + qz * qz)
        r01 = s * (qx * qy - qz * qw)
        r10 = s * (qx * qy + qz * qw)
        r11 = 1.0 - s * (qx * qx + qz * qz)
        self.rot = (
            r00, r01, s * (qx * qz + qy * qw),
            r10, r11, s * (qy * qz - qx * qw),
            s * (qx * qz - qy * qw), s * (qy * qz + qx * qw), 1.0 - s * (qx * qx + qy * qy),
        )
        # yaw = atan2(R10, R00); when +x points straight up or down, take it from +y.
        h = math.hypot(r00, r10)
        if h > 1e-12:
            self.cos_yaw, self.sin_yaw = r00 / h, r10 / h
        else:
            yaw = math.atan2(-r01, r11)
            self.cos_yaw, self.sin_yaw = math.cos(yaw), math.sin(yaw)


def _to_robot_frame(rot: tuple[float, ...], v: tuple[float, float, float]) -> tuple[float, float, float]:
    """``R^T v``: a world vector in the robot frame."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rot
    vx, vy, vz = v
    return (
        r00 * vx + r10 * vy + r20 * vz,
        r01 * vx + r11 * vy + r21 * vz,
        r02 * vx + r12 * vy + r22 * vz,
    )


class ObservationTerm:
    """Base class: one named part of the observation.

    Subclasses set :attr:`name` and :attr:`size` and implement :meth:`bounds` and
    :meth:`values`; :meth:`reset` is optional.

    Attributes
    ----------
    name : str
        Key of the term in the ``Dict`` observation (and in the task's ``observation_terms``).
    size : int
        Number of float32 values the term contributes.
    doc_rows : tuple of (str, str, str)
        Per value: what it is (with its unit), its lower and its upper bound, as the env
        docs' observation table shows them (:func:`markdown_table`).
    shape : tuple of int or None
        Shape of the term's array in the ``Dict`` observation; None means ``(size,)``. The
        flat observation holds its values row by row.
    dtype : numpy.dtype
        Dtype of the term's array in the ``Dict`` observation (float32 unless declared);
        the flat observation is float32 throughout.
    array_values : bool
        Whether :meth:`values` returns a numpy array (sensors with many values) rather than
        a sequence of floats; the layout then copies and clips it with numpy.
    """

    name: ClassVar[str] = "observation"
    size: ClassVar[int] = 0
    doc_rows: ClassVar[tuple[tuple[str, str, str], ...]] = ()
    shape: tuple[int, ...] | None = None
    dtype: np.dtype[Any] = np.dtype(np.float32)
    array_values: ClassVar[bool] = False

    def bounds(self, task: Any, env: Any) -> tuple[Sequence[float], Sequence[float]]:
        """``(low, high)``, ``size`` finite floats each; called when the task meets ``env``."""
        raise NotImplementedError(f"{type(self).__name__} must implement bounds()")

    def reset(self, task: Any, env: Any) -> None:
        """Clear per-episode state; called by the task at every reset, after it lands the robot."""

    def values(self, frame: Frame) -> Sequence[float]:
        """The term's ``size`` values at this step (clipped to the bounds by the task)."""
        raise NotImplementedError(f"{type(self).__name__} must implement values()")

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


def _floor_reach(task: Any, env: Any) -> float:
    """The floor's diagonal plus 1 m (m): how far a goal can be from a robot on or by it."""
    xmin, xmax, ymin, ymax = env.scene.floors[task.floor].extent
    return math.hypot(xmax - xmin, ymax - ymin) + 1.0


class GoalVector(ObservationTerm):
    """The goal relative to the robot, in its heading frame (+x ahead, +y left).

    Parameters
    ----------
    polar : bool
        ``(rho, phi)``: distance (m) and bearing (rad, in ``(-pi, pi]``) instead of ``(x, y)``
        (m). Bounded by the floor's diagonal plus 1 m (a robot may fall off an edge).
    """

    name = "xy_pos_to_goal"
    size = 2
    doc_rows = (
        ("goal x relative to the robot (m)", "-D", "D"),
        ("goal y relative to the robot (m)", "-D", "D"),
    )

    def __init__(self, polar: bool = False) -> None:
        self.polar = bool(polar)

    def bounds(self, task: Any, env: Any) -> tuple[Sequence[float], Sequence[float]]:
        reach = _floor_reach(task, env)
        if self.polar:
            return (0.0, -math.pi), (reach, math.pi)
        return (-reach, -reach), (reach, reach)

    def values(self, frame: Frame) -> tuple[float, float]:
        dx, dy = frame.goal_x - frame.x, frame.goal_y - frame.y
        c, s = frame.cos_yaw, frame.sin_yaw
        lx, ly = c * dx + s * dy, c * dy - s * dx
        if not self.polar:
            return lx, ly
        rho = math.hypot(lx, ly)
        phi = math.atan2(ly, lx) if rho > 0.0 else 0.0
        return rho, (math.pi if phi == -math.pi else phi)

    def __repr__(self) -> str:
        return f"GoalVector(polar={self.polar})"


class LinearVelocity(ObservationTerm):
    """The robot's world linear velocity in its own frame (m/s), within sqrt(2) times its top speed."""

    name = "robot_lin_vel"
    size = 3
    doc_rows = (
        ("linear velocity x (m/s)", "-v", "v"),
        ("linear velocity y (m/s)", "-v", "v"),
        ("linear velocity z (m/s, negative when falling)", "-v", "v"),
    )

    def bounds(self, task: Any, env: Any) -> tuple[Sequence[float], Sequence[float]]:
        v = math.sqrt(2.0) * env.robots[task.robot_idn].max_linear_velocity  # holonomic diagonal
        return (-v, -v, -v), (v, v, v)

    def values(self, frame: Frame) -> tuple[float, float, float]:
        return _to_robot_frame(frame.rot, frame.lin_vel)


class AngularVelocity(ObservationTerm):
    """The robot's world angular velocity in its own frame (rad/s), within its top yaw rate."""

    name = "robot_ang_vel"
    size = 3
    doc_rows = (
        ("angular velocity x (rad/s)", "-w", "w"),
        ("angular velocity y (rad/s)", "-w", "w"),
        ("angular velocity z, the yaw rate (rad/s)", "-w", "w"),
    )

    def bounds(self, task: Any, env: Any) -> tuple[Sequence[float], Sequence[float]]:
        w = env.robots[task.robot_idn].max_angular_velocity
        return (-w, -w, -w), (w, w, w)

    def values(self, frame: Frame) -> tuple[float, float, float]:
        return _to_robot_frame(frame.rot, frame.ang_vel)


def default_observation_terms(goal_in_polar: bool = False) -> list[ObservationTerm]:
    """OmniGibson's ``low_dim`` observation: goal vector, linear and angular velocity."""
    return [GoalVector(polar=goal_in_polar), LinearVelocity(), AngularVelocity()]


class ObservationLayout:
    """Where each term's values sit in the flat observation, and the bounds of them all.

    Parameters
    ----------
    terms : sequence of ObservationTerm
        In observation order; names must be unique.
    low, high : sequence of float
        The bounds of every value, in flat order (see :meth:`from_terms`).
    """

    def __init__(self, terms: Sequence[ObservationTerm], low: Sequence[float], high: Sequence[float]) -> None:
        self.terms = tuple(terms)
        self.low = tuple(float(v) for v in low)
        self.high = tuple(float(v) for v in high)
        slices: dict[str, slice] = {}
        start = 0
        for term in self.terms:
            slices[term.name] = slice(start, start + term.size)
            start += term.size
        self.slices = slices
        self.size = start
        # Terms whose values are arrays, or whose Dict entry is not a flat float32 vector,
        # take the numpy paths of values() and split(); the built-in terms never do.
        self._arrays = any(term.array_values for term in self.terms)
        self._low_arr = np.array(self.low, dtype=np.float64)
        self._high_arr = np.array(self.high, dtype=np.float64)
        self._shaped = {
            term.name: (self.slices[term.name], term.shape, np.dtype(term.dtype))
            for term in self.terms
            if term.shape is not None or np.dtype(term.dtype) != np.float32
        }

    @classmethod
    def from_terms(cls, terms: Sequence[ObservationTerm], task: Any, env: Any) -> ObservationLayout:
        """Ask every term for its bounds and check them (``ValueError`` naming the term)."""
        low: list[float] = []
        high: list[float] = []
        for term in terms:
            lo, hi = (tuple(float(v) for v in b) for b in term.bounds(task, env))
            if len(lo) != term.size or len(hi) != term.size:
                raise ArgumentError(
                    f"observation term {term.name!r} must give {term.size} low and high bounds, "
                    f"got {len(lo)} and {len(hi)}"
                )
            if not all(math.isfinite(a) and math.isfinite(b) and a <= b for a, b in zip(lo, hi)):
                raise ArgumentError(
                    f"observation term {term.name!r} bounds must be finite with low <= high, "
                    f"got low={list(lo)}, high={list(hi)}"
                )
            low += lo
            high += hi
        return cls(terms, low, high)

    def values(self, frame: Frame) -> list[float] | NDArray[np.float64]:
        """Every term's values at this step, end to end, clipped to the bounds.

        A list of floats; a float64 array when a term gives its values as an array.
        """
        if self._arrays:
            flat = np.empty(self.size, dtype=np.float64)
            for term in self.terms:
                flat[self.slices[term.name]] = term.values(frame)
            # maximum/minimum: np.clip's argument checks cost more than the clipping.
            np.maximum(flat, self._low_arr, out=flat)
            return np.minimum(flat, self._high_arr, out=flat)
        out: list[float] = []
        for term in self.terms:
            out += term.values(frame)
        return [lo if v < lo else hi if v > hi else v for v, lo, hi in zip(out, self.low, self.high)]

    def split(self, flat: NDArray[np.float32]) -> dict[str, NDArray[Any]]:
        """The ``Dict`` observation: one array per term, in term order.

        Views of ``flat``, except for a term with a declared ``shape`` or ``dtype``, which
        gets ``flat``'s values reshaped and cast (a fresh array).
        """
        out = {name: flat[s] for name, s in self.slices.items()}
        for name, (s, shape, dtype) in self._shaped.items():
            value = flat[s].astype(dtype)
            out[name] = value.reshape(shape) if shape is not None else value
        return out

    def space_bounds(self, name: str, low: NDArray[np.float32], high: NDArray[np.float32]) -> tuple[Any, Any, tuple[int, ...], np.dtype[Any]]:
        """``(low, high, shape, dtype)`` of term ``name``'s ``Box`` in the ``Dict`` space,
        from the flat bounds ``low`` and ``high``."""
        s = self.slices[name]
        if name not in self._shaped:
            return low[s], high[s], (s.stop - s.start,), np.dtype(np.float32)
        _, shape, dtype = self._shaped[name]
        shape = shape if shape is not None else (s.stop - s.start,)
        return low[s].reshape(shape).astype(dtype), high[s].reshape(shape).astype(dtype), shape, dtype


def markdown_table(terms: Sequence[ObservationTerm]) -> str:
    """The observation table of the env docs (Num, Key, Observation, Min, Max), one row
    per value in flat order, from each term's :attr:`~ObservationTerm.doc_rows`."""
    rows = [("Num", "Key", "Observation", "Min", "Max")]
    for term in terms:
        if len(term.doc_rows) != term.size:
            raise ArgumentError(f"observation term {term.name!r} must have {term.size} doc_rows, got {len(term.doc_rows)}")
        for what, lo, hi in term.doc_rows:
            rows.append((str(len(rows) - 1), f"`{term.name}`", what, lo, hi))
    widths = [max(len(r[i]) for r in rows) for i in range(5)]
    line = lambda r: "| " + " | ".join(c.ljust(w) for c, w in zip(r, widths)) + " |"  # noqa: E731
    return "\n".join([line(rows[0]), "|" + "|".join("-" * (w + 2) for w in widths) + "|", *(line(r) for r in rows[1:])])
