"""Properties of pointnav_core.transforms: round trips, invariants and agreement of paths."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from pointnav_core.testing.strategies import (
    euler_angles,
    finite_vectors,
    unit_quaternions,
    yaws,
)
from pointnav_core.transforms import (
    cartesian_to_polar,
    euler2quat,
    heading_of,
    l2_distance,
    mat2quat,
    polar_to_cartesian,
    quat2euler,
    quat2mat,
    quat2yaw,
    quat_apply,
    quat_inverse,
    quat_multiply,
    to_robot_frame,
    yaw2quat,
)

# Positions within 1 km; see finite_vectors. Errors scale with the coordinates.
ATOL = 1e-9


def angle_diff(a, b):
    """Smallest signed difference between angles, in [-pi, pi]."""
    return np.angle(np.exp(1j * (np.asarray(a, dtype=float) - np.asarray(b, dtype=float))))


def same_rotation(q1, q2, atol=1e-12) -> bool:
    """Quaternions equal up to sign (q and -q are the same rotation)."""
    q1, q2 = np.asarray(q1), np.asarray(q2)
    return bool(np.allclose(q1, q2, rtol=0, atol=atol) or np.allclose(q1, -q2, rtol=0, atol=atol))


scales = st.floats(1e-3, 1e3)


# --------------------------------------------------------------------------- rotations


@given(unit_quaternions())
def test_quat_mat_round_trip_up_to_sign(q):
    back = mat2quat(quat2mat(q))
    assert same_rotation(back, q)
    assert back[3] >= 0.0


@given(unit_quaternions())
def test_quat2mat_is_orthonormal_with_determinant_one(q):
    m = quat2mat(q)
    np.testing.assert_allclose(m @ m.T, np.eye(3), rtol=0, atol=1e-14)
    assert abs(np.linalg.det(m) - 1.0) < 1e-14


@given(unit_quaternions(), scales)
def test_quaternion_scale_does_not_change_the_rotation(q, scale):
    np.testing.assert_allclose(quat2mat(scale * q), quat2mat(q), rtol=0, atol=1e-14)


@given(euler_angles(gimbal_margin=1e-3))
def test_euler_round_trip_away_from_gimbal_lock(euler):
    back = quat2euler(euler2quat(euler))
    np.testing.assert_allclose(angle_diff(back, euler), 0.0, atol=1e-10)


@given(unit_quaternions())
def test_quat_euler_quat_round_trip_everywhere(q):
    # Holds at gimbal lock too, where the angles themselves are not unique.
    euler = quat2euler(q)
    assert same_rotation(euler2quat(euler), q)
    roll, pitch, yaw = euler
    assert -math.pi < roll <= math.pi and -math.pi < yaw <= math.pi
    assert -math.pi / 2 <= pitch <= math.pi / 2


@given(unit_quaternions())
def test_quat2yaw_is_the_euler_yaw(q):
    euler = quat2euler(q)
    cos_pitch = math.cos(euler[1])
    # The yaw is ill-conditioned near gimbal lock: its rounding error grows like eps / cos.
    assert abs(angle_diff(quat2yaw(q), euler[2])) <= 1e-14 / max(cos_pitch, 1e-14) + 1e-13


@given(unit_quaternions())
def test_quat_multiply_with_inverse_is_identity(q):
    identity = [0.0, 0.0, 0.0, 1.0]
    np.testing.assert_allclose(quat_multiply(q, quat_inverse(q)), identity, rtol=0, atol=1e-15)
    np.testing.assert_allclose(quat_multiply(quat_inverse(q), q), identity, rtol=0, atol=1e-15)


@given(unit_quaternions(), unit_quaternions())
def test_quat_multiply_is_matrix_product(q1, q2):
    np.testing.assert_allclose(
        quat2mat(quat_multiply(q1, q2)), quat2mat(q1) @ quat2mat(q2), rtol=0, atol=1e-14
    )


@given(unit_quaternions(), unit_quaternions(), unit_quaternions())
def test_quat_multiply_is_associative(q1, q2, q3):
    left = quat_multiply(quat_multiply(q1, q2), q3)
    right = quat_multiply(q1, quat_multiply(q2, q3))
    np.testing.assert_allclose(left, right, rtol=0, atol=1e-14)


@given(unit_quaternions(), finite_vectors(3))
def test_quat_apply_preserves_norm(q, v):
    assert abs(np.linalg.norm(quat_apply(q, v)) - np.linalg.norm(v)) <= ATOL


@given(unit_quaternions(), finite_vectors(3))
def test_quat_apply_matches_matrix_product(q, v):
    np.testing.assert_allclose(quat_apply(q, v), quat2mat(q) @ v, rtol=0, atol=ATOL)


@given(unit_quaternions(), finite_vectors(3))
def test_quat_apply_with_inverse_gives_back_the_vector(q, v):
    np.testing.assert_allclose(quat_apply(quat_inverse(q), quat_apply(q, v)), v, rtol=0, atol=ATOL)


@given(st.lists(st.tuples(unit_quaternions(), finite_vectors(3)), min_size=1, max_size=6))
def test_batched_calls_match_single_calls(pairs):
    quats = np.array([q for q, _ in pairs])
    vecs = np.array([v for _, v in pairs])
    for func, args in (
        (quat2mat, (quats,)),
        (quat2euler, (quats,)),
        (quat2yaw, (quats,)),
        (quat_inverse, (quats,)),
        (quat_apply, (quats, vecs)),
        (quat_multiply, (quats, quats[::-1])),
        (to_robot_frame, (vecs[::-1], quats, vecs)),
        (to_robot_frame, (vecs[::-1], quats, vecs[:, :2])),
        (cartesian_to_polar, (vecs[:, :2],)),
        (l2_distance, (vecs, vecs[::-1])),
    ):
        batched = func(*args)
        for i, row in enumerate(batched):
            np.testing.assert_allclose(row, func(*(a[i] for a in args)), rtol=1e-15, atol=1e-15)


# ---------------------------------------------------------------------------- headings


@given(yaws(-4 * math.pi, 4 * math.pi))
def test_yaw_round_trip_wraps_into_half_open_range(yaw):
    back = float(quat2yaw(yaw2quat(yaw)))
    assert -math.pi < back <= math.pi
    assert abs(angle_diff(back, yaw)) <= 1e-14


@given(yaws(-4 * math.pi, 4 * math.pi))
def test_yaw2quat_is_unit_and_planar(yaw):
    q = yaw2quat(yaw)
    assert q[0] == 0.0 and q[1] == 0.0
    assert abs(np.linalg.norm(q) - 1.0) <= 1e-15


@given(unit_quaternions())
def test_quat2yaw_is_the_heading_of_the_forward_axis(q):
    forward = quat_apply(q, [1.0, 0.0, 0.0])
    planar = math.hypot(forward[0], forward[1])
    yaw = float(quat2yaw(q))
    if planar > 1e-6:
        expected = math.atan2(forward[1], forward[0])
        assert abs(angle_diff(yaw, expected)) <= 1e-14 / planar
    assert -math.pi < yaw <= math.pi


@given(unit_quaternions(), st.floats(0.5, 2.0))
def test_heading_of_is_the_heading_of_the_forward_axis(q, scale):
    """The scalar form, on quaternions of any length, against the rotated +x axis worked out
    by quat_apply; straight up or down it reads the heading off +y, as quat2yaw does."""
    qx, qy, qz, qw = (float(v) * scale for v in q)
    forward = quat_apply(q, [1.0, 0.0, 0.0])
    planar = math.hypot(forward[0], forward[1])
    yaw = heading_of(qx, qy, qz, qw)
    if planar > 1e-6:
        assert abs(angle_diff(yaw, math.atan2(forward[1], forward[0]))) <= 1e-14 / planar
    assert -math.pi <= yaw <= math.pi


@given(st.floats(-math.pi, math.pi), st.sampled_from([1.0, -1.0]))
def test_heading_of_straight_up_or_down_is_quat2yaw(angle, sign):
    # +x rotated onto +z or -z (pitch -+90 degrees) after a yaw of `angle`.
    q = quat_multiply(yaw2quat(angle), [0.0, sign * math.sin(math.pi / 4), 0.0, math.cos(math.pi / 4)])
    assert abs(angle_diff(heading_of(*(float(v) for v in q)), float(quat2yaw(q)))) <= 1e-9


# ------------------------------------------------------------------------- polar form


@given(finite_vectors(2))
def test_cartesian_polar_round_trip(xy):
    polar = cartesian_to_polar(xy)
    rho, phi = polar
    assert rho >= 0.0 and -math.pi < phi <= math.pi
    np.testing.assert_allclose(polar_to_cartesian(polar), xy, rtol=0, atol=ATOL)


@given(st.floats(1e-3, 1e3), yaws(-4 * math.pi, 4 * math.pi))
def test_polar_cartesian_round_trip(rho, phi):
    back_rho, back_phi = cartesian_to_polar(polar_to_cartesian([rho, phi]))
    assert abs(back_rho - rho) <= 1e-12 * rho
    assert abs(angle_diff(back_phi, phi)) <= 1e-12
    assert -math.pi < back_phi <= math.pi


# ---------------------------------------------------------------------- frame changes


@given(finite_vectors(3), unit_quaternions(), finite_vectors(3))
def test_to_robot_frame_inverts_the_pose(pos, quat, point):
    local = to_robot_frame(pos, quat, point)
    np.testing.assert_allclose(pos + quat_apply(quat, local), point, rtol=0, atol=ATOL)


@given(finite_vectors(3), unit_quaternions(), finite_vectors(3))
def test_to_robot_frame_preserves_distance_to_the_robot(pos, quat, point):
    local = to_robot_frame(pos, quat, point)
    assert abs(np.linalg.norm(local) - l2_distance(pos, point)) <= ATOL


@given(finite_vectors(3), unit_quaternions(), finite_vectors(2))
def test_to_robot_frame_planar_points_sit_at_robot_height(pos, quat, xy):
    planar = to_robot_frame(pos, quat, xy)
    spatial = to_robot_frame(pos, quat, [xy[0], xy[1], pos[2]])
    np.testing.assert_allclose(planar, spatial[:2], rtol=0, atol=ATOL)


@given(finite_vectors(3), yaws(), finite_vectors(2))
def test_to_robot_frame_planar_is_a_2d_rotation_for_planar_poses(pos, yaw, xy):
    dx, dy = xy[0] - pos[0], xy[1] - pos[1]
    c, s = math.cos(yaw), math.sin(yaw)
    expected = [c * dx + s * dy, -s * dx + c * dy]
    np.testing.assert_allclose(to_robot_frame(pos, yaw2quat(yaw), xy), expected, rtol=0, atol=ATOL)


# ------------------------------------------------------------------------- distances


@given(finite_vectors(3), finite_vectors(3))
def test_l2_distance_is_symmetric_and_non_negative(a, b):
    assert l2_distance(a, b) == l2_distance(b, a)
    assert l2_distance(a, b) >= 0.0
    assert l2_distance(a, a) == 0.0


@given(finite_vectors(3), finite_vectors(3), finite_vectors(3))
def test_l2_distance_triangle_inequality(a, b, c):
    assert l2_distance(a, c) <= l2_distance(a, b) + l2_distance(b, c) + 1e-12


@given(finite_vectors(2), finite_vectors(2))
def test_l2_distance_of_planar_points_is_hypot(a, b):
    expected = math.hypot(a[0] - b[0], a[1] - b[1])
    assert abs(l2_distance(a, b) - expected) <= 1e-15 * max(expected, 1.0)
    assert abs(l2_distance(a[None], b[None])[0] - expected) <= 1e-15 * max(expected, 1.0)
