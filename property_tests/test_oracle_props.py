"""The oracle's float32 holonomic actions move the robot where it aims, to ~1e-10 m sideways.

A passage exactly as wide as the robot leaves it ~1e-9 m of play (the backends' contact
tolerance), less than plain float32 rounding of an action strays (~2e-9 m on a 0.05 m step).
The reference is the world motion worked out by hand: ``scale * R(yaw) a`` in float64.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from pointnav_core.policies.oracle import _float32_move

angles = st.one_of(
    st.floats(-math.pi, math.pi),
    st.integers(-8, 8).map(lambda k: k * math.pi / 8),  # axis-aligned and diagonal: rounding is worst there
)


@given(yaw=angles, heading=angles, share=st.floats(1e-4, 1.0), scale=st.sampled_from((0.05, 0.025, 0.1)))
def test_a_holonomic_oracle_action_strays_under_half_a_nanometre_sideways(yaw, heading, share, scale):
    length = share * scale
    dx, dy = length * math.cos(heading), length * math.sin(heading)
    action = _float32_move(dx, dy, yaw, scale)
    assert action.dtype == np.float32 and action.shape == (2,)
    assert np.all(np.abs(action) <= 1.0)
    a0, a1 = (float(v) for v in action)
    mx = scale * (a0 * math.cos(yaw) - a1 * math.sin(yaw))
    my = scale * (a0 * math.sin(yaw) + a1 * math.cos(yaw))
    sideways = abs((mx - dx) * dy - (my - dy) * dx) / length
    along = ((mx * dx + my * dy) / length) / length
    assert sideways <= 4e-10 * scale / 0.05
    assert 1.0 - 1.1e-3 <= along <= 1.0 + 1e-6
