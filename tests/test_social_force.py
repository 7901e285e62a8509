"""crowds.social_force_step: hand-computed steps, pysocialforce's positions on random crowds
over 200 steps (the issue's must-show 2), batches of worlds, and the arguments it refuses.

The crowds step 0.1 s, where pysocialforce is stable: there both paths stay within 1e-10 m
of it (rounding only; 1e-14 m for Moussaïd's repulsion, 1e-11 m for Helbing and Molnár's,
whose finite-difference gradient divides rounding by its 1e-3 m step). At 0.25 s and more
with walls (0.4 s without) the model amplifies rounding: pysocialforce started one ulp apart
from itself ends metres apart within 200 steps, so no other code can follow it there
(docs/decisions.md, "Social force in the project"; ``test_larger_steps_amplify_rounding``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from social_force_reference import Crowd, random_crowd, simulator, skip_without_reference, worst_gap

from pointnav_core.crowds import SocialForceParams, social_force_step
from pointnav_core.errors import ArgumentError

HAS_NUMBA = __import__("importlib").util.find_spec("numba") is not None
METHODS = ["array", pytest.param("numba", marks=pytest.mark.skipif(not HAS_NUMBA, reason="the `fast` extra"))]
BOTH = ("array", "numba") if HAS_NUMBA else ("array",)
MODELS = ["moussaid", "helbing_molnar"]
needs_reference = pytest.mark.usefixtures("reference")


@pytest.fixture
def reference():
    skip_without_reference()


@pytest.mark.parametrize("method", METHODS)
def test_two_pedestrians_moussaid_by_hand(method):
    # Both stand still 2 m apart on the x axis, goals 10 m up. For pedestrian 0: r_0 - r_1 =
    # (-2, 0), e = (-1, 0); no relative velocity, so the interaction vector is e itself, t =
    # (-1, 0), theta = atan2(t) - atan2(e) = 0 and B = gamma |t| = 0.35: the push is
    # 5.1 exp(-2 / 0.35) along t, with no turning part (sign(0) = 0). The desired force is
    # ((0, 1.3) - 0) / 0.5 = (0, 2.6). After dt = 0.1: v = 0.1 F = (-0.51 exp(-40 / 7), 0.26),
    # under the max speed; x = 0.1 v. Pedestrian 1 is the mirror image.
    push = 0.51 * math.exp(-40.0 / 7.0)  # 0.00168...
    pos, vel = social_force_step([[0.0, 0.0], [2.0, 0.0]], np.zeros((2, 2)), [[0.0, 10.0], [2.0, 10.0]],
                                 1.3, 1.3, 0.1, method=method)
    np.testing.assert_allclose(vel, [[-push, 0.26], [push, 0.26]], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(pos, [[-0.1 * push, 0.026], [2.0 + 0.1 * push, 0.026]], rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("method", METHODS)
def test_two_pedestrians_helbing_molnar_by_hand(method):
    # Still pedestrians: the step dt |v_b| e_b is 0, the ellipse a circle, b = |r| and
    # V(r) = 2.1 exp(-|r| / 0.3). With r_0 - r_1 = (-2, 0) the forward difference in x moves
    # to |r| = 2 - 1e-3: f_x = -(V(2 - 1e-3) - V(2)) / 1e-3 (away from pedestrian 1); in y,
    # |r| = sqrt(4 + 1e-6). -f points along +x, 90° from the desired direction (0, 1),
    # within the 100° field of view: weight 1, then factor 1.5. For pedestrian 1, r = (2, 0)
    # and the x difference moves to |r| = 2 + 1e-3: a forward difference is not symmetric.
    v = lambda d: 2.1 * math.exp(-d / 0.3)
    fy = -(v(math.sqrt(4.0 + 1e-6)) - v(2.0)) / 1e-3
    want = [0.1 * np.array([1.5 * -(v(2.0 - sign * 1e-3) - v(2.0)) / 1e-3, 2.6 + 1.5 * fy]) for sign in (1, -1)]
    pos, vel = social_force_step([[0.0, 0.0], [2.0, 0.0]], np.zeros((2, 2)), [[0.0, 10.0], [2.0, 10.0]],
                                 1.3, 1.3, 0.1, model="helbing_molnar", method=method)
    np.testing.assert_allclose(vel, want, rtol=1e-8)
    np.testing.assert_allclose(pos, 0.1 * vel + [[0.0, 0.0], [2.0, 0.0]], rtol=1e-12)


@pytest.mark.parametrize("method", METHODS)
def test_speed_cap_goal_stop_and_a_wall_by_hand(method):
    # Alone, at rest, goal 10 m away: v = 0.1 * 2.0 / 0.5 = 0.4 m/s, capped at 0.3 m/s.
    pos, vel = social_force_step([[0.0, 0.0]], [[0.0, 0.0]], [[10.0, 0.0]], 2.0, 0.3, 0.1, method=method)
    np.testing.assert_allclose(vel, [[0.3, 0.0]], rtol=1e-15)
    # 0.4 m from the goal, within the 0.5 m stop distance: stopped.
    pos, vel = social_force_step([[0.0, 0.0]], [[1.0, 0.0]], [[0.4, 0.0]], 1.0, 1.3, 0.1, method=method)
    assert vel.tolist() == [[0.0, 0.0]] and pos.tolist() == [[0.0, 0.0]]
    # A wall from (0, -1) to (0, 1): 20 points 2/19 m apart. The pedestrian at (1, 0), at
    # rest with its goal 10 m up, is pushed along +x by 10 * sum exp(-(d_k - 0.35) / 0.2) (d_k / d_k).
    ys = np.linspace(-1.0, 1.0, 20)
    d = np.hypot(1.0, ys)
    push = 10.0 * np.sum(np.exp(-(d - 0.35) / 0.2) / d)
    pos, vel = social_force_step([[1.0, 0.0]], [[0.0, 0.0]], [[1.0, 10.0]], 1.0, 5.0, 0.1,
                                 walls=[[[0.0, -1.0], [0.0, 1.0]]], method=method)
    np.testing.assert_allclose(vel, [[0.1 * push, 0.2]], rtol=1e-12, atol=1e-15)


@needs_reference
@pytest.mark.parametrize("model", MODELS)
def test_random_crowds_equal_pysocialforce_over_200_steps(model):
    """The issue's must-show 2: 30 pedestrians in an 8 m square, 200 steps of 0.1 s, both
    paths, three crowds (one with walls): within 1e-6 m (and m/s) of pysocialforce."""
    for seed, walls in ((0, 0), (1, 0), (2, 3)):
        crowd = random_crowd(np.random.default_rng(seed), 30, 8.0, walls)
        assert worst_gap(crowd, 200, BOTH, model) < 1e-6


@needs_reference
def test_the_comparison_sees_a_small_difference():
    """A relaxation time 1e-6 s longer than pysocialforce's does not pass."""
    crowd = random_crowd(np.random.default_rng(0), 20, 6.0)
    assert worst_gap(crowd, 50) < 1e-12
    assert worst_gap(crowd, 50, params=SocialForceParams(relaxation_time=0.5 + 1e-6)) > 1e-6


