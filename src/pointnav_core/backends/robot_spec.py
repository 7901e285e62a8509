"""What a backend needs to know about one robot: :class:`RobotSpec` (size, speed limits,
drive) and how an action in ``[-1, 1]`` becomes its velocity command."""

from __future__ import annotations

import math
import types
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.utils import validation

__all__ = ["DRIVES", "RobotSpec"]

#: Drive types and the meaning of their action vector (robot frame: +x ahead, +y left).
DRIVES = types.MappingProxyType({"differential": ("v", "w"), "holonomic": ("vx", "vy", "w")})


# Dtypes whose ndarray.tolist() gives exactly the float64 values of asarray(float64).
_FLOAT_DTYPES = frozenset((np.dtype(np.float32), np.dtype(np.float64)))


def _positive(name: str, value: Any, *, strict: bool, unit: str) -> float:
    return validation.real(name, value, minimum=0.0, strict=strict, unit=unit)


@dataclass(frozen=True, kw_only=True)
class RobotSpec:
    """What a backend needs to know about one robot: its size, speed limits and drive.

    Parameters
    ----------
    radius : float
        Radius of the robot's footprint disc in metres, >= 0 (0 is a point robot).
    max_linear_velocity : float
        Speed in m/s that an action component of 1 maps to, > 0.
    max_angular_velocity : float
        Yaw rate in rad/s that an action component of 1 maps to, > 0.
    drive : {"differential", "holonomic"}
        ``"differential"``: action ``(v, w)``, forward speed and yaw rate.
        ``"holonomic"``: action ``(vx, vy, w)``, velocities in the robot frame (+x ahead,
        +y to the left) and yaw rate.

    Examples
    --------
    >>> spec = RobotSpec(radius=0.2, drive="holonomic")
    >>> spec.action_dim
    3
    >>> spec.scale_action([1.0, -2.0, 0.5]).tolist()  # -2 is clipped to -1
    [0.5, -0.5, 0.75]
    >>> RobotSpec(drive="tank")
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: drive must be one of ['differential', 'holonomic'], got 'tank'
    """

    radius: float = 0.18
    max_linear_velocity: float = 0.5
    max_angular_velocity: float = 1.5
    drive: str = "differential"

    if TYPE_CHECKING:
        # Set in __post_init__; declared here for type checkers only, so not a field.
        _maxima: tuple[float, ...]

    def __post_init__(self) -> None:
        # Store floats, so that a spec built from numpy scalars or ints compares and hashes
        # like one built from Python floats.
        set_ = object.__setattr__
        set_(self, "radius", _positive("radius", self.radius, strict=False, unit="metres"))
        set_(
            self,
            "max_linear_velocity",
            _positive("max_linear_velocity", self.max_linear_velocity, strict=True, unit="m/s"),
        )
        set_(
            self,
            "max_angular_velocity",
            _positive("max_angular_velocity", self.max_angular_velocity, strict=True, unit="rad/s"),
        )
        if not isinstance(self.drive, str) or self.drive not in DRIVES:
            raise ArgumentError(f"drive must be one of {sorted(DRIVES)}, got {self.drive!r}")
        lin, ang = self.max_linear_velocity, self.max_angular_velocity
        # Velocity each action component maps to: derived, so not a field (asdict, eq).
        set_(self, "_maxima", (lin, ang) if self.drive == "differential" else (lin, lin, ang))

    @property
    def action_dim(self) -> int:
        """Length of an action vector: 2 for differential drive, 3 for holonomic."""
        return len(self._maxima)

    def scale_action(self, action: ArrayLike) -> NDArray[np.float64]:
        """Turn an action in ``[-1, 1]`` into velocities.

        Parameters
        ----------
        action : array_like, shape (action_dim,)
            ``(v, w)`` for differential drive or ``(vx, vy, w)`` for holonomic drive, each
            in ``[-1, 1]``; values outside are clipped.

        Returns
        -------
        ndarray of float64, shape (action_dim,)
            Velocities: linear components in m/s (robot frame), the yaw rate in rad/s.

        Raises
        ------
        ValueError
            If ``action`` has the wrong shape or holds NaN or infinity.

        Examples
        --------
        >>> RobotSpec().scale_action([0.5, -1.0]).tolist()
        [0.25, -1.5]
        >>> RobotSpec().scale_action([float("nan"), 0.0])
        Traceback (most recent call last):
        ...
        pointnav_core.errors.ArgumentError: action must be finite, got [nan, 0.0]
        """
        return np.array(self.scale_action_floats(action))

    def scale_action_floats(self, action: ArrayLike) -> tuple[float, ...]:
        """:meth:`scale_action` as a tuple of Python floats, without an output array.

        Same checks, clipping and errors; for a backend's ``step``, which scales every
        robot's action on every control step (plain floats beat numpy for 2 or 3 numbers).

        Examples
        --------
        >>> RobotSpec().scale_action_floats(np.array([0.5, -1.0], np.float32))
        (0.25, -1.5)
        """
        maxima = self._maxima
        if type(action) is np.ndarray and action.ndim == 1 and action.dtype in _FLOAT_DTYPES:
            # What env.step passes: tolist gives the float64 values, without a copy first.
            values = action.tolist()
            ok = len(values) == len(maxima)
        else:
            try:
                values = np.asarray(action, dtype=np.float64).tolist()
            except (TypeError, ValueError):
                values = None
            ok = (
                isinstance(values, list)
                and len(values) == len(maxima)
                and not any(isinstance(v, list) for v in values)
            )
        if not ok:
            shape = getattr(np.asarray(action, dtype=object), "shape", None)
            raise ArgumentError(
                f"action must have shape ({len(maxima)},) for a {self.drive} drive "
                f"({', '.join(DRIVES[self.drive])}), got shape {shape}"
            )
        out = []
        for v, m in zip(values, maxima):
            if not -math.inf < v < math.inf:  # also False for NaN
                raise ArgumentError(f"action must be finite, got {values}")
            out.append(m if v >= 1.0 else -m if v <= -1.0 else v * m)
        return tuple(out)
