"""Quaternions and Euler angles: conversions, products, inverses and rotating vectors.

Conventions and errors are those of :mod:`pointnav_core.transforms`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.transforms._kernels import (
    _GIMBAL_TOL,
    _ORTHO_TOL,
    _as_array,
    _batch,
    _cos,
    _raise_not_finite,
    _rotate,
    _sin,
    _stack,
    _unit_quat,
    _vectors,
    _wrap,
)

__all__ = [
    "euler2quat",
    "quat2euler",
    "quat2mat",
    "mat2quat",
    "quat_multiply",
    "quat_inverse",
    "quat_apply",
]


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
        raise ArgumentError(
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
        raise ArgumentError(
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
