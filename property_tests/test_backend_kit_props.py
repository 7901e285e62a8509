"""Properties of the backend kit against references written here from first principles.

- ``drive_arc``: the motion of a constant body-frame command, against the unicycle's
  world velocity ``R(yaw + w t) (vx, vy)`` integrated numerically (composite Simpson) and
  against its antiderivative worked out by hand.
- ``planar_quat_floats``: against the quaternion of a rotation about +z,
  ``(0, 0, sin(yaw / 2), cos(yaw / 2))``, up to the sign that makes ``w >= 0``.
- ``robots_overlap``: against a loop over the other discs, one distance at a time.
- ``FloorGrid``: its point lookups against the map's own ``cell_class_at``.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st

from pointnav_core.backends.kit import (
    FloorGrid,
    body_command,
    drive_arc,
    parse_orientation,
    planar_quat,
    planar_quat_floats,
    robots_overlap,
)
from pointnav_core.floor.maps import VOID
from pointnav_core.testing.strategies import (
    robot_actions,
    robot_specs,
    traversable_maps,
)

headings = st.floats(-20.0, 20.0)
speeds = st.floats(-3.0, 3.0)
yaw_rates = st.floats(-12.0, 12.0)
durations = st.floats(1e-3, 1.0)


def simpson_arc(yaw: float, vx: float, vy: float, w: float, h: float, n: int = 2000):
    """The unicycle's displacement: its world velocity integrated over [0, h] (Simpson)."""
    t = np.linspace(0.0, h, n + 1)
    heading = yaw + w * t
    ux = vx * np.cos(heading) - vy * np.sin(heading)
    uy = vx * np.sin(heading) + vy * np.cos(heading)
    weights = np.ones(n + 1)
    weights[1:-1:2] = 4.0
    weights[2:-1:2] = 2.0
    return float(ux @ weights) * h / (3 * n), float(uy @ weights) * h / (3 * n)


def closed_form_arc(yaw: float, vx: float, vy: float, w: float, h: float):
    """By hand: the integrals of cos and sin of yaw + w t are (sin, -cos) over w."""
    s0, c0 = math.sin(yaw), math.cos(yaw)
    s1, c1 = math.sin(yaw + w * h), math.cos(yaw + w * h)
    dx = (vx * (s1 - s0) - vy * (c0 - c1)) / w
    dy = (vx * (c0 - c1) + vy * (s1 - s0)) / w
    return dx, dy


@given(yaw=headings, vx=speeds, vy=speeds, w=yaw_rates, h=durations)
def test_drive_arc_is_the_integral_of_the_unicycle_velocity(yaw, vx, vy, w, h):
    dx, dy = drive_arc(yaw, vx, vy, w, h)
    rx, ry = simpson_arc(yaw, vx, vy, w, h)
    scale = 1.0 + math.hypot(vx, vy) * h
    assert math.isclose(dx, rx, abs_tol=1e-10 * scale)
    assert math.isclose(dy, ry, abs_tol=1e-10 * scale)


@given(yaw=headings, vx=speeds, vy=speeds, w=yaw_rates, h=durations)
def test_drive_arc_equals_the_closed_form_worked_out_by_hand(yaw, vx, vy, w, h):
    assume(abs(w * h) > 1e-3)  # the hand form cancels badly for a nearly straight line
    dx, dy = drive_arc(yaw, vx, vy, w, h)
    rx, ry = closed_form_arc(yaw, vx, vy, w, h)
    scale = 1.0 + math.hypot(vx, vy) * h
    assert math.isclose(dx, rx, abs_tol=1e-11 * scale / abs(w * h))
    assert math.isclose(dy, ry, abs_tol=1e-11 * scale / abs(w * h))


@given(yaw=headings, vx=speeds, vy=speeds, h=durations)
def test_drive_arc_without_turning_is_a_straight_line(yaw, vx, vy, h):
    dx, dy = drive_arc(yaw, vx, vy, 0.0, h)
    assert math.isclose(dx, h * (vx * math.cos(yaw) - vy * math.sin(yaw)), abs_tol=1e-15)
    assert math.isclose(dy, h * (vx * math.sin(yaw) + vy * math.cos(yaw)), abs_tol=1e-15)


@given(yaw=headings, vx=speeds, vy=speeds, w=yaw_rates, h=durations)
def test_the_chord_velocity_covers_the_arc_in_its_duration(yaw, vx, vy, w, h):
    ux, uy = drive_arc(yaw, vx, vy, w, h, velocity=True)
    dx, dy = drive_arc(yaw, vx, vy, w, h)
    assert math.isclose(ux * h, dx, rel_tol=1e-14, abs_tol=1e-15)
    assert math.isclose(uy * h, dy, rel_tol=1e-14, abs_tol=1e-15)
    # Never faster than the command: a chord is no longer than its arc.
    assert math.hypot(ux, uy) <= math.hypot(vx, vy) * (1.0 + 1e-12)


