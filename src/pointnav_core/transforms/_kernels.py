"""Shared checks and float/array kernels of the transforms (private to the package).

A *component* is a Python float for a single value (the per-step fast path) or an array
view of one coordinate over a batch; every kernel takes and returns either.
"""

from __future__ import annotations

import math
from typing import Sequence, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.errors import ArgumentError

# A component is a Python float (single value, fast path) or an array of a batch.
_Comp = Union[float, NDArray[np.float64]]

# Within this distance (rad) of pitch = +-pi/2, roll and yaw are not separable: quat2euler
# then reports roll = 0 and puts the whole turn about the vertical in yaw, and quat2yaw
# agrees. The reconstructed rotation is off by at most about this much.
_GIMBAL_TOL = 1e-12

# Squared quaternion norms outside this range are rescaled before normalising, so that
# tiny or huge (but finite, non-zero) quaternions still normalise exactly.
_N2_MIN = 1e-300
_N2_MAX = 1e300

# Largest deviation of M @ M.T from the identity that mat2quat accepts as a rotation.
_ORTHO_TOL = 1e-6


# --------------------------------------------------------------------------- validation


def _as_array(value: ArrayLike, name: str, expected: str) -> NDArray[np.float64]:
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ArgumentError(f"{name} must be {expected}, got {value!r}") from None


def _raise_not_finite(arr: NDArray[np.float64], name: str) -> None:
    index = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
    where = f" at index {index}" if index else ""
    raise ArgumentError(f"{name} must be finite (no NaN or infinity), got {arr[index]}{where}")


def _vectors(
    value: ArrayLike, name: str, size: int, meaning: str
) -> tuple[NDArray[np.float64], list[_Comp], tuple[int, ...]]:
    """Check an ``(..., size)`` finite array; return it, its components and batch shape.

    The components are Python floats for a single vector and views of the last axis
    otherwise.
    """
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ArgumentError(
            f"{name} must be an array of shape (..., {size}) {meaning}, got {value!r}"
        ) from None
    if arr.shape[-1:] != (size,):
        raise ArgumentError(f"{name} must have shape (..., {size}) {meaning}, got shape {arr.shape}")
    if arr.ndim == 1:
        comps: list[_Comp] = arr.tolist()
        if not all(map(math.isfinite, comps)):
            _raise_not_finite(arr, name)
        return arr, comps, ()
    if not np.isfinite(arr).all():
        _raise_not_finite(arr, name)
    return arr, [arr[..., i] for i in range(size)], arr.shape[:-1]


def _unit_quat(value: ArrayLike, name: str) -> tuple[list[_Comp], tuple[int, ...]]:
    """Check quaternions and normalise them; return components (x, y, z, w) and batch shape."""
    arr, q, shape = _vectors(value, name, 4, "(quaternions x, y, z, w)")
    x, y, z, w = q
    if shape:
        with np.errstate(over="ignore"):  # huge quaternions are rescaled below
            n2 = x * x + y * y + z * z + w * w
        if not ((n2 > _N2_MIN) & (n2 < _N2_MAX)).all():
            return _unit_quat_rescaled(arr, name)
        inv = 1.0 / np.sqrt(n2)
    else:
        n2 = x * x + y * y + z * z + w * w
        if not _N2_MIN < n2 < _N2_MAX:
            return _unit_quat_rescaled(arr, name)
        inv = 1.0 / math.sqrt(n2)
    return [x * inv, y * inv, z * inv, w * inv], shape


def _unit_quat_rescaled(
    arr: NDArray[np.float64], name: str
) -> tuple[list[_Comp], tuple[int, ...]]:
    # Slow path for tiny, huge or zero quaternions: divide by the largest component first.
    scale = np.abs(arr).max(axis=-1, keepdims=True)
    if (scale == 0).any():
        index = tuple(int(i) for i in np.argwhere(scale[..., 0] == 0)[0])
        where = f" at index {index}" if index else ""
        raise ArgumentError(
            f"{name} must be a non-zero quaternion (x, y, z, w) to be a rotation, "
            f"got (0, 0, 0, 0){where}"
        )
    unit = arr / scale
    unit /= np.sqrt(np.einsum("...i,...i->...", unit, unit))[..., None]
    if arr.ndim == 1:
        return unit.tolist(), ()
    return [unit[..., i] for i in range(4)], arr.shape[:-1]


def _batch(names: str, *shapes: tuple[int, ...]) -> tuple[int, ...]:
    """Broadcast the batch shapes of several arguments, naming them if that fails."""
    if not any(shapes):
        return ()
    try:
        return np.broadcast_shapes(*shapes)
    except ValueError:
        listed = ", ".join(str(s) for s in shapes)
        raise ArgumentError(
            f"{names} must have batch shapes (all but the last axis) that broadcast, "
            f"got {listed}"
        ) from None


def _stack(comps: Sequence[_Comp], shape: tuple[int, ...]) -> NDArray[np.float64]:
    """Assemble components into an ``shape + (len(comps),)`` float64 array."""
    if shape:
        out = np.empty(shape + (len(comps),))
        for i, comp in enumerate(comps):
            out[..., i] = comp
        out += 0.0  # -0.0 -> +0.0, so results print the same whatever the signs of zeros
        return out
    return np.array([c + 0.0 for c in comps], dtype=np.float64)


# ------------------------------------------------------------------- float/array kernels


def _sin(a: _Comp) -> _Comp:
    return math.sin(a) if type(a) is float else np.sin(a)


def _cos(a: _Comp) -> _Comp:
    return math.cos(a) if type(a) is float else np.cos(a)


def _angle(y: _Comp, x: _Comp) -> _Comp:
    """``atan2(y, x)`` in (-pi, pi], with signed zeros treated as +0 (the origin is 0)."""
    y = y + 0.0
    x = x + 0.0
    if type(y) is float and type(x) is float:
        a = math.atan2(y, x)
        return math.pi if a <= -math.pi else a + 0.0
    a = np.arctan2(y, x)
    # atan2 of a tiny negative y and a negative x rounds to -pi: that is the angle pi.
    return np.where(a <= -np.pi, np.pi, a) + 0.0


def _wrap(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """Wrap angles in [-2 pi, 2 pi] into (-pi, pi]."""
    a = np.where(a > np.pi, a - 2.0 * np.pi, a)
    a = np.where(a <= -np.pi, a + 2.0 * np.pi, a)
    return a


def _rotate(
    q: Sequence[_Comp], vx: _Comp, vy: _Comp, vz: _Comp, inverse: bool = False
) -> tuple[_Comp, _Comp, _Comp]:
    """Rotate ``v`` by the unit quaternion ``q`` (by its inverse if ``inverse``)."""
    x, y, z, w = q
    if inverse:
        x, y, z = -x, -y, -z
    # v' = v + w t + u x t with u = (x, y, z) and t = 2 u x v.
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (
        vx + w * tx + (y * tz - z * ty),
        vy + w * ty + (z * tx - x * tz),
        vz + w * tz + (x * ty - y * tx),
    )
