"""The observation layout's array path (sensor terms) equals its float-list path."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from pointnav_core.task.observations import Frame, ObservationLayout, ObservationTerm


class Listed(ObservationTerm):
    name = "listed"

    def __init__(self, values):
        self.size = len(values)
        self._values = list(values)

    def values(self, frame):
        return list(self._values)


class Arrayed(Listed):
    name = "arrayed"
    array_values = True

    def values(self, frame):
        return np.array(self._values)


finite = st.floats(-1e6, 1e6)


@given(st.lists(finite, min_size=1, max_size=20), st.data())
def test_array_values_clip_and_flatten_like_float_lists(values, data):
    n = len(values)
    low = data.draw(st.lists(st.floats(-1e3, 0.0), min_size=n, max_size=n))
    high = data.draw(st.lists(st.floats(0.0, 1e3), min_size=n, max_size=n))
    frame = Frame()
    listed = ObservationLayout([Listed(values)], low, high).values(frame)
    arrayed = ObservationLayout([Arrayed(values)], low, high).values(frame)
    assert isinstance(listed, list) and isinstance(arrayed, np.ndarray)
    np.testing.assert_array_equal(np.array(listed, np.float32), arrayed.astype(np.float32))


@given(st.integers(1, 6), st.integers(1, 6), st.data())
def test_a_shaped_term_splits_into_its_shape_and_dtype(rows, cols, data):
    codes = data.draw(st.lists(st.integers(0, 3), min_size=rows * cols, max_size=rows * cols))

    class Grid(Arrayed):
        name = "grid"
        shape = (rows, cols)
        dtype = np.dtype(np.uint8)

    layout = ObservationLayout([Listed([0.5]), Grid(codes)], [0.0] * (1 + rows * cols), [3.0] * (1 + rows * cols))
    flat = np.array(layout.values(Frame()), dtype=np.float32)
    parts = layout.split(flat)
    assert parts["grid"].shape == (rows, cols) and parts["grid"].dtype == np.uint8
    np.testing.assert_array_equal(parts["grid"].ravel(), np.array(codes, np.uint8))
    assert parts["listed"].tolist() == [0.5]