@given(data=st.data(), spec=robot_specs())
def test_body_command_is_the_scaled_action_in_the_body_frame(data, spec):
    action = data.draw(robot_actions(spec, overshoot=0.5))
    scaled = spec.scale_action(action).tolist()
    expected = scaled if spec.drive == "holonomic" else [scaled[0], 0.0, scaled[1]]
    assert list(body_command(spec, action)) == expected


@given(yaw=st.floats(-100.0, 100.0))
def test_planar_quat_floats_is_the_rotation_about_z_with_w_not_negative(yaw):
    q = planar_quat_floats(yaw)
    assert all(type(v) is float for v in q)
    assert q == tuple(planar_quat(yaw).tolist())
    hand = (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))
    sign = 1.0 if hand[3] >= 0.0 else -1.0  # q and -q are the same rotation
    tol = 1e-15 * (1.0 + abs(yaw))
    assert q[:2] == (0.0, 0.0) and q[3] >= 0.0
    assert math.isclose(q[2], sign * hand[2], abs_tol=tol)
    assert math.isclose(q[3], sign * hand[3], abs_tol=tol)
    assert math.isclose(math.hypot(*q), 1.0, abs_tol=1e-15)
    # Read back, it is the same heading.
    assert abs(math.remainder(parse_orientation(q) - yaw, 2.0 * math.pi)) < tol + 1e-15


coordinates = st.floats(-5.0, 5.0)
radii = st.floats(0.0, 2.0)
discs = st.tuples(coordinates, coordinates, radii)


def brute_force_overlap(x, y, radius, others, tolerance):
    """One other disc at a time: closer than the sum of radii less the tolerance."""
    for ox, oy, other_radius in others:
        reach = radius + other_radius - tolerance
        if reach > 0.0 and math.hypot(x - ox, y - oy) < reach:
            return True
    return False


@given(
    disc=discs,
    others=st.lists(discs, max_size=8),
    tolerance=st.sampled_from((0.0, 1e-9, 1e-6, 0.05)),
)
def test_robots_overlap_agrees_with_a_loop_over_the_other_discs(disc, others, tolerance):
    x, y, radius = disc
    for ox, oy, other_radius in others:  # away from the boundary, where rounding decides
        reach = radius + other_radius - tolerance
        assume(abs(math.hypot(x - ox, y - oy) - reach) > 1e-9)
    expected = brute_force_overlap(x, y, radius, others, tolerance)
    assert robots_overlap(x, y, radius, others, tolerance) is expected
    assert robots_overlap(x, y, radius, np.array(others).reshape(-1, 3), tolerance) is expected


@given(
    x=st.integers(-40, 40),
    y=st.integers(-40, 40),
    radius=st.integers(0, 16),
    m=st.integers(0, 8),
    k=st.integers(-1, 1),
    direction=st.sampled_from([(1, 0, 1), (0, -1, 1), (3, 4, 5), (-4, 3, 5), (5, -12, 13)]),
)
def test_robots_overlap_decides_touching_discs_exactly(x, y, radius, m, k, direction):
    # On a grid of 1/8 m, along Pythagorean directions, the arithmetic is exact: discs
    # whose radii add up to their distance touch (no overlap); 1/8 m more is an overlap.
    a, b, c = direction
    distance = c * m
    other_radius = distance - radius + k
    assume(other_radius >= 0)
    other = ((x + a * m) / 8.0, (y + b * m) / 8.0, other_radius / 8.0)
    got = robots_overlap(x / 8.0, y / 8.0, radius / 8.0, [other], 0.0)
    assert got is (k > 0)
    assert got is brute_force_overlap(x / 8.0, y / 8.0, radius / 8.0, [other], 0.0)


@given(tmap=traversable_maps(), fx=st.floats(-0.2, 1.2), fy=st.floats(-0.2, 1.2))
def test_floor_grid_lookups_agree_with_the_map(tmap, fx, fy):
    grid = FloorGrid(tmap, tmap.height)
    xmin, xmax, ymin, ymax = tmap.extent
    x, y = xmin + fx * (xmax - xmin), ymin + fy * (ymax - ymin)
    g = tmap.world_to_grid([x, y])
    assume(np.all(np.abs(g - np.round(g)) > 1e-6))  # off cell borders, where rounding decides
    code = int(tmap.cell_class_at([x, y]))
    assert grid.code(x, y) == code
    assert grid.is_void(x, y) is (code == VOID)
    index = grid.cell_index(x, y)
    assert (index < 0) is (not bool(tmap.in_bounds(tmap.world_to_cell([x, y]))))
    if index >= 0:
        assert grid.codes[index] == code
