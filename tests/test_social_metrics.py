"""Social metrics (``pointnav_core.task.social``) on trajectories worked out by hand, and
their refusals. Each scene's numbers are derived in the comments."""

from __future__ import annotations

import math
import re
import runpy
from pathlib import Path

import numpy as np
import pytest

from pointnav_core import SOCIAL_METRIC_KEYS, social_metrics
from pointnav_core.errors import ArgumentError
from pointnav_core.task.social import (
    excess_rotation,
    min_pedestrian_distance,
    min_time_to_collision,
    motion_statistics,
    path_irregularity,
    pedestrian_collisions,
    personal_space_steps,
    personal_space_time,
    psc,
    stl,
    time_to_collision,
)

approx = pytest.approx


def line(xs, y=0.0) -> np.ndarray:
    return np.array([[x, y] for x in xs], dtype=float)


# --- a straight pass by a standing pedestrian ------------------------------------------
# The robot (radius 0.1 m) drives x = 0 .. 4 m along y = 0 at 1 m/s, 8 steps of 0.5 s:
# x = 0, 0.5, ..., 4. A pedestrian (radius 0.2 m) stands at (2, 0.4).
# Centre distances: sqrt((x - 2)^2 + 0.16): 0.4 at x = 2 (after step 4), sqrt(0.41) = 0.64
# at x = 1.5 and 2.5, more elsewhere. So one step of 8 is inside the 0.5 m personal space:
# PSC = 1 - 1/8 = 0.875, 0.5 s in personal space; min distance 0.4 m, clearance
# 0.4 - 0.1 - 0.2 = 0.1 m: no contact, and the relative path (y offset 0.4 > 0.3) never
# touches: no time-to-collision.
PASS_T = 8
PASS_ROBOT = line(np.arange(PASS_T + 1) * 0.5)
PASS_PEDS = np.tile([[[2.0, 0.4]]], (PASS_T + 1, 1, 1))
PASS = {"dt": 0.5, "robot_radius": 0.1, "pedestrian_radii": 0.2}


def test_straight_pass_by_a_standing_pedestrian() -> None:
    got = social_metrics(
        PASS_ROBOT, np.zeros(PASS_T + 1), PASS_PEDS, **PASS, success=True, geodesic_dist=4.0, max_speed=1.0
    )
    assert tuple(got) == SOCIAL_METRIC_KEYS
    assert all(v is None or type(v) is float for v in got.values())
    want = {
        "psc": 0.875, "personal_space_time": 0.5, "min_ped_distance": 0.4, "min_ped_clearance": 0.1,
        "min_ttc": None, "ped_collisions": 0.0,
        # 4 m at 1 m/s is 4 s, and it took 8 x 0.5 = 4 s.
        "stl": 1.0,
        # Straight ahead, heading 0 all along, towards its end: no turn at all.
        "path_irregularity": 0.0, "excess_rotation": 0.0,
        # 0.5 m per 0.5 s: 1 m/s throughout, no acceleration, no jerk.
        "speed_mean": 1.0, "speed_max": 1.0, "accel_mean": 0.0, "accel_max": 0.0, "jerk_mean": 0.0, "jerk_max": 0.0,
    }
    for key, value in want.items():
        assert got[key] == (None if value is None else approx(value, abs=1e-12)), key


def test_psc_iGibson_form_divides_by_the_step_limit() -> None:
    # iGibson: info["psc"] = 1 - violation_steps / max_step (500): 1 - 1/500.
    assert psc(PASS_ROBOT, PASS_PEDS, max_steps=500) == approx(0.998)
    assert personal_space_steps(PASS_ROBOT, PASS_PEDS) == 1
    # A 0.7 m personal space also takes in x = 1.5 and 2.5 (0.64 m): 3 steps, 1.5 s.
    assert personal_space_steps(PASS_ROBOT, PASS_PEDS, 0.7) == 3
    assert personal_space_time(PASS_ROBOT, PASS_PEDS, 0.5, 0.7) == approx(1.5)
    assert psc(PASS_ROBOT, PASS_PEDS, 0.7) == approx(1 - 3 / 8)