@needs_reference
def test_larger_steps_amplify_rounding():
    """At dt = 0.4 s pysocialforce against itself started one ulp apart is far more than
    1e-6 m apart after 200 steps: the reason the comparisons step 0.1 s."""
    crowd = random_crowd(np.random.default_rng(0), 30, 8.0, dt=0.4)
    moved = Crowd(np.nextafter(crowd.positions, np.inf), crowd.velocities, crowd.goals, dt=0.4)
    a, b = simulator(crowd), simulator(moved)
    with np.errstate(divide="ignore", invalid="ignore"):  # pysocialforce divides by zero speeds
        a.step(200)
        b.step(200)
    assert np.abs(a.peds.pos() - b.peds.pos()).max() > 1e-3


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("model", MODELS)
def test_worlds_step_apart_as_if_alone(method, model):
    rng = np.random.default_rng(3)
    crowds = [random_crowd(rng, 12, 6.0, walls=2) for _ in range(3)]
    stack = [np.stack([getattr(c, name) for c in crowds]) for name in ("positions", "velocities", "goals", "walls")]
    speed = rng.uniform(0.5, 1.5, (3, 12))
    pos, vel = social_force_step(*stack[:3], speed, 1.6, 0.1, model=model, walls=stack[3], method=method)
    for w, crowd in enumerate(crowds):
        one = social_force_step(crowd.positions, crowd.velocities, crowd.goals, speed[w], 1.6, 0.1, model=model,
                                walls=crowd.walls, method=method)
        np.testing.assert_array_equal(pos[w], one[0])
        np.testing.assert_array_equal(vel[w], one[1])


