"""Planar helpers: headings, polar form, distances and the robot frame.

Conventions and errors are those of :mod:`pointnav_core.transforms`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.transforms._kernels import (
    _GIMBAL_TOL,
    _angle,
    _as_array,
    _batch,
    _Comp,
    _raise_not_finite,
    _rotate,
    _stack,
    _unit_quat,
    _vectors,
)

__all__ = [
    "yaw2quat",
    "quat2yaw",
    "heading_of",
    "cartesian_to_polar",
    "polar_to_cartesian",
    "l2_distance",
    "to_robot_frame",
]


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


def heading_of(qx: float, qy: float, qz: float, qw: float) -> float:
    """:func:`quat2yaw` of one quaternion ``(qx, qy, qz, qw)`` given as four floats, with no
    array: the form of a per-step caller (a scan, a crowd's track), as
    :class:`~pointnav_core.task.observations.Frame` derives the heading (the same angle
    within a few ulps; unchecked input).

    >>> round(heading_of(0.0, 0.0, math.sin(0.25), math.cos(0.25)), 12)
    0.5
    """
    q2 = 2.0 / (qx * qx + qy * qy + qz * qz + qw * qw)
    r00 = 1.0 - q2 * (qy * qy + qz * qz)
    r10 = q2 * (qx * qy + qz * qw)
    h = math.hypot(r00, r10)
    if h > 1e-12:
        return math.atan2(r10 / h, r00 / h)
    r01 = q2 * (qx * qy - qz * qw)
    r11 = 1.0 - q2 * (qx * qx + qz * qz)
    return math.atan2(-r01, r11)


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
            raise ArgumentError(
                f"polar must have rho (polar[..., 0]) >= 0 metres, got {arr[index + (0,)]} "
                f"at index {index}"
            )
        return _stack((rho * np.cos(phi), rho * np.sin(phi)), shape)
    if rho < 0.0:
        raise ArgumentError(f"polar must have rho (polar[..., 0]) >= 0 metres, got {rho}")
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
        raise ArgumentError(
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
        raise ArgumentError(
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