def test_personal_space_is_strict_and_judged_after_each_step() -> None:
    # Exactly 0.5 m is not inside (iGibson's `<`); the start is not judged (iGibson checks
    # after each step), so a robot that starts 0.1 m away and leaves complies fully.
    robot = line([0.0, 1.0, 2.0])
    at_half = np.array([[[0.0, 0.5]], [[1.0, 0.5]], [[2.0, 0.5]]])
    assert psc(robot, at_half) == 1.0
    start_only = np.array([[[0.1, 0.0]], [[5.0, 5.0]], [[5.0, 5.0]]])
    assert psc(robot, start_only) == 1.0 and personal_space_steps(robot, start_only) == 0
    assert min_pedestrian_distance(robot, start_only) == approx(0.1)  # the start counts here


def test_stl_is_spl_on_times() -> None:
    # t_opt = 4 m / 0.5 m/s = 8 s; 10 s taken: 0.8. Faster than t_opt: 1. Failure: 0.
    assert stl(True, 4.0, 10.0, 0.5) == approx(0.8)
    assert stl(True, 4.0, 6.0, 0.5) == 1.0
    assert stl(False, 4.0, 10.0, 0.5) == 0.0
    assert stl(True, math.inf, 10.0, 0.5) == 0.0  # unreachable goal, as SPL
    assert stl(True, 0.0, 0.0, 1.0) == 1.0 and stl(True, 0.0, 1.0, 1.0) == 0.0
    # In the pass above with a 2 m/s top speed: t_opt = 2 s of 4 s taken.
    got = social_metrics(
        PASS_ROBOT, np.zeros(PASS_T + 1), PASS_PEDS, **PASS, success=True, geodesic_dist=4.0, max_speed=2.0
    )
    assert got["stl"] == approx(0.5)


# --- a head-on approach ----------------------------------------------------------------
# Robot (r 0.2) from (0, 0) at +1 m/s, pedestrian (r 0.3) from (5, 0) at -0.5 m/s, dt 0.5,
# T = 4. Centre gaps 5, 4.25, 3.5, 2.75 at t = 0..3, closing at 1.5 m/s; contact at a
# gap of 0.5, so the time-to-collision is (gap - 0.5) / 1.5 = 3, 2.5, 2, 1.5 s: the
# minimum is 1.5 s, at t = 3 (t = 4 has no next step, hence no velocity). The last gap
# is 2: min distance 2 m, clearance 1.5 m.
def test_head_on_approach_known_ttc() -> None:
    robot = line([0.0, 0.5, 1.0, 1.5, 2.0])
    peds = line([5.0, 4.75, 4.5, 4.25, 4.0])[:, None, :]
    radii = {"robot_radius": 0.2, "pedestrian_radii": 0.3}
    assert min_time_to_collision(robot, peds, 0.5, **radii) == approx(1.5, abs=1e-12)
    assert min_pedestrian_distance(robot, peds) == approx(2.0)
    assert min_pedestrian_distance(robot, peds, **radii) == approx(1.5)
    # The pedestrian turned away (+0.5 m/s): the robot still catches up, at 0.5 m/s. Gaps
    # 5, 4.75, 4.5, 4.25: the last gives (4.25 - 0.5) / 0.5 = 7.5 s.
    away = line([5.0, 5.25, 5.5, 5.75, 6.0])[:, None, :]
    assert min_time_to_collision(robot, away, 0.5, **radii) == approx(7.5)
    # Walking away at 1.5 m/s, faster than the robot: the gap opens, no time-to-collision.
    faster = line([5.0, 5.75, 6.5, 7.25, 8.0])[:, None, :]
    assert min_time_to_collision(robot, faster, 0.5, **radii) is None


