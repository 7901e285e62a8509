"""Hypothesis strategies for orientations and vectors: unit quaternions, yaws, Euler angles, finite vectors.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import strategies as st

from pointnav_core.errors import ArgumentError

__all__ = [
    "unit_quaternions",
    "yaws",
    "euler_angles",
    "finite_vectors",
]


@st.composite
def unit_quaternions(draw: st.DrawFn) -> np.ndarray:
    """Unit quaternions ``(x, y, z, w)`` as float64 arrays of shape (4,), covering all rotations.

    Built without filtering: one component, the lead, gets a magnitude in [0.5, 1] and the
    others lie in [-1, 1], so the norm is at least 0.5 before normalising. Every unit
    quaternion is reachable (its largest component is at least 0.5), both signs included.
    Shrinks towards the identity ``(0, 0, 0, 1)``.
    """
    lead = draw(st.sampled_from((3, 0, 1, 2)))  # w first: shrinks to the identity
    magnitude = draw(st.floats(0.5, 1.0))
    sign = draw(st.sampled_from((1.0, -1.0)))
    q = [draw(st.floats(-1.0, 1.0)) if i != lead else sign * magnitude for i in range(4)]
    arr = np.array(q, dtype=np.float64)
    return arr / np.linalg.norm(arr)


def yaws(
    min_value: float = -math.pi, max_value: float = math.pi
) -> st.SearchStrategy[float]:
    """Headings in radians in ``[min_value, max_value]`` (default ``[-pi, pi]``).

    Shrinks towards 0 when it is in range. Pass a wider range (e.g. ``-4 * pi`` to ``4 * pi``)
    to test wrapping.

    Parameters
    ----------
    min_value, max_value : float
        Bounds in radians, finite, ``min_value <= max_value``.
    """
    if not (math.isfinite(min_value) and math.isfinite(max_value) and min_value <= max_value):
        raise ArgumentError(
            f"min_value and max_value must be finite with min_value <= max_value, "
            f"got {min_value!r} and {max_value!r}"
        )
    return st.floats(min_value, max_value)


def euler_angles(gimbal_margin: float = 0.0) -> st.SearchStrategy[np.ndarray]:
    """Euler angles ``(roll, pitch, yaw)`` in canonical ranges, as float64 arrays of shape (3,).

    Roll and yaw lie in (-pi, pi] and pitch in ``[-pi/2 + gimbal_margin, pi/2 - gimbal_margin]``;
    a positive ``gimbal_margin`` (radians) keeps away from gimbal lock, where roll and yaw
    are not unique. Shrinks towards ``(0, 0, 0)``.

    Parameters
    ----------
    gimbal_margin : float
        Distance in radians to keep from pitch = +-pi/2, in [0, pi/2).
    """
    if not 0.0 <= gimbal_margin < math.pi / 2:
        raise ArgumentError(f"gimbal_margin must be in [0, pi/2) radians, got {gimbal_margin!r}")
    half_turn = st.floats(-math.pi, math.pi, exclude_min=True)
    limit = math.pi / 2 - gimbal_margin
    return st.tuples(half_turn, st.floats(-limit, limit), half_turn).map(
        lambda angles: np.array(angles, dtype=np.float64)
    )


def finite_vectors(n: int, max_abs: float = 1e3) -> st.SearchStrategy[np.ndarray]:
    """Float64 arrays of shape ``(n,)`` with entries in ``[-max_abs, max_abs]``.

    The default bound (1 km for positions in metres) keeps sums and squares far from
    overflow, so tolerances in properties stay meaningful. Shrinks towards the zero vector.

    Parameters
    ----------
    n : int
        Length of the vectors, >= 1.
    max_abs : float
        Largest absolute value of an entry, finite and > 0.
    """
    if not (isinstance(n, int) and n >= 1):
        raise ArgumentError(f"n must be an int >= 1, got {n!r}")
    if not (math.isfinite(max_abs) and max_abs > 0):
        raise ArgumentError(f"max_abs must be a finite number > 0, got {max_abs!r}")
    return st.lists(st.floats(-max_abs, max_abs), min_size=n, max_size=n).map(
        lambda values: np.array(values, dtype=np.float64)
    )


# ----------------------------------------------------------------------- robots and actions
