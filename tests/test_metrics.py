"""SPL and SoftSPL: hand-computed values, and one definition on floats, numpy and torch arrays."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from pointnav_core.task.metrics import soft_spl, soft_spl_values, spl, spl_values

INF = math.inf

# (success, d0, L, d_T, SPL, SoftSPL), each worked out by hand from Anderson et al. (2018)
# and Habitat's SoftSPL, with the module's readings of d0 = 0 and inf.
HAND = [
    (True, 4.0, 5.0, 0.4, 0.8, 0.9 * 0.8),  # 4 / 5; progress 1 - 0.4 / 4
    (True, 4.0, 3.5, 0.3, 1.0, 1.0 - 0.3 / 4.0),  # shorter than the geodesic: efficiency 1
    (False, 4.0, 8.0, 2.0, 0.0, 0.5 * 0.5),  # failed: SPL 0, half way at half the efficiency
    (False, 4.0, 1.0, 5.0, 0.0, 0.0),  # ended farther than it started
    (True, INF, 2.0, INF, 0.0, 0.0),  # unreachable goal
    (True, 0.0, 0.0, 0.0, 1.0, 1.0),  # started on the goal and stayed
    (True, 0.0, 0.3, 0.0, 0.0, 0.0),  # started on the goal and wandered
    (False, 3.0, 2.0, INF, 0.0, 0.0),  # cannot reach the goal from where it ended
]


@pytest.mark.parametrize(("success", "d0", "length", "d_t", "want_spl", "want_soft"), HAND)
def test_hand_computed_values(success, d0, length, d_t, want_spl, want_soft) -> None:
    assert spl(success, d0, length) == pytest.approx(want_spl, abs=1e-15)
    assert soft_spl(d_t, d0, length) == pytest.approx(want_soft, abs=1e-15)


def _grid() -> tuple[np.ndarray, ...]:
    values = [0.0, 0.5, 1.0, 2.0, 4.0, INF]
    rows = [(s, d0, L, dt) for s, d0, L, dt in itertools.product([False, True], values, values[:-1], values)]
    s, d0, L, dt = (np.array(c) for c in zip(*rows))
    return s.astype(bool), d0, L, dt


def test_one_definition_on_floats_and_numpy_arrays() -> None:
    s, d0, length, d_t = _grid()
    with np.errstate(invalid="ignore"):  # inf / inf in the branch where() discards
        got_spl = spl_values(s, d0, length, np.where)
        got_soft = soft_spl_values(d_t, d0, length, np.where)
    want_spl = [spl_values(bool(a), float(b), float(c)) for a, b, c in zip(s, d0, length)]
    want_soft = [soft_spl_values(float(a), float(b), float(c)) for a, b, c in zip(d_t, d0, length)]
    np.testing.assert_array_equal(got_spl, want_spl)
    np.testing.assert_array_equal(got_soft, want_soft)
    assert all(0.0 <= v <= 1.0 for v in want_spl + want_soft)


def test_one_definition_on_torch_tensors() -> None:
    torch = pytest.importorskip("torch")
    s, d0, length, d_t = _grid()
    t = {k: torch.as_tensor(v) for k, v in (("s", s), ("d0", d0), ("L", length), ("dt", d_t))}
    got_spl = spl_values(t["s"], t["d0"], t["L"], torch.where).numpy()
    got_soft = soft_spl_values(t["dt"], t["d0"], t["L"], torch.where).numpy()
    with np.errstate(invalid="ignore"):
        np.testing.assert_array_equal(got_spl, spl_values(s, d0, length, np.where))
        np.testing.assert_array_equal(got_soft, soft_spl_values(d_t, d0, length, np.where))
