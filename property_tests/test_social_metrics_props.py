"""Social metrics against brute-force references written here, and their invariances.

The references loop over samples and pedestrians with ``math``; the time-to-collision one
samples the relative motion finely up to the last time a first contact is possible (by
the triangle inequality, ``(|dp| + R) / |dv|``) and bisects the first sampled contact.
Exact comparisons use positions on a 1/8 m grid and steps of a power of two, where every
difference and dot product is exact, so even boundary cases (a centre exactly at the
personal-space radius, discs exactly touching) must agree.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from pointnav_core.task.social import (
    SOCIAL_METRIC_KEYS,
    min_time_to_collision,
    motion_statistics,
    pedestrian_collisions,
    psc,
    social_metrics,
    time_to_collision,
)

approx = pytest.approx


@st.composite
def episodes(draw, grid: bool = True):
    """(robot (T+1, 2), headings (T+1,), peds (T+1, P, 2), dt, robot radius, ped radii)."""
    steps = draw(st.integers(1, 6))
    count = draw(st.integers(0, 3))
    # Grid: multiples of 1/8 m in [-4, 4]; otherwise multiples of 1 mm in [-5, 5].
    scale, bound = (8.0, 32) if grid else (1000.0, 5000)
    cells = st.integers(-bound, bound)
    robot = draw(hnp.arrays(np.int64, (steps + 1, 2), elements=cells)) / scale
    peds = draw(hnp.arrays(np.int64, (steps + 1, count, 2), elements=cells)) / scale
    yaw = draw(hnp.arrays(np.float64, steps + 1, elements=st.floats(-math.pi, math.pi)))
    dt = draw(st.sampled_from([0.25, 0.5, 1.0]))
    r_robot = draw(st.integers(0, 8)) / 16
    r_peds = draw(hnp.arrays(np.int64, count, elements=st.integers(0, 8))) / 16
    return robot, yaw, peds, dt, r_robot, r_peds


def run(ep, personal_space: float = 0.5) -> dict:
    robot, yaw, peds, dt, r_robot, r_peds = ep
    return social_metrics(
        robot, yaw, peds, dt=dt, robot_radius=r_robot, pedestrian_radii=r_peds, success=True,
        geodesic_dist=2.0, max_speed=1.0, personal_space=personal_space,
    )


# --- references ------------------------------------------------------------------------
def ref_ttc(dp, dv, radius) -> tuple[float, float]:
    """(first contact time by sampling and bisection, the sampled minimum distance)."""
    gap = math.hypot(*dp)
    if gap <= radius:
        return 0.0, gap

    def dist(tau: float) -> float:
        return math.hypot(dp[0] + dv[0] * tau, dp[1] + dv[1] * tau)

    speed = math.hypot(*dv)
    horizon = (gap + radius) / speed if speed > 0.0 else math.inf
    if math.isinf(horizon):  # still, or so slow that a contact would come after 1e308 s
        return math.inf, gap
    taus = np.linspace(0.0, horizon, 4001)
    d = np.hypot(dp[0] + dv[0] * taus, dp[1] + dv[1] * taus)
    hit = np.flatnonzero(d <= radius)
    if hit.size == 0:
        return math.inf, float(d.min())
    lo, hi = float(taus[hit[0] - 1]), float(taus[hit[0]])
    for _ in range(64):  # the bracket is 1/4000 of the horizon: 64 halvings pass an ulp
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if dist(mid) <= radius else (mid, hi)
    return hi, float(d.min())


def agree_ttc(got: float, dp, dv, radius) -> None:
    want, closest = ref_ttc(dp, dv, radius)
    if math.isinf(want) == math.isinf(got):
        assert got == approx(want, rel=1e-6, abs=1e-9)
    else:
        # Only a graze can split them: contact at a single instant (or a sliver shorter
        # than a sample), the sampled distance never below the radius by more than a hair.
        assert closest >= radius - 1e-6 * max(1.0, radius)
        if not math.isinf(got):
            assert math.hypot(dp[0] + dv[0] * got, dp[1] + dv[1] * got) == approx(radius, abs=1e-6)


def loop_reference(ep, personal_space: float = 0.5) -> dict:
    robot, _yaw, peds, dt, r_robot, r_peds = ep
    steps, count = len(robot) - 1, peds.shape[1]
    dist = [[math.hypot(*(peds[t, p] - robot[t])) for p in range(count)] for t in range(steps + 1)]
    inside = sum(1 for t in range(1, steps + 1) if any(d < personal_space for d in dist[t]))
    touching = [[dist[t][p] <= r_robot + r_peds[p] for p in range(count)] for t in range(steps + 1)]
    contacts = sum(touching[0]) + sum(
        1 for t in range(1, steps + 1) for p in range(count) if touching[t][p] and not touching[t - 1][p]
    )
    clear = [dist[t][p] - r_robot - r_peds[p] for t in range(steps + 1) for p in range(count)]
    return {
        "psc": 1.0 - inside / steps,
        "personal_space_time": inside * dt,
        "min_ped_distance": min((d for row in dist for d in row), default=None),
        "min_ped_clearance": min(clear, default=None),
        "ped_collisions": float(contacts),
    }


# --- properties ------------------------------------------------------------------------
@given(ep=episodes(), personal_space=st.sampled_from([0.0, 0.25, 0.5, 1.0]))
def test_distances_and_contacts_equal_loops(ep, personal_space) -> None:
    got, want = run(ep, personal_space), loop_reference(ep, personal_space)
    for key, value in want.items():
        assert got[key] == (None if value is None else approx(value, abs=1e-12)), key
    assert 0.0 <= got["psc"] <= 1.0 and 0.0 <= got["stl"] <= 1.0
    assert tuple(got) == SOCIAL_METRIC_KEYS and all(v is None or type(v) is float for v in got.values())


@given(ep=episodes())
def test_contact_iff_no_clearance_and_zero_ttc_iff_contact_before_the_end(ep) -> None:
    robot, _, peds, _, r_robot, r_peds = ep
    got = run(ep)
    if got["min_ped_clearance"] is None:
        assert got["ped_collisions"] == 0.0 and got["min_ttc"] is None
        return
    assert (got["ped_collisions"] > 0) == (got["min_ped_clearance"] <= 0.0)
    # The time-to-collision is read at samples 0..T-1 (the last has no next step).
    early = any(
        math.hypot(*(peds[t, p] - robot[t])) <= r_robot + r_peds[p]
        for t in range(len(robot) - 1) for p in range(peds.shape[1])
    )
    assert (got["min_ttc"] == 0.0) == early


@given(
    dp=st.tuples(st.floats(-5, 5), st.floats(-5, 5)),
    dv=st.tuples(st.floats(-3, 3), st.floats(-3, 3)),
    radius=st.floats(0.0, 1.0),
)
def test_pair_ttc_equals_sampling(dp, dv, radius) -> None:
    agree_ttc(float(time_to_collision([dp], [dv], radius)[0]), dp, dv, radius)


@given(ep=episodes(grid=False))
def test_min_ttc_equals_sampling_over_the_episode(ep) -> None:
    robot, _, peds, dt, r_robot, r_peds = ep
    got = min_time_to_collision(robot, peds, dt, robot_radius=r_robot, pedestrian_radii=r_peds)
    best, solid, graze = math.inf, math.inf, False
    for t in range(len(robot) - 1):
        v_robot = (robot[t + 1] - robot[t]) / dt
        for p in range(peds.shape[1]):
            radius = r_robot + r_peds[p]
            tau, closest = ref_ttc(peds[t, p] - robot[t], (peds[t + 1, p] - peds[t, p]) / dt - v_robot, radius)
            best = min(best, tau)
            # A graze (the sampled distance never more than a hair inside the radius: a
            # point contact, or one shorter than a sample) may be found by one side only.
            if closest >= radius - 1e-6 * max(1.0, radius):
                graze = True
            else:
                solid = min(solid, tau)
    got = math.inf if got is None else got
    assert got <= solid * (1 + 1e-6) + 1e-9
    assert got >= best * (1 - 1e-6) - 1e-9 or graze


@given(ep=episodes(grid=False))
def test_motion_and_turning_equal_loops(ep) -> None:
    robot, yaw, _, dt, _, _ = ep
    got = run(ep)
    v = [((robot[t + 1] - robot[t]) / dt) for t in range(len(robot) - 1)]
    a = [(v[t + 1] - v[t]) / dt for t in range(len(v) - 1)]
    j = [(a[t + 1] - a[t]) / dt for t in range(len(a) - 1)]
    for name, seq in (("speed", v), ("accel", a), ("jerk", j)):
        norms = [math.hypot(*x) for x in seq]
        assert got[f"{name}_mean"] == (approx(sum(norms) / len(norms), rel=1e-9, abs=1e-9) if norms else None)
        assert got[f"{name}_max"] == (approx(max(norms), rel=1e-9, abs=1e-9) if norms else None)
    turns = sum(abs(math.atan2(math.sin(b - c), math.cos(b - c))) for c, b in itertools.pairwise(yaw))
    off = robot[-1] - robot[0]
    bearing = math.atan2(off[1], off[0]) - yaw[0]
    needed = abs(math.atan2(math.sin(bearing), math.cos(bearing))) if off.any() else 0.0
    length = sum(math.hypot(*(robot[t + 1] - robot[t])) for t in range(len(robot) - 1))
    assert got["excess_rotation"] == approx(max(0.0, turns - needed), abs=1e-9)
    assert got["path_irregularity"] == (approx(max(0.0, turns - needed) / length, abs=1e-9) if length else None)


@given(ep=episodes(), quarter=st.integers(0, 3), shift=st.tuples(st.integers(-16, 16), st.integers(-16, 16)))
def test_quarter_turns_and_grid_shifts_change_nothing(ep, quarter, shift) -> None:
    # Quarter turns and shifts on the grid are exact: every metric, boundaries included,
    # is unchanged (headings turn by a rounded k pi / 2: irregularity to 1e-9).
    robot, yaw, peds, *rest = ep
    turn = np.linalg.matrix_power(np.array([[0.0, -1.0], [1.0, 0.0]]), quarter)
    offset = np.array(shift) / 8.0
    moved = (robot @ turn.T + offset, yaw + quarter * math.pi / 2, peds @ turn.T + offset, *rest)
    got, want = run(moved), run(ep)
    for key in SOCIAL_METRIC_KEYS:
        assert got[key] == (None if want[key] is None else approx(want[key], abs=1e-9)), key


@given(ep=episodes(grid=False), angle=st.floats(-math.pi, math.pi), shift=st.tuples(st.floats(-3, 3), st.floats(-3, 3)))
def test_rigid_motions_keep_the_continuous_metrics(ep, angle, shift) -> None:
    # Any rotation and shift: the metrics that are continuous in the positions are kept to
    # rounding (PSC, contacts and TTC jump at their boundaries, so exact cases are above).
    robot, yaw, peds, *rest = ep
    c, s = math.cos(angle), math.sin(angle)
    turn = np.array([[c, -s], [s, c]])
    moved = (robot @ turn.T + shift, yaw + angle, peds @ turn.T + shift, *rest)
    got, want = run(moved), run(ep)
    keys = ["min_ped_distance", "min_ped_clearance", "excess_rotation", "path_irregularity", "stl"]
    keys += [f"{m}_{s}" for m in ("speed", "accel", "jerk") for s in ("mean", "max")]
    for key in keys:
        assert got[key] == (None if want[key] is None else approx(want[key], rel=1e-9, abs=1e-9)), key


@given(ep=episodes(), max_steps=st.integers(0, 20))
def test_psc_in_unit_interval_and_iGibson_form(ep, max_steps) -> None:
    robot, _, peds, *_ = ep
    steps = len(robot) - 1
    plain = psc(robot, peds)
    gibson = psc(robot, peds, max_steps=steps + max_steps)
    assert 0.0 <= plain <= gibson <= 1.0  # a longer denominator only forgives
    assert (1.0 - gibson) * (steps + max_steps) == approx((1.0 - plain) * steps)


@given(ep=episodes())
def test_collisions_count_is_at_most_the_samples(ep) -> None:
    robot, _, peds, _, r_robot, r_peds = ep
    n = pedestrian_collisions(robot, peds, robot_radius=r_robot, pedestrian_radii=r_peds)
    assert 0 <= n <= peds.shape[1] * ((len(robot) + 1) // 2)  # onsets need a gap between them
    assert motion_statistics(robot, ep[3])["speed_max"] >= 0.0
