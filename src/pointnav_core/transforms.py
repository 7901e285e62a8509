"""Rigid-body transforms: quaternions, Euler angles, headings, polar form and frame changes.

Every function here is pure and broadcasts like numpy: pass one value (a length-k sequence)
or an ``(..., k)`` array. Batch dimensions are kept, and they broadcast between the arguments
of one call (one robot pose against ``(N, 2)`` points, ``(R, 1, 3)`` against ``(N, 3)``, ...).
Inputs are converted to float64 and results are float64; a function that returns one number
per value returns a numpy float64 scalar for a single value.

These functions are called on every control step, so a single value takes a plain-float fast
path (no array temporaries). It evaluates the same formulas as the array path; results agree
to rounding.

Conventions (SPEC section 1)
----------------------------
- Quaternions are ``(x, y, z, w)``. A function that reads a quaternion as a rotation
  normalises it first, so it need not be of unit length; quaternions returned are unit.
- A heading ``yaw`` about +z is the quaternion ``(0, 0, sin(yaw/2), cos(yaw/2))``.
- Euler angles are ``(roll, pitch, yaw)`` with ``R = Rz(yaw) @ Ry(pitch) @ Rx(roll)``, the
  same as ``scipy.spatial.transform.Rotation.from_euler("xyz", ...)`` (extrinsic axes).
- Robot frame: +x straight ahead, +y to the robot's left, +z up.
- Polar form of ``(x, y)`` is ``(rho, phi)`` with ``rho = hypot(x, y)`` and
  ``phi = atan2(y, x)``.
- Angles returned lie in (-pi, pi] (pitch in [-pi/2, pi/2]), so the negative x axis is
  ``pi``, never ``-pi``. Zeros are returned as ``+0.0``.

Errors
------
Every function raises ``ValueError`` naming the parameter when an input has the wrong
last-axis size, holds NaN or infinity, is a zero quaternion (not a rotation), or when the
batch shapes of two arguments do not broadcast.
"""

from __future__ import annotations

import math
from typing import Sequence, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "euler2quat",
    "quat2euler",
    "quat2mat",
    "mat2quat",
    "quat_multiply",
    "quat_inverse",
    "quat_apply",
    "yaw2quat",
    "quat2yaw",
    "cartesian_to_polar",
    "polar_to_cartesian",
    "l2_distance",
    "to_robot_frame",
]

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
        raise ValueError(f"{name} must be {expected}, got {value!r}") from None


