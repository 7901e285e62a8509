"""Example tests for pointnav_core.transforms: known values, scipy agreement, shapes, errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from pointnav_core.transforms import (
    cartesian_to_polar,
    euler2quat,
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

S = math.sqrt(0.5)
IDENTITY = [0.0, 0.0, 0.0, 1.0]
YAW_90 = [0.0, 0.0, S, S]


def random_quats(n: int, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).normal(size=(n, 4))


def assert_same_rotation(q1, q2, atol=1e-12):
    """Quaternions equal up to sign (q and -q are the same rotation)."""
    q1, q2 = np.asarray(q1), np.asarray(q2)
    sign = np.where(np.sum(q1 * q2, axis=-1, keepdims=True) < 0, -1.0, 1.0)
    np.testing.assert_allclose(q1, sign * q2, rtol=0, atol=atol)


def angle_diff(a, b):
    """Smallest signed difference between angles, in [-pi, pi]."""
    return np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b))))


# ------------------------------------------------------------------------- known values


def test_yaw2quat_90_degrees_is_half_angle_quaternion():
    np.testing.assert_allclose(yaw2quat(np.pi / 2), YAW_90, rtol=0, atol=1e-15)


def test_quat2mat_90_degree_yaw_maps_x_to_y():
    expected = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    np.testing.assert_allclose(quat2mat(YAW_90), expected, rtol=0, atol=1e-15)


def test_quat_apply_90_degree_yaw_turns_ahead_into_left():
    np.testing.assert_allclose(quat_apply(YAW_90, [1.0, 0.0, 0.0]), [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(quat_apply(YAW_90, [0.0, 1.0, 0.0]), [-1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(quat_apply(YAW_90, [0.0, 0.0, 1.0]), [0, 0, 1], atol=1e-15)


def test_identity_quaternion_is_identity_everywhere():
    assert quat2mat(IDENTITY).tolist() == np.eye(3).tolist()
    assert mat2quat(np.eye(3)).tolist() == IDENTITY
    assert quat2euler(IDENTITY).tolist() == [0.0, 0.0, 0.0]
    assert euler2quat([0.0, 0.0, 0.0]).tolist() == IDENTITY
    assert float(quat2yaw(IDENTITY)) == 0.0
    assert quat_inverse(IDENTITY).tolist() == IDENTITY
    assert quat_apply(IDENTITY, [1.0, -2.0, 3.0]).tolist() == [1.0, -2.0, 3.0]


def test_euler_angles_follow_rz_ry_rx_order():
    roll, pitch, yaw = 0.3, -0.4, 1.1
    rx = [[1, 0, 0], [0, math.cos(roll), -math.sin(roll)], [0, math.sin(roll), math.cos(roll)]]
    ry = [[math.cos(pitch), 0, math.sin(pitch)], [0, 1, 0], [-math.sin(pitch), 0, math.cos(pitch)]]
    rz = [[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0], [0, 0, 1]]
    expected = np.array(rz) @ np.array(ry) @ np.array(rx)
    np.testing.assert_allclose(quat2mat(euler2quat([roll, pitch, yaw])), expected, atol=1e-15)


def test_euler2quat_of_pure_yaw_equals_yaw2quat():
    for yaw in (0.0, 1.0, -2.5, np.pi, 5.0):
        np.testing.assert_allclose(euler2quat([0.0, 0.0, yaw]), yaw2quat(yaw), atol=1e-16)


@pytest.mark.parametrize("pitch", [np.pi / 2, -np.pi / 2])
@pytest.mark.parametrize("roll, yaw", [(0.3, 0.5), (-2.0, 2.5), (3.0, -3.0), (0.0, 0.0)])
def test_quat2euler_at_gimbal_lock_sets_roll_zero_and_keeps_rotation(pitch, roll, yaw):
    quat = euler2quat([roll, pitch, yaw])
    back = quat2euler(quat)
    assert back[0] == 0.0
    assert back[1] == pytest.approx(pitch, abs=1e-12)
    assert_same_rotation(euler2quat(back), quat)
    # quat2yaw follows the same convention there.
    assert abs(angle_diff(quat2yaw(quat), back[2])) < 1e-12


def test_quat2euler_near_gimbal_lock_is_still_accurate():
    for offset in (1e-13, 1e-11, 1e-9, 1e-6):
        for pitch in (np.pi / 2 - offset, -np.pi / 2 + offset):
            quat = euler2quat([0.3, pitch, 0.5])
            assert_same_rotation(euler2quat(quat2euler(quat)), quat, atol=1e-12)


def test_quat2yaw_of_half_turn_is_pi_for_either_sign():
    assert float(quat2yaw([0.0, 0.0, 1.0, 0.0])) == np.pi
    assert float(quat2yaw([0.0, 0.0, -1.0, 0.0])) == np.pi
    assert quat2yaw(np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, -1.0, 0.0]])).tolist() == [
        np.pi,
        np.pi,
    ]


def test_quat2euler_angles_are_in_half_open_range():
    half_turns = [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, -1.0, 0.0]]
    for euler in quat2euler(half_turns):
        assert -np.pi < euler[0] <= np.pi and -np.pi < euler[2] <= np.pi


def test_quat2yaw_ignores_tilt_of_a_pitched_robot():
    quat = euler2quat([0.2, 0.4, 1.0])
    assert float(quat2yaw(quat)) == pytest.approx(1.0, abs=1e-14)


def test_yaw2quat_keeps_the_spec_formula_beyond_pi():
    np.testing.assert_allclose(yaw2quat(3 * np.pi / 2), [0, 0, S, -S], atol=1e-15)


def test_mat2quat_half_turns_are_canonical():
    assert mat2quat(np.diag([1.0, -1.0, -1.0])).tolist() == [1.0, 0.0, 0.0, 0.0]
    assert mat2quat(np.diag([-1.0, 1.0, -1.0])).tolist() == [0.0, 1.0, 0.0, 0.0]
    assert mat2quat(np.diag([-1.0, -1.0, 1.0])).tolist() == [0.0, 0.0, 1.0, 0.0]


def test_mat2quat_returns_non_negative_w():
    quats = mat2quat(quat2mat(random_quats(200)))
    assert (quats[:, 3] >= 0).all()


def test_quat_multiply_composes_yaws():
    np.testing.assert_allclose(quat_multiply(yaw2quat(0.5), yaw2quat(1.0)), yaw2quat(1.5))


def test_quat_multiply_applies_right_operand_first():
    roll_90 = [S, 0.0, 0.0, S]
    composed = quat_multiply(YAW_90, roll_90)
    v = np.array([0.0, 1.0, 0.0])
    np.testing.assert_allclose(
        quat_apply(composed, v), quat_apply(YAW_90, quat_apply(roll_90, v)), atol=1e-15
    )


def test_to_robot_frame_goal_ahead_and_left():
    # Robot at (1, 1) facing +y: a goal at (1, 3) is 2 m ahead, one at (0, 1) is 1 m left.
    pos, quat = [1.0, 1.0, 0.0], yaw2quat(np.pi / 2)
    np.testing.assert_allclose(to_robot_frame(pos, quat, [1.0, 3.0]), [2, 0], atol=1e-15)
    np.testing.assert_allclose(to_robot_frame(pos, quat, [0.0, 1.0]), [0, 1], atol=1e-15)


def test_to_robot_frame_planar_points_are_taken_at_robot_height():
    # A tilted robot, so that the height of the point matters.
    pos, quat = [0.0, 0.0, 0.5], euler2quat([0.3, -0.2, 0.7])
    planar = to_robot_frame(pos, quat, [3.0, -1.0])
    spatial = to_robot_frame(pos, quat, [3.0, -1.0, 0.5])
    np.testing.assert_allclose(planar, spatial[:2], rtol=0, atol=1e-15)
    assert not np.allclose(planar, to_robot_frame(pos, quat, [3.0, -1.0, 0.0])[:2])


def test_to_robot_frame_matches_omnigibson_formula():
    rng = np.random.default_rng(1)
    pos, quat, goal = rng.normal(size=3), rng.normal(size=4), rng.normal(size=3)
    expected = Rotation.from_quat(quat).as_matrix().T @ (goal - pos)
    np.testing.assert_allclose(to_robot_frame(pos, quat, goal), expected, atol=1e-14)


# -------------------------------------------------------------------- scipy agreement


def test_quat2mat_agrees_with_scipy():
    q = random_quats(500)
    np.testing.assert_allclose(quat2mat(q), Rotation.from_quat(q).as_matrix(), atol=1e-14)


def test_mat2quat_agrees_with_scipy_canonical():
    rotations = Rotation.from_quat(random_quats(500))
    expected = rotations.as_quat(canonical=True)
    np.testing.assert_allclose(mat2quat(rotations.as_matrix()), expected, atol=1e-14)


def test_euler2quat_agrees_with_scipy_extrinsic_xyz():
    euler = np.random.default_rng(2).uniform(-4, 4, size=(500, 3))
    assert_same_rotation(euler2quat(euler), Rotation.from_euler("xyz", euler).as_quat())


def test_quat2euler_agrees_with_scipy_extrinsic_xyz():
    q = random_quats(500)
    expected = Rotation.from_quat(q).as_euler("xyz")
    np.testing.assert_allclose(angle_diff(quat2euler(q), expected), 0.0, atol=1e-13)


def test_quat2yaw_agrees_with_scipy_yaw():
    q = random_quats(500)
    expected = Rotation.from_quat(q).as_euler("xyz")[:, 2]
    np.testing.assert_allclose(angle_diff(quat2yaw(q), expected), 0.0, atol=1e-13)


def test_quat_multiply_agrees_with_scipy_composition():
    q1, q2 = random_quats(500, seed=3), random_quats(500, seed=4)
    expected = (Rotation.from_quat(q1) * Rotation.from_quat(q2)).as_quat()
    assert_same_rotation(quat_multiply(q1, q2), expected)


def test_quat_inverse_agrees_with_scipy():
    q = random_quats(500)
    assert_same_rotation(quat_inverse(q), Rotation.from_quat(q).inv().as_quat())


def test_quat_apply_agrees_with_scipy():
    q = random_quats(500)
    v = np.random.default_rng(5).normal(size=(500, 3))
    np.testing.assert_allclose(quat_apply(q, v), Rotation.from_quat(q).apply(v), atol=1e-13)


# ----------------------------------------------------------------- shapes and dtypes

# name -> (function, one input per argument, trailing output shape)
FAMILIES = {
    "euler2quat": (euler2quat, ([0.1, 0.2, 0.3],), (4,)),
    "quat2euler": (quat2euler, ([0.1, 0.2, 0.3, 0.9],), (3,)),
    "quat2mat": (quat2mat, ([0.1, 0.2, 0.3, 0.9],), (3, 3)),
    "mat2quat": (mat2quat, (quat2mat([0.1, 0.2, 0.3, 0.9]).tolist(),), (4,)),
    "quat_inverse": (quat_inverse, ([0.1, 0.2, 0.3, 0.9],), (4,)),
    "quat2yaw": (quat2yaw, ([0.1, 0.2, 0.3, 0.9],), ()),
    "quat_multiply": (quat_multiply, ([0.1, 0.2, 0.3, 0.9], [0.5, -0.1, 0.2, 0.7]), (4,)),
    "quat_apply": (quat_apply, ([0.1, 0.2, 0.3, 0.9], [1.0, -2.0, 0.5]), (3,)),
    "cartesian_to_polar": (cartesian_to_polar, ([3.0, -4.0],), (2,)),
    "polar_to_cartesian": (polar_to_cartesian, ([2.0, 0.4],), (2,)),
    "l2_distance": (l2_distance, ([1.0, 2.0, 3.0], [0.0, -1.0, 2.5]), ()),
    "to_robot_frame_3d": (
        to_robot_frame,
        ([1.0, 2.0, 0.1], [0.1, 0.2, 0.3, 0.9], [4.0, -1.0, 0.3]),
        (3,),
    ),
    "to_robot_frame_2d": (
        to_robot_frame,
        ([1.0, 2.0, 0.1], [0.1, 0.2, 0.3, 0.9], [4.0, -1.0]),
        (2,),
    ),
}


def tiled(value, batch):
    arr = np.asarray(value, dtype=np.float64)
    return np.broadcast_to(arr, batch + arr.shape).copy()


@pytest.mark.parametrize("name", sorted(FAMILIES))
@pytest.mark.parametrize("batch", [(), (1,), (5,), (2, 3), (0,)])
def test_output_is_float64_with_batch_shape_kept(name, batch):
    func, args, tail = FAMILIES[name]
    out = np.asarray(func(*(tiled(a, batch) for a in args)))
    assert out.dtype == np.float64
    assert out.shape == batch + tail


@pytest.mark.parametrize("name", sorted(FAMILIES))
def test_single_value_fast_path_matches_array_path(name):
    func, args, _ = FAMILIES[name]
    single = np.asarray(func(*args))
    batched = func(*(tiled(a, (3,)) for a in args))
    for row in batched:
        np.testing.assert_allclose(row, single, rtol=1e-15, atol=1e-15)


@pytest.mark.parametrize("name", sorted(FAMILIES))
def test_integer_and_float32_inputs_give_float64(name):
    func, args, _ = FAMILIES[name]
    as_f32 = [np.asarray(a, dtype=np.float32) for a in args]
    assert np.asarray(func(*as_f32)).dtype == np.float64


@pytest.mark.parametrize("name", sorted(FAMILIES))
def test_inputs_are_not_modified(name):
    func, args, _ = FAMILIES[name]
    arrays = [tiled(a, (2,)) for a in args]
    copies = [a.copy() for a in arrays]
    func(*arrays)
    for arr, copy in zip(arrays, copies):
        assert np.array_equal(arr, copy)


def test_integer_lists_are_accepted():
    assert yaw2quat(0).tolist() == IDENTITY
    assert quat2mat([0, 0, 0, 1]).dtype == np.float64
    assert cartesian_to_polar([3, 4]).tolist() == [5.0, math.atan2(4, 3)]


def test_scalar_results_are_numpy_float64():
    assert type(quat2yaw(IDENTITY)) is np.float64
    assert type(l2_distance([0.0, 0.0], [3.0, 4.0])) is np.float64


def test_yaw2quat_keeps_any_batch_shape():
    assert yaw2quat(np.zeros((2, 3))).shape == (2, 3, 4)
    assert yaw2quat([]).shape == (0, 4)


def test_quat_multiply_broadcasts_batch_shapes():
    q1 = random_quats(2).reshape(2, 1, 4)
    q2 = random_quats(3, seed=1)
    out = quat_multiply(q1, q2)
    assert out.shape == (2, 3, 4)
    np.testing.assert_allclose(out[1, 2], quat_multiply(q1[1, 0], q2[2]), atol=1e-15)


def test_quat_apply_broadcasts_one_quaternion_over_many_vectors():
    v = np.random.default_rng(0).normal(size=(7, 3))
    out = quat_apply(YAW_90, v)
    assert out.shape == (7, 3)
    np.testing.assert_allclose(out[:, 0], -v[:, 1], atol=1e-15)


def test_to_robot_frame_one_pose_many_points():
    points = np.random.default_rng(0).normal(size=(6, 2))
    out = to_robot_frame([0.0, 0.0, 0.0], IDENTITY, points)
    assert out.shape == (6, 2)
    np.testing.assert_allclose(out, points, atol=0)


def test_to_robot_frame_many_poses_against_many_points():
    rng = np.random.default_rng(0)
    pos, quat = rng.normal(size=(4, 1, 3)), rng.normal(size=(4, 1, 4))
    points = rng.normal(size=(5, 3))
    out = to_robot_frame(pos, quat, points)
    assert out.shape == (4, 5, 3)
    np.testing.assert_allclose(out[3, 2], to_robot_frame(pos[3, 0], quat[3, 0], points[2]))


def test_l2_distance_broadcasts_one_point_against_many():
    points = np.array([[3.0, 4.0], [0.0, 0.0], [-6.0, 8.0]])
    assert l2_distance(points, [0.0, 0.0]).tolist() == [5.0, 0.0, 10.0]


def test_l2_distance_does_not_overflow_for_large_coordinates():
    a, b = [1e200, 1e200], [-1e200, -1e200]
    expected = 2e200 * math.sqrt(2)
    assert float(l2_distance(a, b)) == pytest.approx(expected, rel=1e-15)
    assert float(l2_distance([a], [b])[0]) == pytest.approx(expected, rel=1e-15)


def test_results_are_fresh_arrays():
    q = np.array(IDENTITY)
    for out in (quat_inverse(q), quat_multiply(q, q), quat2mat(q), mat2quat(np.eye(3))):
        assert not np.shares_memory(out, q)


@pytest.mark.parametrize("scale", [1e-200, 1e-3, 7.0, 1e200])
def test_quaternions_are_normalised_whatever_their_scale(scale):
    q = np.array([0.1, -0.2, 0.3, 0.9])
    unit = q / np.linalg.norm(q)
    np.testing.assert_allclose(quat2mat(scale * q), quat2mat(unit), atol=1e-15)
    np.testing.assert_allclose(quat_inverse(scale * q), quat_inverse(unit), atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(quat_multiply(scale * q, scale * q)), 1.0)
    assert float(quat2yaw(scale * q)) == pytest.approx(float(quat2yaw(unit)), abs=1e-15)
    np.testing.assert_allclose(quat2mat(np.stack([scale * q, q])), quat2mat([unit, unit]))


def test_zeros_are_returned_positive():
    for out in (quat_inverse(IDENTITY), cartesian_to_polar([-0.0, -0.0]), quat2euler(IDENTITY)):
        assert not np.signbit(out).any()


# ------------------------------------------------------------------------------- errors

QUAT_TAKERS = {
    "quat2euler": (quat2euler, "quat", lambda q: (q,)),
    "quat2mat": (quat2mat, "quat", lambda q: (q,)),
    "quat_inverse": (quat_inverse, "quat", lambda q: (q,)),
    "quat2yaw": (quat2yaw, "quat", lambda q: (q,)),
    "quat_apply": (quat_apply, "quat", lambda q: (q, [1.0, 0.0, 0.0])),
    "quat_multiply_q1": (quat_multiply, "q1", lambda q: (q, IDENTITY)),
    "quat_multiply_q2": (quat_multiply, "q2", lambda q: (IDENTITY, q)),
    "to_robot_frame": (to_robot_frame, "robot_quat", lambda q: ([0.0, 0.0, 0.0], q, [1.0, 1.0])),
}

BAD_QUATS = {
    "zero": ([0.0, 0.0, 0.0, 0.0], "non-zero quaternion"),
    "zero_in_batch": ([IDENTITY, [0.0, 0.0, 0.0, 0.0]], "at index (1,)"),
    "nan": ([0.0, 0.0, float("nan"), 1.0], "finite"),
    "inf_in_batch": ([IDENTITY, [0.0, float("inf"), 0.0, 1.0]], "finite"),
    "three_components": ([0.0, 0.0, 1.0], "shape (..., 4)"),
    "scalar": (1.0, "shape (..., 4)"),
    "not_numbers": ("north", "shape (..., 4)"),
}


@pytest.mark.parametrize("bad", sorted(BAD_QUATS))
@pytest.mark.parametrize("taker", sorted(QUAT_TAKERS))
def test_bad_quaternion_raises_value_error_naming_the_parameter(taker, bad):
    func, name, make_args = QUAT_TAKERS[taker]
    value, expected = BAD_QUATS[bad]
    with pytest.raises(ValueError, match=rf"^{name} must .*") as info:
        func(*make_args(value))
    assert expected in str(info.value)


BAD_OTHER = [
    (euler2quat, ([0.0, float("nan"), 0.0],), "euler must be finite"),
    (euler2quat, ([0.0, 0.0],), r"euler must have shape \(\.\.\., 3\)"),
    (yaw2quat, (float("nan"),), "yaw must be finite"),
    (yaw2quat, ([0.0, float("-inf")],), "yaw must be finite"),
    (yaw2quat, ("east",), "yaw must be"),
    (quat_apply, (IDENTITY, [0.0, float("nan"), 0.0]), "vec must be finite"),
    (quat_apply, (IDENTITY, [1.0, 0.0]), r"vec must have shape \(\.\.\., 3\)"),
    (quat_apply, (random_quats(2), np.zeros((3, 3))), "quat and vec must have batch shapes"),
    (quat_multiply, (random_quats(2), random_quats(3)), "q1 and q2 must have batch shapes"),
    (mat2quat, (np.eye(2),), r"mat must have shape \(\.\.\., 3, 3\)"),
    (mat2quat, (np.full((3, 3), np.nan),), "mat must be finite"),
    (mat2quat, (np.diag([1.0, 1.0, -1.0]),), "mat must hold rotation matrices"),
    (mat2quat, (2 * np.eye(3),), "mat must hold rotation matrices"),
    (mat2quat, (np.stack([np.eye(3), 2 * np.eye(3)]),), r"at index \(1,\)"),
    (cartesian_to_polar, ([1.0, float("nan")],), "xy must be finite"),
    (cartesian_to_polar, ([1.0, 2.0, 3.0],), r"xy must have shape \(\.\.\., 2\)"),
    (polar_to_cartesian, ([float("inf"), 0.0],), "polar must be finite"),
    (polar_to_cartesian, ([-1.0, 0.0],), "polar must have rho"),
    (polar_to_cartesian, ([[1.0, 0.0], [-1.0, 0.0]],), "polar must have rho"),
    (l2_distance, ([0.0, float("nan")], [0.0, 0.0]), "a must be finite"),
    (l2_distance, ([[0.0, 0.0]], [[0.0, float("inf")]]), "b must be finite"),
    (l2_distance, ([0.0, 0.0], [0.0, 0.0, 0.0]), "a and b must have shape"),
    (l2_distance, (1.0, 2.0), "a and b must have shape"),
    (l2_distance, (np.zeros((2, 0)), np.zeros((2, 0))), "a and b must have shape"),
    (l2_distance, (np.zeros((2, 2)), np.zeros((3, 2))), "a and b must have batch shapes"),
    (to_robot_frame, ([0.0, 0.0], IDENTITY, [1.0, 1.0]), "robot_pos must have shape"),
    (to_robot_frame, ([0.0, 0.0, float("nan")], IDENTITY, [1.0, 1.0]), "robot_pos must be finite"),
    (to_robot_frame, ([0.0, 0.0, 0.0], IDENTITY, [1.0]), r"points must have shape \(\.\.\., 2\)"),
    (to_robot_frame, ([0.0, 0.0, 0.0], IDENTITY, [1.0, float("nan")]), "points must be finite"),
    (
        to_robot_frame,
        (np.zeros((2, 3)), IDENTITY, np.zeros((3, 2))),
        "robot_pos, robot_quat and points must have batch shapes",
    ),
    (
        to_robot_frame,
        (np.zeros((2, 3)), IDENTITY, np.zeros((3, 3))),
        "robot_pos, robot_quat and points must have batch shapes",
    ),
    (
        to_robot_frame,
        ([0.0, 0.0, 0.0], random_quats(2), np.zeros((3, 3))),
        "robot_pos, robot_quat and points must have batch shapes",
    ),
]


@pytest.mark.parametrize(
    "func, args, message",
    BAD_OTHER,
    ids=[f"{func.__name__}-{i}" for i, (func, _, _) in enumerate(BAD_OTHER)],
)
def test_bad_input_raises_value_error_naming_the_parameter(func, args, message):
    with pytest.raises(ValueError, match=message):
        func(*args)


def test_mat2quat_accepts_float32_rounded_rotations():
    mats = quat2mat(random_quats(100)).astype(np.float32)
    assert_same_rotation(mat2quat(mats), mat2quat(mats.astype(np.float64)), atol=1e-6)


# -------------------------------------------------------------------- polar edge cases


def test_cartesian_to_polar_negative_x_axis_is_pi_not_minus_pi():
    assert cartesian_to_polar([-1.0, 0.0]).tolist() == [1.0, np.pi]
    assert cartesian_to_polar([-1.0, -0.0]).tolist() == [1.0, np.pi]
    assert cartesian_to_polar([[-2.0, -0.0]]).tolist() == [[2.0, np.pi]]


def test_cartesian_to_polar_tiny_negative_y_behind_rounds_to_pi():
    # atan2 rounds this to -pi; the range is (-pi, pi], so it must come back as pi.
    assert cartesian_to_polar([-1.0, -1e-300])[1] == np.pi
    assert cartesian_to_polar([[-1.0, -1e-300]])[0, 1] == np.pi


def test_cartesian_to_polar_origin_is_zero_for_every_signed_zero():
    for xy in ([0.0, 0.0], [-0.0, 0.0], [0.0, -0.0], [-0.0, -0.0]):
        assert cartesian_to_polar(xy).tolist() == [0.0, 0.0]
        assert cartesian_to_polar([xy]).tolist() == [[0.0, 0.0]]


def test_cartesian_to_polar_quadrants():
    out = cartesian_to_polar([[1.0, 0.0], [0.0, 1.0], [0.0, -1.0], [1.0, 1.0], [-1.0, -1.0]])
    np.testing.assert_allclose(out[:, 1], [0, np.pi / 2, -np.pi / 2, np.pi / 4, -3 * np.pi / 4])
    np.testing.assert_allclose(out[:, 0], [1, 1, 1, math.sqrt(2), math.sqrt(2)])


def test_polar_to_cartesian_accepts_unwrapped_angles_and_zero_rho():
    expected = [math.cos(0.5), math.sin(0.5)]
    np.testing.assert_allclose(polar_to_cartesian([1.0, 2 * np.pi + 0.5]), expected)
    assert polar_to_cartesian([0.0, 3.0]).tolist() == [0.0, 0.0]
