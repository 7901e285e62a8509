"""The scan noise's compiled hashing equals its numpy passes, and both equal the hash by hand.

:func:`~pointnav_core.sensors.noise.scan_noise` hashes every ray's word either with numpy
whole-array passes or in one compiled loop (numba, the ``fast`` extra); for random keys
(the whole uint64 range), robots, steps, batch shapes, ray counts and channels both give
the same bits, and a drawn element equals splitmix64 written out with Python ints here.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.special import ndtri

from pointnav_core.sensors.noise import DROPOUT, NOISE, scan_noise

pytest.importorskip("numba")

M64 = 0xFFFFFFFFFFFFFFFF


def _finalise(z: int) -> int:
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & M64
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & M64
    return z ^ (z >> 31)


def _mix(h: int, v: int) -> int:
    return _finalise(_finalise((h + 0x9E3779B97F4A7C15) & M64) ^ v)


def _by_hand(episode: int, robot: int, step: int, ray: int, channel: int) -> float:
    return ((_mix(_mix(_mix(_mix(episode, robot), step), ray), channel) >> 11) + 0.5) / 2.0**53


@settings(max_examples=60, deadline=None)
@given(
    worlds=st.integers(1, 6), robots=st.integers(1, 4), n_rays=st.integers(1, 40),
    seed=st.integers(0, 2**32 - 1), noise_std=st.sampled_from([0.0, 0.01, 0.3]),
    dropout=st.sampled_from([0.0, 0.05, 0.5]), pick=st.integers(0, 10**6),
)
def test_compiled_noise_equals_numpy_and_the_hash_by_hand(
    worlds: int, robots: int, n_rays: int, seed: int, noise_std: float, dropout: float, pick: int
) -> None:
    rng = np.random.default_rng(seed)
    episode = rng.integers(0, 2**64, (worlds, 1, 1), dtype=np.uint64)
    robot = np.arange(robots)[None, :, None]
    step = rng.integers(0, 10_000, (worlds, robots, 1))
    args = (episode, robot, step, n_rays, noise_std, dropout)
    want, got = scan_noise(*args, method="numpy"), scan_noise(*args, method="numba")
    for w, g in zip(want, got, strict=True):
        assert (w is None) == (g is None)
        if w is not None:
            assert w.shape == (worlds, robots, n_rays)
            np.testing.assert_array_equal(g, w)
    # One element by hand (Python ints): world, robot and ray from the drawn pick.
    i, j, r = pick % worlds, (pick // worlds) % robots, (pick // (worlds * robots)) % n_rays
    keys = (int(episode[i, 0, 0]), j, int(step[i, j, 0]), r)
    if noise_std > 0.0:
        assert got[0][i, j, r] == noise_std * ndtri(_by_hand(*keys, NOISE))
    if dropout > 0.0:
        assert bool(got[1][i, j, r]) == (_by_hand(*keys, DROPOUT) < dropout)
    if noise_std == 0.0 and dropout == 0.0:
        assert got == (None, None)
