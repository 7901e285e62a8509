"""The kinematic backend: exact motion, collisions, falls, poses and speed of the fast path."""

from __future__ import annotations

import math
import types

import numpy as np
import pytest
from pointnav_kinematic import KinematicBackend

from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID, TraversableMap
from pointnav_core.testing.conformance import obstacle_distance

IDENTITY = (0.0, 0.0, 0.0, 1.0)


def quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def yaw_of(q: np.ndarray) -> float:
    return 2.0 * math.atan2(q[2], q[3])


def scene_of(*floors: TraversableMap) -> types.SimpleNamespace:
    """A stand-in for Scene with exactly the three members a backend may use."""
    return types.SimpleNamespace(
        floors=list(floors),
        n_floors=len(floors),
        get_floor_height=lambda floor=0: floors[floor].height,
    )


def open_floor(size: int = 60, res: float = 0.1, height: float = 0.0) -> TraversableMap:
    """A free square room with a one-cell wall all around; inside spans (res, (size-1)*res)."""
    grid = np.full((size, size), FREE, np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return TraversableMap(grid, res, height=height)


def loaded(floors, specs, *, mode="slide", freq=10.0) -> KinematicBackend:
    backend = KinematicBackend(collision_mode=mode)
    backend.load(scene_of(*floors), specs, action_frequency=freq)
    return backend


def position(backend: KinematicBackend, idn: int = 0) -> np.ndarray:
    return backend.get_pose(idn)[0]


# ----------------------------------------------------------------------- construction


def test_collision_mode_must_be_a_known_choice():
    with pytest.raises(ValueError, match=r"collision_mode must be one of \['slide', 'stop'\]"):
        KinematicBackend(collision_mode="bounce")


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan")])
def test_fall_speed_must_be_positive(bad):
    with pytest.raises(ValueError, match="fall_speed"):
        KinematicBackend(fall_speed=bad)


@pytest.mark.parametrize("bad", [0.0, -10.0, float("inf")])
def test_load_rejects_bad_action_frequency(bad):
    with pytest.raises(ValueError, match="action_frequency"):
        loaded([open_floor()], [RobotSpec()], freq=bad)


def test_load_rejects_non_spec_robots():
    with pytest.raises(TypeError, match=r"robots\[1\] must be a RobotSpec"):
        loaded([open_floor()], [RobotSpec(), 0.3])


def test_n_robots_is_zero_before_load_and_counts_specs_after():
    backend = KinematicBackend()
    assert backend.n_robots == 0
    backend.load(scene_of(open_floor()), [RobotSpec(), RobotSpec()])
    assert backend.n_robots == 2


def test_robots_start_present_unplaced_and_at_rest():
    backend = loaded([open_floor()], [RobotSpec(), RobotSpec()])
    backend.step({0: [1.0, 1.0]})  # unplaced: not moved
    for idn in range(2):
        assert backend.is_present(idn)
        assert not backend.in_contact(idn)
        assert position(backend, idn).tolist() == [0.0, 0.0, 0.0]
        assert backend.get_velocity(idn)[0].tolist() == [0.0, 0.0, 0.0]
    # Unplaced robots block nothing.
    backend.land(1, 0, (3.0, 3.0), IDENTITY)
    assert backend.is_valid_pose(1, (3.0, 3.0))


def test_robot_index_errors_name_the_range():
    backend = loaded([open_floor()], [RobotSpec()])
    with pytest.raises(ValueError, match=r"idn must be in \[0, 1\), got 3"):
        backend.get_pose(3)
    with pytest.raises(ValueError, match=r"idn must be in \[0, 1\)"):
        backend.step({1: [0.0, 0.0]})
    with pytest.raises(TypeError, match="idn must be an int"):
        backend.get_pose("robot_0")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"floor must be in \[0, 1\), got 2"):
        backend.land(0, 2, (1.0, 1.0), IDENTITY)