@pytest.mark.parametrize(
    ("dp", "dv", "radius", "want"),
    [
        ((4.0, 0.0), (-2.0, 0.0), 1.0, 1.5),  # 3 m gap closed at 2 m/s
        ((3.0, 4.0), (-1.2, -1.6), 1.0, 2.0),  # 5 m away, straight at it at 2 m/s: (5 - 1) / 2
        ((2.0, 1.0), (-1.0, 0.0), 1.0, 2.0),  # grazing: tangent at tau = 2 (x = 0, y = 1)
        ((0.5, 0.0), (1.0, 0.0), 1.0, 0.0),  # already overlapping, even moving apart
        ((1.0, 0.0), (0.0, 0.0), 1.0, 0.0),  # touching exactly
        ((2.0, 0.0), (1.0, 0.0), 1.0, math.inf),  # moving apart
        ((2.0, 0.0), (0.0, 0.0), 1.0, math.inf),  # standing still relative to each other
        ((2.0, 1.5), (-1.0, 0.0), 1.0, math.inf),  # passing 1.5 m wide of a 1 m contact
    ],
)
def test_time_to_collision_of_disc_pairs(dp, dv, radius, want) -> None:
    assert time_to_collision([dp], [dv], radius)[0] == approx(want, abs=1e-12)


# --- path irregularity on a zig-zag ----------------------------------------------------
# (0,0) -> (1,1) -> (2,0) -> (3,1) -> (4,0): 4 segments of sqrt(2), L = 4 sqrt(2) m.
# Headings along each next segment: pi/4, -pi/4, pi/4, -pi/4, -pi/4: three turns of pi/2,
# 3 pi / 2 in all. The direct path to the end (4, 0) starts by turning from pi/4 to 0:
# pi/4. Excess 3 pi/2 - pi/4 = 5 pi/4 rad; irregularity 5 pi / (16 sqrt(2)) = 0.694 rad/m.
ZIG = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 0.0], [3.0, 1.0], [4.0, 0.0]])
ZIG_YAW = np.array([1, -1, 1, -1, -1]) * math.pi / 4


def test_zig_zag_irregularity() -> None:
    assert excess_rotation(ZIG, ZIG_YAW) == approx(5 * math.pi / 4)
    assert path_irregularity(ZIG, ZIG_YAW) == approx(5 * math.pi / (16 * math.sqrt(2)))
    # Towards a goal at (4, 4), bearing pi/4, the direct path needs no turn: 3 pi / 2.
    assert excess_rotation(ZIG, ZIG_YAW, goal=(4.0, 4.0)) == approx(3 * math.pi / 2)


def test_turns_wrap_the_short_way_and_excess_is_clipped() -> None:
    # Heading 3.0 -> -3.0 rad is a turn of 2 pi - 6 (across +-pi), not 6 rad. Driving to
    # (-1, 0), bearing pi, the direct path turns pi - 3 from 3.0: excess pi - 3 over 1 m.
    robot = np.array([[0.0, 0.0], [-1.0, 0.0]])
    assert excess_rotation(robot, [3.0, -3.0]) == approx(math.pi - 3.0)
    assert path_irregularity(robot, [3.0, -3.0]) == approx(math.pi - 3.0)
    # A holonomic robot sliding sideways (heading 0, moving +y) turns less than the direct
    # path would (pi/2): the excess is 0, not negative.
    assert excess_rotation(line([0.0, 0.0, 0.0]) + [[0, 0], [0, 1], [0, 2]], [0.0, 0.0, 0.0]) == 0.0


def test_turning_on_the_spot() -> None:
    # No length: irregularity is undefined (None); the half turn is all excess (pi).
    robot = np.zeros((3, 2))
    yaw = [0.0, math.pi / 2, math.pi]
    assert path_irregularity(robot, yaw) is None
    assert excess_rotation(robot, yaw) == approx(math.pi)


# --- speed, acceleration, jerk ---------------------------------------------------------
def test_constant_acceleration_has_no_jerk() -> None:
    # x = a t^2 / 2 with a = 2 m/s^2, dt = 0.5: x = 0, .25, 1, 2.25, 4, 6.25, 9 (T = 6),
    # along the direction (0.6, 0.8). Speeds (dx / 0.5): 0.5, 1.5, .., 5.5 (mean 3, max
    # 5.5); accelerations all 1 / 0.5 = 2; jerk 0.
    x = 0.5 * 2.0 * (np.arange(7) * 0.5) ** 2
    got = motion_statistics(x[:, None] * [0.6, 0.8], 0.5)
    want = {"speed_mean": 3.0, "speed_max": 5.5, "accel_mean": 2.0, "accel_max": 2.0, "jerk_mean": 0.0, "jerk_max": 0.0}
    assert got == {k: approx(v, abs=1e-12) for k, v in want.items()}


