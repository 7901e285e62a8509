"""Plain and compiled paths of :func:`pointnav_core.crowds.orca_step`: the check of
``property_tests/test_compiled_paths.py`` for ``crowds._orca_kernel``.

Both paths give the same floats, bit for bit, on random crowds in batches of worlds (one
to 30 agents, more than RVO2's k-d tree leaf of 10), with per-agent radii and speeds, ties of
distances (agents on a grid) and overlaps, over several steps. Each is also checked against
RVO2 itself (``tests/test_orca.py``, ``property_tests/test_orca_props.py``).
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from orca_reference import preferred, random_crowd

from pointnav_core.crowds import orca_step
from pointnav_core.utils.compiled import kernel

Plain = Callable[[], AbstractContextManager[None]]


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    worlds=st.integers(1, 3),
    n=st.integers(1, 30),
    side=st.floats(0.5, 10.0),
    snap=st.sampled_from([0.0, 0.5]),
    max_neighbors=st.integers(0, 12),
    time_horizon=st.floats(0.1, 5.0),
    steps=st.integers(1, 10),
)
def check_orca(
    seed: int, worlds: int, n: int, side: float, snap: float, max_neighbors: int, time_horizon: float, steps: int,
    plain_paths: Plain,
) -> None:
    """orca_step with its kernel and inside ``plain_paths()``."""
    rng = np.random.default_rng(seed)
    crowds = [random_crowd(rng, n, side, snap) for _ in range(worlds)]
    pos, vel, goals, radius, speed = (
        np.stack([getattr(c, name) for c in crowds]) for name in ("positions", "velocities", "goals", "radius", "max_speed")
    )
    args = (radius, speed, 0.1, 4.0, max_neighbors, time_horizon)
    got = want = (pos, vel)
    for _ in range(steps):
        pref = np.stack([preferred(p, g) for p, g in zip(got[0], goals)])
        got = orca_step(*got, pref, *args)
        with plain_paths():
            assert kernel("pointnav_core.crowds._orca_kernel", "orca_worlds") is None
            want = orca_step(*want, pref, *args)
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])
    assert kernel("pointnav_core.crowds._orca_kernel", "orca_worlds") is not None
