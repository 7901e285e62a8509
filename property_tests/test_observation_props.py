"""The observation terms' float fast path against the general transforms (numpy, any batch).

``observations.Frame`` derives the rotation and the heading from the quaternion with plain
floats on every step; ``transforms`` is the general, vectorised path. They must agree.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st

from pointnav_core.task.observations import (
    AngularVelocity,
    Frame,
    GoalVector,
    LinearVelocity,
)
from pointnav_core.testing.strategies import unit_quaternions, yaws
from pointnav_core.transforms import (
    cartesian_to_polar,
    quat2mat,
    quat2yaw,
    to_robot_frame,
    yaw2quat,
)

coords = st.floats(-50.0, 50.0)
speeds = st.tuples(*[st.floats(-3.0, 3.0)] * 3)


def frame_at(x, y, z, quat, goal=(0.0, 0.0), lin=(0.0, 0.0, 0.0), ang=(0.0, 0.0, 0.0)) -> Frame:
    frame = Frame()
    frame.set_pose(x, y, z, [float(v) for v in quat])
    frame.goal_x, frame.goal_y = goal
    frame.lin_vel, frame.ang_vel = lin, ang
    return frame


@given(unit_quaternions(), coords, coords, speeds, speeds)
def test_rotation_and_velocities_equal_the_general_transforms(quat, x, y, lin, ang):
    frame = frame_at(x, y, 0.0, quat, lin=lin, ang=ang)
    mat = quat2mat(quat)
    assert np.allclose(np.array(frame.rot).reshape(3, 3), mat, atol=1e-12)
    assert np.allclose(LinearVelocity().values(frame), mat.T @ np.array(lin), atol=1e-9)
    assert np.allclose(AngularVelocity().values(frame), mat.T @ np.array(ang), atol=1e-9)


@given(unit_quaternions())
def test_the_heading_is_quat2yaw(quat):
    mat = quat2mat(quat)
    assume(math.hypot(mat[0, 0], mat[1, 0]) > 1e-6)  # +x not vertical: the heading is defined
    frame = frame_at(0.0, 0.0, 0.0, quat)
    yaw = float(quat2yaw(quat))
    assert math.isclose(frame.cos_yaw, math.cos(yaw), abs_tol=1e-9)
    assert math.isclose(frame.sin_yaw, math.sin(yaw), abs_tol=1e-9)


@given(yaws(), coords, coords, coords, coords)
def test_goal_vector_of_a_planar_robot_equals_to_robot_frame(yaw, x, y, gx, gy):
    quat = yaw2quat(yaw)
    frame = frame_at(x, y, 0.0, quat, goal=(gx, gy))
    local = to_robot_frame([x, y, 0.0], quat, [gx, gy])
    assert np.allclose(GoalVector().values(frame), local, atol=1e-9)
    rho, phi = GoalVector(polar=True).values(frame)
    want = cartesian_to_polar(local)
    assert math.isclose(rho, want[0], abs_tol=1e-9)
    if rho > 1e-6:  # the bearing of a goal under the robot is 0 by convention
        assert math.isclose(math.remainder(phi - want[1], 2 * math.pi), 0.0, abs_tol=1e-9)
        assert -math.pi < phi <= math.pi
