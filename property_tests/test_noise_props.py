"""The scan noise's compiled hashing equals its numpy passes.

:func:`~pointnav_core.sensors.noise.scan_noise` hashes every ray's word either with numpy
whole-array passes or in one compiled loop (numba, the ``fast`` extra); for random keys
(the whole uint64 range), robots, steps, batch shapes, ray counts and channels both give
the same bits. (``tests/test_scan_noise.py`` checks the numpy path against splitmix64
written out with Python ints.)
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pointnav_core.sensors.noise import scan_noise

pytest.importorskip("numba")


@settings(max_examples=60, deadline=None)
@given(
    worlds=st.integers(1, 6), robots=st.integers(1, 4), n_rays=st.integers(1, 40),
    seed=st.integers(0, 2**32 - 1), noise_std=st.sampled_from([0.0, 0.01, 0.3]),
    dropout=st.sampled_from([0.0, 0.05, 0.5]),
)
def test_compiled_noise_equals_numpy(
    worlds: int, robots: int, n_rays: int, seed: int, noise_std: float, dropout: float
) -> None:
    rng = np.random.default_rng(seed)
    episode = rng.integers(0, 2**64, (worlds, 1, 1), dtype=np.uint64)
    robot = np.arange(robots)[None, :, None]
    step = rng.integers(0, 10_000, (worlds, robots, 1))
    args = (episode, robot, step, n_rays, noise_std, dropout)
    want, got = scan_noise(*args, method="array"), scan_noise(*args, method="numba")
    for w, g in zip(want, got, strict=True):
        assert (w is None) == (g is None)
        if w is not None:
            assert w.shape == (worlds, robots, n_rays)
            np.testing.assert_array_equal(g, w)
    if noise_std == 0.0 and dropout == 0.0:
        assert got == (None, None)