def test_constant_jerk() -> None:
    # x = j t^3 / 6 with j = 6, dt = 1: x = 0, 1, 8, 27, 64. Speeds 1, 7, 19, 37 (mean 16);
    # accelerations 6, 12, 18 (mean 12); jerks 6, 6.
    got = motion_statistics(line([0.0, 1.0, 8.0, 27.0, 64.0]), 1.0)
    want = {"speed_mean": 16.0, "speed_max": 37.0, "accel_mean": 12.0, "accel_max": 18.0, "jerk_mean": 6.0, "jerk_max": 6.0}
    assert got == {k: approx(v) for k, v in want.items()}


def test_too_short_for_a_difference_is_none() -> None:
    one = motion_statistics(line([0.0, 1.0]), 0.5)  # T = 1: a speed, nothing more
    assert one == {"speed_mean": 2.0, "speed_max": 2.0, "accel_mean": None, "accel_max": None, "jerk_mean": None, "jerk_max": None}
    two = motion_statistics(line([0.0, 1.0, 3.0]), 1.0)  # T = 2: speeds 1, 2; accel 1
    assert two["accel_mean"] == 1.0 and two["jerk_mean"] is None


# --- contacts and crowds ---------------------------------------------------------------
def test_contacts_count_each_onset_per_pedestrian() -> None:
    # Robot r 0.2 along x at 1 m per step, x = 0..6; pedestrian A (r 0.3) stands at (2, 0)
    # and B (r 0.3) at (5, 0.4). Contact with A while |x - 2| <= 0.5: x = 2 only; with B
    # while sqrt((x - 5)^2 + 0.16) <= 0.5: |x - 5| <= 0.3: x = 5 only. Two contacts.
    robot = line(range(7))
    peds = np.tile([[[2.0, 0.0], [5.0, 0.4]]], (7, 1, 1))
    radii = {"robot_radius": 0.2, "pedestrian_radii": 0.3}
    assert pedestrian_collisions(robot, peds, **radii) == 2
    # Held contact counts once; leaving and coming back counts again: x = 2, 2, 2, 0, 2.
    back = line([0.0, 2.0, 2.0, 2.0, 0.0, 2.0])
    assert pedestrian_collisions(back, np.tile([[[2.0, 0.0]]], (6, 1, 1)), **radii) == 2
    # A start in contact counts (per pedestrian: two at once are two).
    both = np.tile([[[0.5, 0.0], [-0.5, 0.0]]], (2, 1, 1))
    assert pedestrian_collisions(line([0.0, 0.0]), both, **radii) == 2
    # Per-pedestrian radii: B of radius 0.1 is never touched (0.4 > 0.3 at x = 5).
    assert pedestrian_collisions(robot, peds, robot_radius=0.2, pedestrian_radii=[0.3, 0.1]) == 1
    assert min_pedestrian_distance(robot, peds, robot_radius=0.2, pedestrian_radii=[0.3, 0.1]) == approx(-0.5)
    # Touching at a sample makes the time-to-collision 0.
    assert min_time_to_collision(robot, peds, 1.0, **radii) == 0.0


def test_no_pedestrians() -> None:
    got = social_metrics(
        PASS_ROBOT, np.zeros(PASS_T + 1), np.zeros((PASS_T + 1, 0, 2)), dt=0.5, robot_radius=0.1,
        pedestrian_radii=[], success=False, geodesic_dist=4.0, max_speed=1.0,
    )
    assert got["psc"] == 1.0 and got["personal_space_time"] == 0.0 and got["ped_collisions"] == 0.0
    assert got["min_ped_distance"] is got["min_ped_clearance"] is got["min_ttc"] is None
    assert got["stl"] == 0.0