def test_shared_walls_and_padding():
    """(m, 2, 2) walls are every world's; a zero-length segment adds no point (padding)."""
    rng = np.random.default_rng(4)
    crowd = random_crowd(rng, 8, 5.0, walls=2)
    pos, vel, goals = (np.stack([x, x]) for x in (crowd.positions, crowd.velocities, crowd.goals))
    shared = social_force_step(pos, vel, goals, 1.0, 1.3, 0.1, walls=crowd.walls, method="array")
    padded = np.stack([np.concatenate([crowd.walls, np.zeros((1, 2, 2))]), np.concatenate([crowd.walls, crowd.walls[:1]])])
    padded[1, 2] = padded[1, 2, :1]  # world 1's third segment: zero length too
    each = social_force_step(pos, vel, goals, 1.0, 1.3, 0.1, walls=padded, method="array")
    np.testing.assert_array_equal(shared[0], each[0])


def test_inputs_are_not_changed():
    pos, vel, goals = np.zeros((2, 2)), np.ones((2, 2)), np.full((2, 2), 5.0)
    pos[1] = 1.0
    before = [pos.copy(), vel.copy()]
    social_force_step(pos, vel, goals, 1.0, 1.3, 0.1, method="array")
    np.testing.assert_array_equal(pos, before[0])
    np.testing.assert_array_equal(vel, before[1])


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"positions": [[0.0, 0.0, 0.0]]}, "positions must be an"),
        ({"positions": [[np.inf, 0.0]]}, "positions must be"),
        ({"velocities": [[0.0, 0.0], [1.0, 1.0]]}, r"velocities must be an array of shape \(1, 2\)"),
        ({"goals": [[True, False]]}, "goals must be"),
        ({"goals": "ab"}, "goals must be"),
        ({"speed": -0.1}, r"speed must be a finite number >= 0 \(m/s\)"),
        ({"speed": True}, "speed must be a number"),
        ({"max_speed": [1.0, 2.0]}, r"max_speed must be a finite number >= 0 \(m/s\), or an array of shape \(1,\)"),
        ({"max_speed": np.nan}, "max_speed must be a finite number"),
        ({"dt": 0.0}, r"dt must be a finite number > 0 \(s\)"),
        ({"dt": "0.1"}, "dt must be a finite number"),
        ({"model": "helbing"}, "model must be one of 'moussaid', 'helbing_molnar'"),
        ({"walls": [[0.0, 0.0], [1.0, 1.0]]}, r"walls must be an \(m, 2, 2\) array"),
        ({"walls": np.zeros((2, 1, 2, 2))}, r"walls must be .* or \(1, m, 2, 2\)"),
        ({"walls": [[[0.0, 0.0], [np.nan, 1.0]]]}, "walls must be"),
        ({"params": {"relaxation_time": 1.0}}, "params must be a SocialForceParams"),
        ({"method": "fast"}, "method must be one of"),
    ],
)
def test_bad_arguments_are_refused_by_name(change, match):
    args = {"positions": [[0.0, 0.0]], "velocities": [[0.0, 0.0]], "goals": [[1.0, 0.0]], "speed": 1.0,
            "max_speed": 1.3, "dt": 0.1}
    with pytest.raises(ArgumentError, match=match):
        social_force_step(**{**args, **change})


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"relaxation_time": 0.0}, r"relaxation_time must be a finite number > 0 \(s\)"),
        ({"social_factor": -1.0}, r"social_factor must be a finite number >= 0 \(m/s²\)"),
        ({"sigma": True}, "sigma must be a finite number > 0"),
        ({"n": "2"}, "n must be a finite number >= 0"),
        ({"wall_resolution": np.inf}, "wall_resolution must be a finite number"),
    ],
)
def test_bad_parameters_are_refused_by_name(change, match):
    with pytest.raises(ArgumentError, match=match):
        SocialForceParams(**change)
