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

from pointnav_core.transforms.planar import (
    cartesian_to_polar,
    heading_of,
    l2_distance,
    polar_to_cartesian,
    quat2yaw,
    to_robot_frame,
    yaw2quat,
)
from pointnav_core.transforms.quaternions import (
    euler2quat,
    mat2quat,
    quat2euler,
    quat2mat,
    quat_apply,
    quat_inverse,
    quat_multiply,
)

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
    "heading_of",
    "cartesian_to_polar",
    "polar_to_cartesian",
    "l2_distance",
    "to_robot_frame",
]