def test_step_with_bad_action_leaves_state_unchanged():
    backend = loaded([open_floor()], [RobotSpec(), RobotSpec()])
    backend.land(0, 0, (2.0, 2.0), IDENTITY)
    backend.land(1, 0, (4.0, 4.0), IDENTITY)
    with pytest.raises(ValueError, match="action must be finite"):
        backend.step({0: [1.0, 0.0], 1: [math.nan, 0.0]})
    assert position(backend, 0).tolist() == [2.0, 2.0, 0.0]


# ----------------------------------------------------------------------- exact motion


def test_differential_arc_matches_hand_computed_values():
    spec = RobotSpec(max_linear_velocity=1.0, max_angular_velocity=2.0)
    backend = loaded([open_floor()], [spec], freq=4.0)
    x0, y0, th = 3.0, 2.5, 0.3
    backend.land(0, 0, (x0, y0), quat(th))
    backend.step({0: [0.5, 0.25]})  # v = 0.5 m/s, w = 0.5 rad/s, dt = 0.25 s
    v, w, dt = 0.5, 0.5, 0.25
    x = x0 + v / w * (math.sin(th + w * dt) - math.sin(th))
    y = y0 - v / w * (math.cos(th + w * dt) - math.cos(th))
    pos, q = backend.get_pose(0)
    np.testing.assert_allclose(pos, [x, y, 0.0], rtol=0, atol=1e-12)
    assert yaw_of(q) == pytest.approx(th + w * dt, abs=1e-12)


def test_differential_drives_straight_when_not_turning():
    backend = loaded([open_floor()], [RobotSpec()])
    backend.land(0, 0, (2.0, 2.0), quat(math.pi / 6))
    backend.step({0: [1.0, 0.0]})
    np.testing.assert_allclose(
        position(backend)[:2],
        [2.0 + 0.05 * math.cos(math.pi / 6), 2.0 + 0.05 * math.sin(math.pi / 6)],
        atol=1e-15,
    )


def test_rotation_in_place_keeps_position():
    backend = loaded([open_floor()], [RobotSpec()])
    backend.land(0, 0, (2.0, 2.0), IDENTITY)
    backend.step({0: [0.0, -1.0]})
    pos, q = backend.get_pose(0)
    assert pos.tolist() == [2.0, 2.0, 0.0]
    assert yaw_of(q) == pytest.approx(-0.15, abs=1e-12)


def test_holonomic_motion_matches_closed_form():
    spec = RobotSpec(drive="holonomic", max_linear_velocity=1.0, max_angular_velocity=1.0)
    backend = loaded([open_floor()], [spec], freq=2.0)
    x0, y0, th = 3.0, 3.0, -0.7
    backend.land(0, 0, (x0, y0), quat(th))
    vx, vy, w, dt = 0.4, -0.3, 0.8, 0.5
    backend.step({0: [vx, vy, w]})
    # Integral of R(th + w t) (vx, vy) over [0, dt].
    s0, c0 = math.sin(th), math.cos(th)
    s1, c1 = math.sin(th + w * dt), math.cos(th + w * dt)
    x = x0 + (vx * (s1 - s0) + vy * (c1 - c0)) / w
    y = y0 + (-vx * (c1 - c0) + vy * (s1 - s0)) / w
    np.testing.assert_allclose(position(backend)[:2], [x, y], atol=1e-12)


def test_holonomic_moves_sideways_in_the_robot_frame():
    spec = RobotSpec(drive="holonomic", max_linear_velocity=1.0)
    backend = loaded([open_floor()], [spec])
    backend.land(0, 0, (3.0, 3.0), quat(math.pi / 2))  # facing +y: left is -x
    backend.step({0: [0.0, 1.0, 0.0]})
    np.testing.assert_allclose(position(backend)[:2], [2.9, 3.0], atol=1e-15)


def test_actions_are_clipped_before_integration():
    backend = loaded([open_floor()], [RobotSpec()])
    backend.land(0, 0, (2.0, 2.0), IDENTITY)
    backend.step({0: [50.0, 0.0]})
    assert position(backend)[0] == pytest.approx(2.05, abs=1e-15)


