"""crowds.orca_step equals RVO2 (``pyrvo``) on random small crowds, bit for bit.

Up to 10 agents: RVO2's k-d tree is then one leaf visited in agent order, so even exact ties
of distances (agents on a grid, ``snap``) are broken alike, and equality holds without
exception. Crowds are dense enough for overlaps (collision lines) and infeasible programs
(linearProgram3); parameters vary, per-agent radii and speeds included.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from orca_reference import random_crowd, worst_gap

pytest.importorskip("pyrvo", reason="the reference is in the dev extra")


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(1, 10),
    side=st.floats(0.5, 8.0),
    snap=st.sampled_from([0.0, 0.0, 0.5, 0.25]),
    dt=st.sampled_from([0.05, 0.1, 0.25]),
    neighbor_dist=st.floats(0.0, 10.0),
    max_neighbors=st.integers(0, 12),
    time_horizon=st.floats(0.1, 10.0),
    steps=st.integers(1, 30),
    method=st.sampled_from(["auto", "array"]),
)
def test_small_crowds_equal_rvo2(
    seed: int, n: int, side: float, snap: float, dt: float, neighbor_dist: float, max_neighbors: int,
    time_horizon: float, steps: int, method: str,
) -> None:
    crowd = random_crowd(np.random.default_rng(seed), n, side, snap)
    crowd.dt, crowd.neighbor_dist, crowd.max_neighbors, crowd.time_horizon = dt, neighbor_dist, max_neighbors, time_horizon
    assert worst_gap(crowd, steps, method) == 0.0