# --- refusals --------------------------------------------------------------------------
GOOD = {
    "robot_positions": PASS_ROBOT, "headings": np.zeros(PASS_T + 1), "pedestrian_positions": PASS_PEDS, "dt": 0.5,
    "robot_radius": 0.1, "pedestrian_radii": 0.2, "success": True, "geodesic_dist": 4.0, "max_speed": 1.0,
}


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("robot_positions", np.zeros(9)),
        ("robot_positions", np.zeros((9, 3))),
        ("robot_positions", np.zeros((1, 2))),  # no step
        ("robot_positions", np.full((9, 2), np.nan)),
        ("robot_positions", np.zeros((9, 2), bool)),
        ("robot_positions", [["0", "1"]] * 9),
        ("robot_positions", [[0.0, 1.0], [2.0]] + [[0.0, 0.0]] * 7),  # ragged
        ("headings", np.zeros(8)),
        ("headings", [math.inf] * 9),
        ("pedestrian_positions", np.zeros((8, 1, 2))),  # one sample short
        ("pedestrian_positions", np.zeros((9, 2))),
        ("dt", 0.0),
        ("dt", 1e-7),  # under a microsecond: jerk's dt**3 would overflow
        ("robot_positions", np.full((9, 2), 2e9)),  # beyond 1e9 m
        ("robot_radius", 1e10),
        ("dt", -0.1),
        ("dt", True),
        ("dt", "0.5"),
        ("dt", math.nan),
        ("robot_radius", -0.1),
        ("robot_radius", True),
        ("pedestrian_radii", [0.2, 0.2]),  # one pedestrian
        ("pedestrian_radii", -0.2),
        ("pedestrian_radii", [True]),
        ("pedestrian_radii", [[0.2], [0.2, 0.1]]),  # ragged
        ("success", 1),
        ("success", "yes"),
        ("geodesic_dist", -1.0),
        ("geodesic_dist", math.nan),
        ("max_speed", 0.0),
        ("personal_space", -0.5),
        ("personal_space", "0.5"),
        ("goal", (1.0, 2.0, 3.0)),
    ],
)
def test_bad_input_is_refused_by_name(name, value) -> None:
    with pytest.raises(ArgumentError, match=f"^{name} "):
        social_metrics(**{**GOOD, name: value})


def test_bad_max_steps_and_pairs() -> None:
    with pytest.raises(ArgumentError, match="^max_steps "):
        psc(PASS_ROBOT, PASS_PEDS, max_steps=7)  # fewer than the episode's 8 steps
    with pytest.raises(ArgumentError, match="^max_steps "):
        psc(PASS_ROBOT, PASS_PEDS, max_steps=500.0)
    with pytest.raises(ArgumentError, match="^relative_velocities "):
        time_to_collision([[1.0, 0.0]], [[1.0, 0.0], [0.0, 0.0]], 0.5)
    with pytest.raises(ValueError, match="^duration "):
        stl(True, 1.0, -1.0, 1.0)


def test_the_docs_example_runs(tmp_path, capsys) -> None:
    # docs/social_metrics.md's example runs as written (its assert checks two values).
    doc = (Path(__file__).resolve().parents[1] / "docs" / "social_metrics.md").read_text(encoding="utf-8")
    (block,) = re.findall(r"^```python\n(.*?)^```", doc, flags=re.DOTALL | re.MULTILINE)
    script = tmp_path / "social_metrics_example.py"
    script.write_text(block, encoding="utf-8")
    runpy.run_path(str(script))
    assert "'psc': 0.875" in capsys.readouterr().out


def test_extreme_accepted_input_stays_finite() -> None:
    # The bounds (coordinates within 1e9 m, dt >= 1 microsecond) keep every value finite:
    # a robot jumping across 2e9 m each microsecond, pedestrians at the far corners.
    robot = np.array([[-1e9, -1e9], [1e9, 1e9], [-1e9, 1e9], [1e9, -1e9]])
    peds = np.stack([-robot, robot], axis=1)
    got = social_metrics(
        robot, [1e9, -1e9, 1e9, -1e9], peds, dt=1e-6, robot_radius=1e9, pedestrian_radii=[1e9, 0.0],
        success=True, geodesic_dist=1e9, max_speed=1e-9, personal_space=1e9, goal=(1e9, 1e9),
    )
    assert all(v is None or math.isfinite(v) for v in got.values()), got