def test_robots_without_an_action_get_a_zero_command():
    backend = loaded([open_floor()], [RobotSpec(), RobotSpec()])
    backend.land(0, 0, (2.0, 2.0), IDENTITY)
    backend.land(1, 0, (4.0, 4.0), IDENTITY)
    backend.step({0: [1.0, 0.0]})
    backend.step({0: [1.0, 0.0]})
    assert position(backend, 1).tolist() == [4.0, 4.0, 0.0]
    assert backend.get_velocity(1)[0].tolist() == [0.0, 0.0, 0.0]


def test_velocity_agrees_with_displacement_in_open_space_and_sliding():
    backend = loaded([open_floor()], [RobotSpec(drive="holonomic")])
    backend.land(0, 0, (5.7, 3.0), quat(0.2))
    for action in ([1.0, 0.3, 0.5], [1.0, 1.0, -1.0], [1.0, 1.0, 0.0]):  # ends against x = 5.9
        before, q0 = backend.get_pose(0)
        backend.step({0: action})
        after, q1 = backend.get_pose(0)
        lin, ang = backend.get_velocity(0)
        np.testing.assert_allclose(lin, (after - before) / 0.1, atol=1e-12)
        dyaw = math.remainder(yaw_of(q1) - yaw_of(q0), 2 * math.pi)
        np.testing.assert_allclose(ang, [0.0, 0.0, dyaw / 0.1], atol=1e-9)
    assert backend.in_contact(0)


def test_fast_path_agrees_with_contact_resolution_path():
    # The same free motion, once far from everything (one clearance lookup) and once along
    # the map's edge, where the exact resolution runs but finds nothing to hit.
    spec = RobotSpec(radius=0.1, drive="holonomic", max_linear_velocity=1.0)
    grid = np.zeros((60, 60), np.uint8)
    backend = loaded([TraversableMap(grid, 0.1)], [spec, spec])
    backend.land(0, 0, (3.0, 3.0), quat(0.4))
    backend.land(1, 0, (3.0, 0.12), quat(0.4))
    for _ in range(5):
        backend.step({0: [0.9, -0.2, 1.0], 1: [0.9, -0.2, 1.0]})
        d0 = position(backend, 0) - [3.0, 3.0, 0.0]
        d1 = position(backend, 1) - [3.0, 0.12, 0.0]
        np.testing.assert_allclose(d0, d1, atol=1e-12)
    assert not backend.in_contact(1)


# ----------------------------------------------------------------------- collisions


def test_driving_into_a_wall_sets_contact_and_stops_at_the_wall():
    floor = open_floor()  # right wall: x in [5.9, 6.0)
    backend = loaded([floor], [RobotSpec()])
    backend.land(0, 0, (5.6, 3.0), IDENTITY)
    flags = []
    for _ in range(5):
        backend.step({0: [1.0, 0.0]})
        flags.append(backend.in_contact(0))
        assert obstacle_distance(floor, *position(backend)[:2]) >= 0.18 - 1e-9
    assert flags == [False, False, True, True, True]
    assert position(backend)[0] == pytest.approx(5.9 - 0.18, abs=1e-8)


def test_slide_mode_keeps_the_tangential_part_of_the_motion():
    floor = open_floor()
    backend = loaded([floor], [RobotSpec()], mode="slide")
    backend.land(0, 0, (5.72 - 1e-6, 3.0), quat(math.pi / 4))  # touching the wall at 45 deg
    backend.step({0: [1.0, 0.0]})
    assert backend.in_contact(0)
    pos = position(backend)
    # Only the tangential (+y) part of the 0.05 m step survives.
    assert pos[1] == pytest.approx(3.0 + 0.05 * math.sqrt(0.5), abs=1e-9)
    assert pos[0] == pytest.approx(5.72, abs=1e-6)
    assert obstacle_distance(floor, *pos[:2]) >= 0.18 - 1e-9


def test_stop_mode_stays_at_the_contact_point():
    floor = open_floor()
    backend = loaded([floor], [RobotSpec()], mode="stop")
    backend.land(0, 0, (5.7, 3.0), quat(math.pi / 4))
    backend.step({0: [1.0, 0.0]})
    assert backend.in_contact(0)
    x, y, _ = position(backend)
    # Moved along the heading up to contact, then stopped.
    assert x == pytest.approx(5.72, abs=1e-8)
    assert y == pytest.approx(3.02, abs=1e-8)
    backend.step({0: [1.0, 0.0]})
    assert backend.in_contact(0)
    assert position(backend)[:2] == pytest.approx([x, y], abs=1e-12)


