"""crowds.social_force_step equals pysocialforce on random small crowds, within 1e-6 m.

Up to 10 pedestrians in squares down to 0.5 m (crowded: strong repulsions), walls or none,
either repulsion, desired speeds of pysocialforce's rule (1.3 times the initial speed), steps
of 0.05-0.1 s, where pysocialforce is stable (``tests/test_social_force.py`` says why larger
steps cannot be followed by any other code), and sometimes a pedestrian starting on its goal.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from social_force_reference import random_crowd, skip_without_reference, worst_gap

skip_without_reference()


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(1, 10),
    side=st.floats(0.5, 8.0),
    walls=st.integers(0, 2),
    dt=st.sampled_from([0.05, 0.1]),
    model=st.sampled_from(["moussaid", "helbing_molnar"]),
    steps=st.integers(1, 30),
    method=st.sampled_from(["auto", "array"]),
    on_goal=st.booleans(),
)
def test_small_crowds_equal_pysocialforce(
    seed: int, n: int, side: float, walls: int, dt: float, model: str, steps: int, method: str, on_goal: bool,
) -> None:
    crowd = random_crowd(np.random.default_rng(seed), n, side, walls, dt)
    if on_goal:
        crowd.goals[0] = crowd.positions[0]
    assert worst_gap(crowd, steps, (method,), model) < 1e-6