def _raise_not_finite(arr: NDArray[np.float64], name: str) -> None:
    index = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
    where = f" at index {index}" if index else ""
    raise ValueError(f"{name} must be finite (no NaN or infinity), got {arr[index]}{where}")


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
        raise ValueError(
            f"{name} must be an array of shape (..., {size}) {meaning}, got {value!r}"
        ) from None
    if arr.shape[-1:] != (size,):
        raise ValueError(f"{name} must have shape (..., {size}) {meaning}, got shape {arr.shape}")
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
        raise ValueError(
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
        raise ValueError(
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


# ------------------------------------------------------------------------- quaternions


def euler2quat(euler: ArrayLike) -> NDArray[np.float64]:
    """Convert Euler angles (roll, pitch, yaw) to quaternions (x, y, z, w).

    The rotation is ``R = Rz(yaw) @ Ry(pitch) @ Rx(roll)``: roll about the fixed x axis
    first, then pitch about the fixed y axis, then yaw about the fixed z axis.

    Parameters
    ----------
    euler : array_like, shape (..., 3)
        Angles ``(roll, pitch, yaw)`` in radians; any finite values.

    Returns
    -------
    quat : ndarray of float64, shape (..., 4)
        Unit quaternions ``(x, y, z, w)``. The sign is not canonicalised, so that
        ``euler2quat((0, 0, yaw))`` equals ``yaw2quat(yaw)``.

    Raises
    ------
    ValueError
        If ``euler`` is not of shape (..., 3) or is not finite.

    See Also
    --------
    quat2euler : The inverse, with angles in canonical ranges.
    yaw2quat : The special case roll = pitch = 0.

    Examples
    --------
    >>> from pointnav_core.transforms import euler2quat
    >>> euler2quat([0.0, 0.0, np.pi / 2]).round(6).tolist()
    [0.0, 0.0, 0.707107, 0.707107]
    >>> euler2quat([[0.0, 0.0, 0.0], [np.pi, 0.0, 0.0]]).round(6).tolist()
    [[0.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 0.0]]

    Gimbal lock (pitch = pi/2) is an ordinary input here:

    >>> euler2quat([0.3, np.pi / 2, 0.3]).round(6).tolist()
    [0.0, 0.707107, 0.0, 0.707107]
    """
    _, (roll, pitch, yaw), shape = _vectors(euler, "euler", 3, "(roll, pitch, yaw in radians)")
    cr, sr = _cos(roll * 0.5), _sin(roll * 0.5)
    cp, sp = _cos(pitch * 0.5), _sin(pitch * 0.5)
    cy, sy = _cos(yaw * 0.5), _sin(yaw * 0.5)
    return _stack(
        (
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy,
        ),
        shape,
    )


def quat2euler(quat: ArrayLike) -> NDArray[np.float64]:
    """Convert quaternions (x, y, z, w) to Euler angles (roll, pitch, yaw).

    Uses the direct method of Bernardes and Viollet (2022), as scipy does, which is
    accurate right up to gimbal lock. At gimbal lock (pitch within 1e-12 rad of +-pi/2)
    roll and yaw are not separable; roll is then 0 and yaw carries the whole turn about
    the vertical, so that the heading stays meaningful (scipy instead sets yaw to 0 and
    warns).

    Parameters
    ----------
    quat : array_like, shape (..., 4)
        Quaternions ``(x, y, z, w)``; normalised here, so they need not be unit.

    Returns
    -------
    euler : ndarray of float64, shape (..., 3)
        ``(roll, pitch, yaw)`` in radians with roll and yaw in (-pi, pi] and pitch in
        [-pi/2, pi/2], such that ``R = Rz(yaw) @ Ry(pitch) @ Rx(roll)``.

    Raises
    ------
    ValueError
        If ``quat`` is not of shape (..., 4), is not finite, or is zero.

    See Also
    --------
    euler2quat : The inverse.
    quat2yaw : The yaw alone, faster.

    Examples
    --------
    >>> from pointnav_core.transforms import quat2euler
    >>> quat2euler([0.0, 0.0, 0.7071068, 0.7071068]).round(6).tolist()
    [0.0, 0.0, 1.570796]
    >>> quat2euler([[0.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 0.0]]).round(6).tolist()
    [[0.0, 0.0, 0.0], [3.141593, 0.0, 0.0]]

    At gimbal lock only yaw - roll (here) or yaw + roll is defined; roll is reported as 0:

    >>> quat2euler([0.0, 0.7071068, 0.0, 0.7071068]).round(6).tolist()
    [0.0, 1.570796, 0.0]
    """
    (x, y, z, w), shape = _unit_quat(quat, "quat")
    x, y, z, w = (np.reshape(c, -1) for c in (x, y, z, w))
    # Bernardes & Viollet for the extrinsic sequence x-y-z (a Tait-Bryan sequence):
    # permute into a proper Euler problem, then read the angles off half-angle atan2s.
    a, b, c, d = w - y, x + z, y + w, z - x
    h_ab, h_cd = np.hypot(a, b), np.hypot(c, d)
    pitch = 2.0 * np.arctan2(h_cd, h_ab) - 0.5 * np.pi
    half_sum, half_diff = np.arctan2(b, a), np.arctan2(d, c)
    roll = half_sum - half_diff
    yaw = half_sum + half_diff
    # For a unit quaternion h_ab^2 + h_cd^2 = 2 and cos(pitch) = h_ab * h_cd.
    locked = h_ab * h_cd <= _GIMBAL_TOL
    if locked.any():
        # Only roll + yaw (pitch -pi/2, h_cd ~ 0) or yaw - roll (pitch pi/2) is defined.
        down = h_cd <= h_ab
        roll = np.where(locked, 0.0, roll)
        yaw = np.where(locked, np.where(down, 2.0 * half_sum, 2.0 * half_diff), yaw)
    euler = np.stack([_wrap(roll), pitch, _wrap(yaw)], axis=-1) + 0.0
    return euler.reshape(shape + (3,))


def quat2mat(quat: ArrayLike) -> NDArray[np.float64]:
    """Convert quaternions (x, y, z, w) to rotation matrices.

    Parameters
    ----------
    quat : array_like, shape (..., 4)
        Quaternions ``(x, y, z, w)``; normalised here, so they need not be unit.

    Returns
    -------
    mat : ndarray of float64, shape (..., 3, 3)
        Rotation matrices (orthonormal, determinant 1) acting on column vectors:
        ``mat @ v`` rotates ``v``.

    Raises
    ------
    ValueError
        If ``quat`` is not of shape (..., 4), is not finite, or is zero.

    See Also
    --------
    mat2quat : The inverse (up to the sign of the quaternion).
    quat_apply : Rotates vectors without building the matrix.

    Examples
    --------
    >>> from pointnav_core.transforms import quat2mat
    >>> quat2mat([0.0, 0.0, 0.6, 0.8]).round(6).tolist()
    [[0.28, -0.96, 0.0], [0.96, 0.28, 0.0], [0.0, 0.0, 1.0]]
    >>> quat2mat([[0.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 0.0]]).shape
    (2, 3, 3)

    Quaternions are normalised first, so a scaled one gives the same matrix:

    >>> quat2mat([0.0, 0.0, 0.0, 5.0]).tolist()
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    """
    (x, y, z, w), shape = _unit_quat(quat, "quat")
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz = x * y, x * z, y * z
    wx, wy, wz = w * x, w * y, w * z
    flat = _stack(
        (
            1.0 - 2.0 * (yy + zz), 2.0 * (xy - wz), 2.0 * (xz + wy),
            2.0 * (xy + wz), 1.0 - 2.0 * (xx + zz), 2.0 * (yz - wx),
            2.0 * (xz - wy), 2.0 * (yz + wx), 1.0 - 2.0 * (xx + yy),
        ),
        shape,
    )  # fmt: skip
    return flat.reshape(shape + (3, 3))


def mat2quat(mat: ArrayLike) -> NDArray[np.float64]:
    """Convert rotation matrices to canonical quaternions (x, y, z, w).

    Uses Markley's method (pick the best-conditioned of four formulas), as scipy does.

    Parameters
    ----------
    mat : array_like, shape (..., 3, 3)
        Rotation matrices: orthonormal to within 1e-6 with determinant +1.

    Returns
    -------
    quat : ndarray of float64, shape (..., 4)
        Unit quaternions ``(x, y, z, w)`` in canonical form: ``w >= 0``, and when
        ``w == 0`` the first non-zero of ``x, y, z`` is positive.

    Raises
    ------
    ValueError
        If ``mat`` is not of shape (..., 3, 3), is not finite, or is not a rotation
        (not orthonormal, or a reflection).

    See Also
    --------
    quat2mat : The inverse.

    Examples
    --------
    >>> from pointnav_core.transforms import mat2quat
    >>> mat2quat([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]).round(6).tolist()
    [0.0, 0.0, 0.707107, 0.707107]
    >>> mat2quat(np.stack([np.eye(3), np.diag([1.0, -1.0, -1.0])])).tolist()
    [[0.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 0.0]]

    A half turn about -z comes back as the half turn about +z (w = 0, so z > 0):

    >>> mat2quat(np.diag([-1.0, -1.0, 1.0])).tolist()
    [0.0, 0.0, 1.0, 0.0]
    """
    expected = "an array of shape (..., 3, 3) (rotation matrices)"
    m = _as_array(mat, "mat", expected)
    if m.shape[-2:] != (3, 3):
        raise ValueError(
            f"mat must have shape (..., 3, 3) (rotation matrices), got shape {m.shape}"
        )
    if not np.isfinite(m).all():
        _raise_not_finite(m, "mat")
    shape = m.shape[:-2]
    m = m.reshape(-1, 3, 3)
    gram = np.einsum("nij,nkj->nik", m, m)
    bad = (np.abs(gram - np.eye(3)) > _ORTHO_TOL).any(axis=(1, 2)) | (np.linalg.det(m) <= 0.0)
    if bad.any():
        i = int(np.argmax(bad))
        where = f" at index {tuple(int(j) for j in np.unravel_index(i, shape))}" if shape else ""
        raise ValueError(
            "mat must hold rotation matrices (orthonormal to within "
            f"{_ORTHO_TOL:g}, determinant +1), got {m[i].tolist()}{where}"
        )
    m00, m01, m02 = m[:, 0, 0], m[:, 0, 1], m[:, 0, 2]
    m10, m11, m12 = m[:, 1, 0], m[:, 1, 1], m[:, 1, 2]
    m20, m21, m22 = m[:, 2, 0], m[:, 2, 1], m[:, 2, 2]
    # Row r of this symmetric matrix is 4 q[r] (x, y, z, w) for an exact rotation; the row
    # with the largest diagonal entry (largest |q[r]|) is the best-conditioned estimate.
    k = np.stack(
        [
            1.0 + m00 - m11 - m22, m01 + m10, m02 + m20, m21 - m12,
            m01 + m10, 1.0 - m00 + m11 - m22, m12 + m21, m02 - m20,
            m02 + m20, m12 + m21, 1.0 - m00 - m11 + m22, m10 - m01,
            m21 - m12, m02 - m20, m10 - m01, 1.0 + m00 + m11 + m22,
        ],
        axis=-1,
    ).reshape(-1, 4, 4)  # fmt: skip
    rows = np.arange(len(k))
    q = k[rows, np.argmax(np.einsum("nii->ni", k), axis=-1)]
    q /= np.sqrt(np.einsum("ni,ni->n", q, q))[:, None]
    # Canonical sign: the first non-zero of (w, x, y, z) is positive.
    lead = np.argmax(q[:, [3, 0, 1, 2]] != 0, axis=-1)
    q *= np.where(q[rows, (lead + 3) % 4] < 0, -1.0, 1.0)[:, None]
    q += 0.0
    return q.reshape(shape + (4,))


def quat_multiply(q1: ArrayLike, q2: ArrayLike) -> NDArray[np.float64]:
    """Compose rotations: the Hamilton product ``q1 * q2`` (apply ``q2`` first, then ``q1``).

    Parameters
    ----------
    q1, q2 : array_like, shape (..., 4)
        Quaternions ``(x, y, z, w)``; normalised here. Batch shapes broadcast.

    Returns
    -------
    quat : ndarray of float64, shape (..., 4)
        Unit quaternions with ``quat2mat(quat) == quat2mat(q1) @ quat2mat(q2)``
        (scipy's ``Rotation(q1) * Rotation(q2)``). The sign is not canonicalised.

    Raises
    ------
    ValueError
        If ``q1`` or ``q2`` is not of shape (..., 4), not finite or zero, or if their batch
        shapes do not broadcast.

    See Also
    --------
    quat_inverse : ``quat_multiply(q, quat_inverse(q))`` is the identity.

    Examples
    --------
    >>> from pointnav_core.transforms import quat_multiply, yaw2quat
    >>> quat_multiply(yaw2quat(0.5), yaw2quat(1.0)).round(6).tolist() == (
    ...     yaw2quat(1.5).round(6).tolist())
    True
    >>> quat_multiply([0.0, 0.0, 0.0, 1.0], [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]]).tolist()
    [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]]

    Two half turns about x give a full turn, which is ``-identity`` as a quaternion:

    >>> quat_multiply([1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]).tolist()
    [0.0, 0.0, 0.0, -1.0]
    """
    (x1, y1, z1, w1), shape1 = _unit_quat(q1, "q1")
    (x2, y2, z2, w2), shape2 = _unit_quat(q2, "q2")
    shape = _batch("q1 and q2", shape1, shape2)
    return _stack(
        (
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        ),
        shape,
    )


def quat_inverse(quat: ArrayLike) -> NDArray[np.float64]:
    """Invert rotations: the conjugate of the normalised quaternion.

    Parameters
    ----------
    quat : array_like, shape (..., 4)
        Quaternions ``(x, y, z, w)``; normalised here.

    Returns
    -------
    inverse : ndarray of float64, shape (..., 4)
        Unit quaternions ``(-x, -y, -z, w) / |quat|``, the opposite rotations.

    Raises
    ------
    ValueError
        If ``quat`` is not of shape (..., 4), is not finite, or is zero.

    See Also
    --------
    quat_multiply : ``quat_multiply(q, quat_inverse(q))`` is the identity.

    Examples
    --------
    >>> from pointnav_core.transforms import quat_inverse
    >>> quat_inverse([0.0, 0.0, 0.6, 0.8]).tolist()
    [0.0, 0.0, -0.6, 0.8]
    >>> quat_inverse([[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 2.0]]).tolist()
    [[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 1.0]]

    Not-unit input comes back unit:

    >>> quat_inverse([0.0, 0.0, 3.0, 4.0]).round(6).tolist()
    [0.0, 0.0, -0.6, 0.8]
    """
    (x, y, z, w), shape = _unit_quat(quat, "quat")
    return _stack((-x, -y, -z, w), shape)


def quat_apply(quat: ArrayLike, vec: ArrayLike) -> NDArray[np.float64]:
    """Rotate 3-vectors by quaternions.

    Parameters
    ----------
    quat : array_like, shape (..., 4)
        Rotations as quaternions ``(x, y, z, w)``; normalised here.
    vec : array_like, shape (..., 3)
        Vectors to rotate (any unit, e.g. metres or metres per second). The batch shapes
        of ``quat`` and ``vec`` broadcast.

    Returns
    -------
    rotated : ndarray of float64, shape (..., 3)
        ``quat2mat(quat) @ vec``, in the unit of ``vec``.

    Raises
    ------
    ValueError
        If ``quat`` is not of shape (..., 4), not finite or zero, if ``vec`` is not of shape
        (..., 3) or not finite, or if the batch shapes do not broadcast.

    See Also
    --------
    quat2mat : The same rotation as a matrix.
    to_robot_frame : Applies the inverse of a pose (rotation and translation).

    Examples
    --------
    >>> from pointnav_core.transforms import quat_apply, yaw2quat
    >>> quat_apply(yaw2quat(np.pi / 2), [1.0, 0.0, 0.0]).round(6).tolist()
    [0.0, 1.0, 0.0]
    >>> quat_apply(yaw2quat([0.0, np.pi]), [[1.0, 2.0, 3.0]]).round(6).tolist()
    [[1.0, 2.0, 3.0], [-1.0, -2.0, 3.0]]

    The zero vector stays put under any rotation:

    >>> quat_apply([0.3, -0.2, 0.9, 0.1], [0.0, 0.0, 0.0]).tolist()
    [0.0, 0.0, 0.0]
    """
    q, qshape = _unit_quat(quat, "quat")
    _, (vx, vy, vz), vshape = _vectors(vec, "vec", 3, "(3-vectors)")
    shape = _batch("quat and vec", qshape, vshape)
    return _stack(_rotate(q, vx, vy, vz), shape)


# ----------------------------------------------------------------------------- headings


def yaw2quat(yaw: ArrayLike) -> NDArray[np.float64]:
    """Convert headings (yaw about +z) to quaternions (x, y, z, w).

    Parameters
    ----------
    yaw : array_like, shape (...)
        Headings in radians, any finite values (0 faces +x, pi/2 faces +y).

    Returns
    -------
    quat : ndarray of float64, shape (..., 4)
        ``(0, 0, sin(yaw / 2), cos(yaw / 2))`` exactly as in SPEC section 1, so ``w`` is
        negative for ``|yaw| > pi`` (the same rotation as ``-quat``).

    Raises
    ------
    ValueError
        If ``yaw`` is not finite.

    See Also
    --------
    quat2yaw : The inverse, with the heading wrapped into (-pi, pi].

    Examples
    --------
    >>> from pointnav_core.transforms import yaw2quat
    >>> yaw2quat(np.pi / 2).round(6).tolist()
    [0.0, 0.0, 0.707107, 0.707107]
    >>> yaw2quat([0.0, np.pi]).round(6).tolist()
    [[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.0]]

    A full turn is the same rotation, with the opposite sign:

    >>> yaw2quat(2 * np.pi).round(6).tolist()
    [0.0, 0.0, 0.0, -1.0]
    """
    arr = _as_array(yaw, "yaw", "an array of headings in radians")
    if arr.ndim == 0:
        half = float(arr) * 0.5
        if not math.isfinite(half):
            _raise_not_finite(arr, "yaw")
        return _stack((0.0, 0.0, math.sin(half), math.cos(half)), ())
    if not np.isfinite(arr).all():
        _raise_not_finite(arr, "yaw")
    half = arr * 0.5
    return _stack((0.0, 0.0, np.sin(half), np.cos(half)), arr.shape)


def quat2yaw(quat: ArrayLike) -> np.float64 | NDArray[np.float64]:
    """Return the heading (yaw about +z) of orientations.

    The heading is the direction of the body's +x axis projected onto the floor,
    ``atan2(R[1, 0], R[0, 0])``; it equals the yaw of :func:`quat2euler`. When the +x
    axis is vertical (gimbal lock) it takes :func:`quat2euler`'s convention (roll = 0).

    Parameters
    ----------
    quat : array_like, shape (..., 4)
        Orientations as quaternions ``(x, y, z, w)``; normalised here.

    Returns
    -------
    yaw : float64 or ndarray of float64, shape (...)
        Headings in radians in (-pi, pi]; a numpy float64 scalar for one quaternion.

    Raises
    ------
    ValueError
        If ``quat`` is not of shape (..., 4), is not finite, or is zero.

    See Also
    --------
    yaw2quat : The inverse for planar orientations.
    quat2euler : All three angles.

    Examples
    --------
    >>> from pointnav_core.transforms import quat2yaw
    >>> round(float(quat2yaw([0.0, 0.0, 0.7071068, 0.7071068])), 6)
    1.570796
    >>> quats = [[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, -1.0], [0.0, 0.0, 1.0, 0.0]]
    >>> quat2yaw(quats).round(6).tolist()
    [0.0, 0.0, 3.141593]

    Facing -x is pi, never -pi, whichever sign the quaternion has:

    >>> float(quat2yaw([0.0, 0.0, -1.0, 0.0])) == np.pi
    True
    """
    (x, y, z, w), shape = _unit_quat(quat, "quat")
    r10 = 2.0 * (x * y + w * z)
    r00 = 1.0 - 2.0 * (y * y + z * z)
    yaw = _angle(r10, r00)
    # Gimbal lock: no projection of +x on the floor; read yaw off the +y axis (roll = 0).
    locked = r00 * r00 + r10 * r10 <= _GIMBAL_TOL * _GIMBAL_TOL
    if shape:
        if locked.any():
            other = _angle(2.0 * (w * z - x * y), 1.0 - 2.0 * (x * x + z * z))
            yaw = np.where(locked, other, yaw)
        return yaw
    if locked:
        yaw = _angle(2.0 * (w * z - x * y), 1.0 - 2.0 * (x * x + z * z))
    return np.float64(yaw)


# -------------------------------------------------------------------------- polar form


def cartesian_to_polar(xy: ArrayLike) -> NDArray[np.float64]:
    """Convert planar vectors (x, y) to polar form (rho, phi).

    Parameters
    ----------
    xy : array_like, shape (..., 2)
        Planar vectors in metres, e.g. a goal in the robot frame (+x ahead, +y left).

    Returns
    -------
    polar : ndarray of float64, shape (..., 2)
        ``(rho, phi)``: ``rho = hypot(x, y)`` in metres and ``phi = atan2(y, x)`` in
        radians in (-pi, pi] (0 dead ahead, positive to the left). The origin has phi 0.

    Raises
    ------
    ValueError
        If ``xy`` is not of shape (..., 2) or is not finite.

    See Also
    --------
    polar_to_cartesian : The inverse.

    Examples
    --------
    >>> from pointnav_core.transforms import cartesian_to_polar
    >>> cartesian_to_polar([3.0, 4.0]).round(6).tolist()
    [5.0, 0.927295]
    >>> cartesian_to_polar([[0.0, 2.0], [0.0, -2.0]]).round(6).tolist()
    [[2.0, 1.570796], [2.0, -1.570796]]

    Straight behind is pi (also for ``y = -0.0``), and the origin is (0, 0):

    >>> cartesian_to_polar([[-1.0, -0.0], [0.0, 0.0], [-0.0, -0.0]]).round(6).tolist()
    [[1.0, 3.141593], [0.0, 0.0], [0.0, 0.0]]
    """
    _, (x, y), shape = _vectors(xy, "xy", 2, "(x, y in metres)")
    if shape:
        return _stack((np.hypot(x, y), _angle(y, x)), shape)
    return _stack((math.hypot(x, y), _angle(y, x)), ())


def polar_to_cartesian(polar: ArrayLike) -> NDArray[np.float64]:
    """Convert polar form (rho, phi) to planar vectors (x, y).

    Parameters
    ----------
    polar : array_like, shape (..., 2)
        ``(rho, phi)``: distance ``rho >= 0`` in metres and angle ``phi`` in radians
        (any finite value; 0 is +x, pi/2 is +y).

    Returns
    -------
    xy : ndarray of float64, shape (..., 2)
        ``(rho * cos(phi), rho * sin(phi))`` in metres.

    Raises
    ------
    ValueError
        If ``polar`` is not of shape (..., 2), is not finite, or has a negative rho.

    See Also
    --------
    cartesian_to_polar : The inverse.

    Examples
    --------
    >>> from pointnav_core.transforms import polar_to_cartesian
    >>> polar_to_cartesian([2.0, np.pi / 2]).round(6).tolist()
    [0.0, 2.0]
    >>> polar_to_cartesian([[1.0, 0.0], [1.0, np.pi]]).round(6).tolist()
    [[1.0, 0.0], [-1.0, 0.0]]

    At rho = 0 the angle does not matter:

    >>> polar_to_cartesian([0.0, 1.234]).tolist()
    [0.0, 0.0]
    """
    arr, (rho, phi), shape = _vectors(polar, "polar", 2, "(rho in metres, phi in radians)")
    if shape:
        if (rho < 0.0).any():
            index = tuple(int(i) for i in np.argwhere(arr[..., 0] < 0.0)[0])
            raise ValueError(
                f"polar must have rho (polar[..., 0]) >= 0 metres, got {arr[index + (0,)]} "
                f"at index {index}"
            )
        return _stack((rho * np.cos(phi), rho * np.sin(phi)), shape)
    if rho < 0.0:
        raise ValueError(f"polar must have rho (polar[..., 0]) >= 0 metres, got {rho}")
    return _stack((rho * math.cos(phi), rho * math.sin(phi)), ())


# ------------------------------------------------------------------ distances and frames


def l2_distance(a: ArrayLike, b: ArrayLike) -> np.float64 | NDArray[np.float64]:
    """Return the Euclidean distance between points, over the last axis.

    Parameters
    ----------
    a, b : array_like, shape (..., k)
        Points in metres, with the same ``k >= 1``; batch shapes broadcast.

    Returns
    -------
    distance : float64 or ndarray of float64, shape (...)
        ``|a - b|`` in metres; a numpy float64 scalar for one pair of points.

    Raises
    ------
    ValueError
        If ``a`` or ``b`` is not finite or has no last axis, if their last axes differ in
        size, or if their batch shapes do not broadcast.

    Examples
    --------
    >>> from pointnav_core.transforms import l2_distance
    >>> float(l2_distance([0.0, 0.0], [3.0, 4.0]))
    5.0
    >>> l2_distance([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]], [1.0, 1.0, 1.0]).round(6).tolist()
    [1.732051, 0.0]

    An empty batch gives an empty result:

    >>> l2_distance(np.zeros((0, 2)), [1.0, 2.0]).shape
    (0,)
    """
    arr_a = _as_array(a, "a", "an array of points of shape (..., k)")
    arr_b = _as_array(b, "b", "an array of points of shape (..., k)")
    if arr_a.ndim == 0 or arr_b.ndim == 0 or not arr_a.shape[-1] == arr_b.shape[-1] > 0:
        raise ValueError(
            "a and b must have shape (..., k) with the same k (points in metres), "
            f"got shapes {arr_a.shape} and {arr_b.shape}"
        )
    if arr_a.ndim == 1 and arr_b.ndim == 1:
        pa, pb = arr_a.tolist(), arr_b.tolist()
        dist = math.dist(pa, pb)
        if not math.isfinite(dist):
            for name, arr, p in (("a", arr_a, pa), ("b", arr_b, pb)):
                if not all(map(math.isfinite, p)):
                    _raise_not_finite(arr, name)
        return np.float64(dist)
    for name, arr in (("a", arr_a), ("b", arr_b)):
        if not np.isfinite(arr).all():
            _raise_not_finite(arr, name)
    _batch("a and b", arr_a.shape[:-1], arr_b.shape[:-1])
    with np.errstate(over="ignore"):  # points over 1e308 apart are inf apart, as in math.dist
        diff = arr_a - arr_b
    # Chained hypot, like math.dist, neither overflows nor underflows on the way.
    dist = np.abs(diff[..., 0])
    for i in range(1, diff.shape[-1]):
        dist = np.hypot(dist, diff[..., i])
    return dist


def to_robot_frame(
    robot_pos: ArrayLike, robot_quat: ArrayLike, points: ArrayLike
) -> NDArray[np.float64]:
    """Express world points in a robot's frame (+x ahead, +y left, +z up).

    Subtracts the robot's position and rotates by the inverse of its orientation:
    ``quat2mat(robot_quat).T @ (point - robot_pos)``. Planar points (x, y) are taken at the
    robot's height (relative z = 0), and only the planar part of the result is returned.

    Parameters
    ----------
    robot_pos : array_like, shape (..., 3)
        Robot positions ``(x, y, z)`` in metres, world frame.
    robot_quat : array_like, shape (..., 4)
        Robot orientations ``(x, y, z, w)``, world frame; normalised here.
    points : array_like, shape (..., 3) or (..., 2)
        World points ``(x, y, z)`` or planar ``(x, y)`` in metres. The batch shapes of the
        three arguments broadcast: one pose against ``(N, 2)`` points, ``(R, 3)`` poses
        against ``(R, 3)`` points, ``(R, 1, 3)`` poses against ``(N, 3)`` points.

    Returns
    -------
    local : ndarray of float64, shape (..., 3) or (..., 2)
        The points in the robot frame in metres, with as many coordinates as ``points``.

    Raises
    ------
    ValueError
        If an argument has the wrong last-axis size or is not finite, if ``robot_quat`` is
        zero, or if the batch shapes do not broadcast.

    See Also
    --------
    cartesian_to_polar : Turns a planar result into (distance, bearing).
    quat_apply : ``robot_pos + quat_apply(robot_quat, local)`` gives back the world points.

    Examples
    --------
    >>> from pointnav_core.transforms import to_robot_frame, yaw2quat
    >>> to_robot_frame([1.0, 1.0, 0.0], yaw2quat(np.pi / 2), [1.0, 3.0]).round(6).tolist()
    [2.0, 0.0]
    >>> half_turn = [0.0, 0.0, 1.0, 0.0]  # facing -x
    >>> to_robot_frame([0.0, 0.0, 0.0], half_turn, [[1.0, 0.0, 0.5], [0.0, 1.0, 0.0]]).tolist()
    [[-1.0, 0.0, 0.5], [0.0, -1.0, 0.0]]

    The robot's own position is its origin, whatever its orientation:

    >>> to_robot_frame([2.0, -1.0, 0.3], [0.1, 0.2, 0.3, 0.9], [2.0, -1.0, 0.3]).tolist()
    [0.0, 0.0, 0.0]
    """
    _, (px, py, pz), pos_shape = _vectors(robot_pos, "robot_pos", 3, "(x, y, z in metres)")
    q, quat_shape = _unit_quat(robot_quat, "robot_quat")
    pts = _as_array(points, "points", "an array of shape (..., 2) or (..., 3) (metres)")
    planar = pts.shape[-1:] == (2,)
    if not planar and pts.shape[-1:] != (3,):
        raise ValueError(
            f"points must have shape (..., 2) or (..., 3) (x, y[, z] in metres), "
            f"got shape {pts.shape}"
        )
    if planar:
        _, (x, y), pts_shape = _vectors(pts, "points", 2, "(x, y in metres)")
        z: _Comp = pz  # planar points are at the robot's height
    else:
        _, (x, y, z), pts_shape = _vectors(pts, "points", 3, "(x, y, z in metres)")
    shape = _batch("robot_pos, robot_quat and points", pos_shape, quat_shape, pts_shape)
    local = _rotate(q, x - px, y - py, z - pz, inverse=True)
    return _stack(local[:2] if planar else local, shape)