def test_driving_away_from_a_wall_is_not_a_contact():
    backend = loaded([open_floor()], [RobotSpec()])
    backend.land(0, 0, (5.72, 3.0), IDENTITY)  # touching the right wall
    backend.step({0: [-1.0, 0.0]})
    assert not backend.in_contact(0)
    assert position(backend)[0] == pytest.approx(5.67)


def test_rotation_is_never_blocked():
    backend = loaded([open_floor()], [RobotSpec()], mode="stop")
    backend.land(0, 0, (5.72, 3.0), IDENTITY)
    backend.step({0: [1.0, 1.0]})
    assert backend.in_contact(0)
    assert yaw_of(backend.get_pose(0)[1]) == pytest.approx(0.15, abs=1e-12)


def test_concave_corner_stops_a_sliding_robot():
    floor = open_floor()
    backend = loaded([floor], [RobotSpec()])
    backend.land(0, 0, (5.5, 5.5), quat(math.pi / 4))
    for _ in range(20):
        backend.step({0: [1.0, 0.0]})
        assert obstacle_distance(floor, *position(backend)[:2]) >= 0.18 - 1e-9
    np.testing.assert_allclose(position(backend)[:2], [5.72, 5.72], atol=1e-8)
    assert backend.in_contact(0)


@pytest.mark.parametrize("radius", [0.0, 0.001, 0.02])
@pytest.mark.parametrize("mode", ["slide", "stop"])
def test_one_cell_wall_at_huge_speed_does_not_tunnel(radius, mode):
    grid = np.zeros((5, 40), np.uint8)
    grid[:, 20] = OBSTACLE  # wall x in [2.0, 2.1)
    floor = TraversableMap(grid, 0.1)
    spec = RobotSpec(radius=radius, max_linear_velocity=1000.0, drive="holonomic")
    backend = loaded([floor], [spec], mode=mode)
    backend.land(0, 0, (1.0, 0.25), IDENTITY)
    backend.step({0: [1.0, 0.01, 0.0]})  # 100 m in one step
    x, y, _ = position(backend)
    assert backend.in_contact(0)
    assert x <= 2.0 - radius + 1e-9
    assert obstacle_distance(floor, x, y) >= radius - 1e-9


def test_point_robot_never_enters_an_obstacle_cell():
    grid = np.zeros((10, 10), np.uint8)
    grid[4:6, 4:6] = OBSTACLE
    floor = TraversableMap(grid, 1.0)
    backend = loaded([floor], [RobotSpec(radius=0.0, max_linear_velocity=3.0)])
    for yaw in np.linspace(-math.pi, math.pi, 17):
        start = (5.0 - 3.0 * math.cos(yaw), 5.0 - 3.0 * math.sin(yaw))
        backend.land(0, 0, start, quat(yaw))  # aimed at the block's centre
        for _ in range(20):
            backend.step({0: [1.0, 0.2]})
            x, y, _ = position(backend)
            assert floor.cell_class_at([x, y]) != OBSTACLE
            assert obstacle_distance(floor, x, y) >= 0.0


def test_two_robots_head_on_are_both_flagged_and_never_overlap():
    backend = loaded([open_floor()], [RobotSpec(), RobotSpec(radius=0.25)])
    backend.land(0, 0, (2.0, 3.0), IDENTITY)
    backend.land(1, 0, (2.7, 3.0), quat(math.pi))
    flagged = [False, False]
    for _ in range(10):
        backend.step({0: [1.0, 0.0], 1: [1.0, 0.0]})
        gap = np.linalg.norm(position(backend, 0) - position(backend, 1))
        assert gap >= 0.18 + 0.25 - 1e-9
        flagged = [flagged[i] or backend.in_contact(i) for i in range(2)]
        assert backend.in_contact(0) == backend.in_contact(1)
    assert flagged == [True, True]
    assert gap == pytest.approx(0.43, abs=1e-8)


