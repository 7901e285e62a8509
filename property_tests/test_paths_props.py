"""The task's per-step waypoint placement against the general polyline resampler."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from pointnav_core.geodesic.paths import path_length, resample_path
from pointnav_core.task.markers import _waypoints_along

polylines = st.integers(1, 12).flatmap(
    lambda n: arrays(np.float64, (n, 2), elements=st.floats(-20.0, 20.0, allow_subnormal=False))
)


@given(polylines, st.integers(1, 20), st.floats(0.01, 3.0))
def test_waypoints_along_is_resample_path_at_the_same_spacing(pts, count, min_spacing):
    positions, visible = _waypoints_along(pts, count, min_spacing)
    length = path_length(pts)
    spacing = max(min_spacing, length / (count + 1))
    assert np.allclose(positions, resample_path(pts, spacing, count + 1)[1:], atol=1e-9)
    # Shown exactly where the waypoint lies strictly before the path's end (up to rounding).
    s = np.arange(1, count + 1) * spacing
    assert visible[s < length * (1 - 1e-6) - 1e-9].all()
    assert not visible[s >= length].any()