def test_a_robot_hit_by_another_is_flagged_too():
    backend = loaded([open_floor()], [RobotSpec(), RobotSpec()])
    backend.land(0, 0, (2.0, 3.0), IDENTITY)
    backend.land(1, 0, (2.4, 3.0), IDENTITY)  # standing still
    for _ in range(3):
        backend.step({0: [1.0, 0.0]})
    assert backend.in_contact(0) and backend.in_contact(1)
    assert position(backend, 1).tolist() == [2.4, 3.0, 0.0]


def test_robots_on_different_floors_never_collide():
    floors = [open_floor(height=0.0), open_floor(height=3.0)]
    backend = loaded(floors, [RobotSpec(), RobotSpec()])
    backend.land(0, 0, (2.0, 3.0), IDENTITY)
    backend.land(1, 1, (2.3, 3.0), quat(math.pi))
    for _ in range(5):
        backend.step({0: [1.0, 0.0], 1: [1.0, 0.0]})
        assert not backend.in_contact(0) and not backend.in_contact(1)
    np.testing.assert_allclose(position(backend, 0), [2.25, 3.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(position(backend, 1), [2.05, 3.0, 3.0], atol=1e-12)


def test_absent_robot_is_not_moved_and_collides_with_nothing():
    backend = loaded([open_floor()], [RobotSpec(), RobotSpec()])
    backend.land(0, 0, (2.0, 3.0), IDENTITY)
    backend.land(1, 0, (2.3, 3.0), IDENTITY)
    backend.set_present(1, False)
    assert not backend.is_present(1)
    assert backend.is_valid_pose(0, (2.3, 3.0))
    for _ in range(6):
        backend.step({0: [1.0, 0.0], 1: [1.0, 0.0]})
        assert not backend.in_contact(0) and not backend.in_contact(1)
    assert position(backend, 1).tolist() == [2.3, 3.0, 0.0]
    assert position(backend, 0)[0] == pytest.approx(2.3)
    backend.set_present(1, True)
    assert backend.is_present(1)
    assert not backend.is_valid_pose(0, (2.0, 3.0))


# ----------------------------------------------------------------------- valid poses


def test_is_valid_pose_rejects_obstacle_overlap_and_accepts_touching():
    backend = loaded([open_floor()], [RobotSpec()])
    assert backend.is_valid_pose(0, (3.0, 3.0))
    assert backend.is_valid_pose(0, (5.72, 3.0, 0.0), IDENTITY)  # touching the wall
    assert not backend.is_valid_pose(0, (5.73, 3.0))
    assert not backend.is_valid_pose(0, (5.95, 3.0))  # centre in the wall
    assert not backend.is_valid_pose(0, (5.8, 5.8))  # overlaps the corner


def test_is_valid_pose_rejects_other_robots_only_when_present_and_placed():
    backend = loaded([open_floor()], [RobotSpec(), RobotSpec(radius=0.1)])
    assert backend.is_valid_pose(0, (3.2, 3.0))  # robot 1 not placed yet
    backend.land(1, 0, (3.0, 3.0), IDENTITY)
    assert not backend.is_valid_pose(0, (3.2, 3.0))
    assert backend.is_valid_pose(0, (3.28, 3.0))  # touching
    backend.set_present(1, False)
    assert backend.is_valid_pose(0, (3.2, 3.0))


def test_is_valid_pose_rejects_void_and_off_map():
    grid = np.zeros((10, 10), np.uint8)
    grid[:, 7:] = VOID
    backend = loaded([TraversableMap(grid, 0.1)], [RobotSpec(radius=0.05)])
    assert backend.is_valid_pose(0, (0.5, 0.5))
    assert backend.is_valid_pose(0, (0.65, 0.5))  # touching VOID (x >= 0.7) is fine
    assert not backend.is_valid_pose(0, (0.69, 0.5))  # a robot may not stand overhanging it
    assert not backend.is_valid_pose(0, (0.75, 0.5))
    assert not backend.is_valid_pose(0, (-0.01, 0.5))
    assert not backend.is_valid_pose(0, (0.5, 1.2))


def test_is_valid_pose_uses_the_given_floor():
    blocked = np.zeros((10, 10), np.uint8)
    blocked[4:6, 4:6] = OBSTACLE
    floors = [TraversableMap(np.zeros((10, 10), np.uint8), 0.1), TraversableMap(blocked, 0.1)]
    backend = loaded(floors, [RobotSpec(radius=0.05)])
    assert backend.is_valid_pose(0, (0.5, 0.5))
    assert not backend.is_valid_pose(0, (0.5, 0.5), floor=1)
    backend.land(0, 1, (0.2, 0.2), IDENTITY)
    assert not backend.is_valid_pose(0, (0.5, 0.5))


def test_is_valid_pose_validates_its_arguments():
    backend = loaded([open_floor()], [RobotSpec()])
    with pytest.raises(ValueError, match="position must be finite"):
        backend.is_valid_pose(0, (math.nan, 1.0))
    with pytest.raises(ValueError, match="orientation"):
        backend.is_valid_pose(0, (1.0, 1.0), (0.0, 0.0, 0.0, 0.0))


# ----------------------------------------------------------------------- poses and floors


def test_land_sets_z_to_the_floor_height_on_a_two_floor_scene():
    floors = [open_floor(height=0.0), open_floor(height=2.5)]
    backend = loaded(floors, [RobotSpec()])
    backend.land(0, 1, (3.0, 2.0, 99.0), quat(1.0))
    pos, q = backend.get_pose(0)
    assert pos.tolist() == [3.0, 2.0, 2.5]
    assert backend.get_robot_floor(0) == 1
    np.testing.assert_allclose(q, quat(1.0), atol=1e-15)
    backend.land(0, 0, (3.0, 2.0), quat(1.0))
    assert position(backend)[2] == 0.0 and backend.get_robot_floor(0) == 0


def test_set_pose_round_trips_and_get_pose_returns_fresh_arrays():
    backend = loaded([open_floor()], [RobotSpec()])
    backend.set_pose(0, (1.5, 2.5, 0.25), quat(-2.0))
    pos, q = backend.get_pose(0)
    assert pos.tolist() == [1.5, 2.5, 0.25]
    np.testing.assert_allclose(q, quat(-2.0), atol=1e-15)
    pos[0] = 100.0
    q[3] = 0.0
    lin, ang = backend.get_velocity(0)
    lin[0] = 5.0
    assert backend.get_pose(0)[0][0] == 1.5 and backend.get_pose(0)[1][3] != 0.0
    assert backend.get_velocity(0)[0][0] == 0.0


def test_get_pose_quaternion_is_planar_with_non_negative_w():
    backend = loaded([open_floor()], [RobotSpec()])
    backend.land(0, 0, (3.0, 3.0), (0.0, 0.0, -1.0, 0.0))  # yaw pi, written with w = 0
    for _ in range(30):
        backend.step({0: [0.0, 1.0]})
        q = backend.get_pose(0)[1]
        assert q[0] == q[1] == 0.0 and q[3] >= 0.0
        assert np.linalg.norm(q) == pytest.approx(1.0)


def test_set_pose_rejects_bad_position_and_orientation():
    backend = loaded([open_floor()], [RobotSpec()])
    with pytest.raises(ValueError, match=r"position must be finite \(x, y, z\)"):
        backend.set_pose(0, (1.0, 2.0), IDENTITY)
    with pytest.raises(ValueError, match="orientation must be a finite"):
        backend.set_pose(0, (1.0, 2.0, 0.0), (0.0, 0.0, 1.0))
    with pytest.raises(ValueError, match="non-zero quaternion"):
        backend.land(0, 0, (1.0, 2.0), (0.0, 0.0, 0.0, 0.0))


def test_reset_zeroes_velocities_and_contacts_and_unplaces_robots():
    backend = loaded([open_floor()], [RobotSpec(), RobotSpec()])
    backend.land(0, 0, (5.6, 3.0), IDENTITY)
    backend.land(1, 0, (3.0, 3.0), IDENTITY)
    backend.set_present(1, False)
    for _ in range(4):
        backend.step({0: [1.0, 0.0]})
    assert backend.in_contact(0)
    backend.reset()
    assert not backend.in_contact(0)
    assert backend.get_velocity(0)[0].tolist() == [0.0, 0.0, 0.0]
    assert backend.is_present(1)
    assert backend.is_valid_pose(0, (3.0, 3.0))  # robot 1 is unplaced again
    backend.step({0: [1.0, 0.0]})  # unplaced robots do not move
    assert position(backend)[0] == pytest.approx(5.72)


# ----------------------------------------------------------------------- falling


def void_strip_floor(height: float = 1.0) -> TraversableMap:
    grid = np.zeros((20, 40), np.uint8)
    grid[:, 25:] = VOID  # no floor for x >= 2.5
    return TraversableMap(grid, 0.1, height=height)


def test_driving_over_void_drops_z_within_two_steps():
    backend = loaded([void_strip_floor()], [RobotSpec()])
    backend.land(0, 0, (2.47, 1.0), IDENTITY)
    backend.step({0: [1.0, 0.0]})
    backend.step({0: [1.0, 0.0]})
    assert position(backend)[2] < 1.0 - 0.03
    assert not backend.in_contact(0)  # VOID is not an obstacle


def test_a_falling_robot_keeps_falling_and_stops_moving_in_xy():
    backend = loaded([void_strip_floor()], [RobotSpec()])
    backend.land(0, 0, (2.47, 1.0), IDENTITY)
    backend.step({0: [1.0, 0.0]})
    pos = position(backend)
    assert pos[0] > 2.5 and pos[2] <= 1.0 - 0.05
    zs = [pos[2]]
    for _ in range(4):
        backend.step({0: [1.0, 1.0]})
        new = position(backend)
        assert new[:2].tolist() == pos[:2].tolist()
        zs.append(new[2])
        lin, _ = backend.get_velocity(0)
        assert lin[2] == pytest.approx((zs[-1] - zs[-2]) / 0.1)
    assert all(b < a for a, b in zip(zs, zs[1:]))


def test_falling_robot_drops_at_least_5_cm_at_any_rate():
    backend = loaded([void_strip_floor(0.0)], [RobotSpec()], freq=1000.0)
    backend.land(0, 0, (2.5 - 1e-5, 1.0), IDENTITY)
    backend.step({0: [1.0, 0.0]})
    assert position(backend)[2] <= -0.05


def test_land_ends_a_fall():
    backend = loaded([void_strip_floor()], [RobotSpec()])
    backend.land(0, 0, (2.6, 1.0), IDENTITY)  # over the hole: falls on the next step
    backend.step({})
    assert position(backend)[2] < 1.0
    backend.land(0, 0, (1.0, 1.0), IDENTITY)
    backend.step({0: [1.0, 0.0]})
    assert position(backend).tolist() == pytest.approx([1.05, 1.0, 1.0])


def test_robots_drive_over_void_without_hitting_it_but_walls_at_the_edge_still_count():
    backend = loaded([void_strip_floor()], [RobotSpec(radius=0.3)])
    backend.land(0, 0, (2.4, 1.0), quat(math.pi / 2))  # disc overhangs the hole: fine
    backend.step({0: [1.0, 0.0]})
    assert not backend.in_contact(0)
    assert position(backend)[2] == 1.0


# ----------------------------------------------------------------------- determinism


def test_same_state_and_actions_give_the_same_result():
    rng = np.random.default_rng(0)
    actions = rng.uniform(-1.5, 1.5, size=(40, 3, 2))

    def run() -> list:
        backend = loaded([open_floor(30)], [RobotSpec(), RobotSpec(radius=0.3), RobotSpec()])
        for idn, xy in enumerate([(1.0, 1.0), (1.6, 1.0), (1.3, 1.7)]):
            backend.land(idn, 0, xy, quat(idn))
        trace: list[tuple] = []
        for step in actions:
            backend.step({i: step[i] for i in range(3)})
            for i in range(3):
                pos, q = backend.get_pose(i)
                trace.append((pos.tolist(), q.tolist(), backend.in_contact(i)))
        return trace

    assert run() == run()
