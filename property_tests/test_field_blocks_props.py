"""Checking a root-table block: the fast helpers make exactly the general decision.

On walled rooms of random boxes several blocks wide, checking every block with the memo of
checked proposals (what ``vector.fields.settle`` does) leaves exactly the table that
checking each block without it leaves, in a random block order.

``_unique_pairs`` (one int64 key per ``(cell, root)`` pair, one 1-D sort) gives the rows
that ``np.unique(pairs, axis=0)`` gives, in the same order; the reference here is Python's
``sorted(set(...))`` of the pairs, which orders tuples lexicographically by cell then root.
"""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st

from pointnav_core.maps import OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.tangent_field import _unique_pairs

_pairs = st.lists(st.tuples(st.integers(0, 2_000), st.integers(-2, 3_000_000)), max_size=300)


@settings(deadline=None)
@given(pairs=_pairs, repeat=st.integers(1, 3))
def test_unique_pairs_are_the_sorted_distinct_pairs(pairs: list[tuple[int, int]], repeat: int) -> None:
    cells = np.array([c for c, _ in pairs] * repeat, dtype=np.int64)
    roots = np.array([r for _, r in pairs] * repeat, dtype=np.int64)
    got = _unique_pairs(cells, roots)
    want = sorted(set(pairs))
    assert got.dtype == np.int64
    assert got.shape == (len(want), 2)
    assert [tuple(row) for row in got.tolist()] == want


@settings(deadline=None)
@given(
    cells=st.lists(st.integers(0, 1_023), min_size=1, max_size=200),
    roots=st.data(),
)
def test_unique_pairs_match_numpy_row_unique(cells: list[int], roots: st.DataObject) -> None:
    """The small roots a block holds (none, the goal, a few labels): numpy's row unique."""
    r = roots.draw(st.lists(st.integers(-2, 5), min_size=len(cells), max_size=len(cells)))
    c = np.array(cells, dtype=np.int64)
    rr = np.array(r, dtype=np.int64)
    want = np.unique(np.stack([c, rr], axis=1), axis=0)
    assert np.array_equal(_unique_pairs(c, rr), want)


@st.composite
def _wide_fields(draw: st.DrawFn):
    """A goal field of a walled room of random boxes, several blocks wide, with its proposed
    (unchecked) table; radius 0 to 0.2 m, the goal at a random usable cell centre."""
    rows, cols = draw(st.integers(20, 56)), draw(st.integers(20, 56))
    rng = np.random.default_rng(draw(st.integers(0, 2**31 - 1)))
    grid = np.zeros((rows, cols), np.uint8)
    for _ in range(draw(st.integers(0, rows * cols // 40))):
        r, c = rng.integers(0, rows - 1), rng.integers(0, cols - 1)
        grid[r : r + rng.integers(1, 5), c : c + rng.integers(1, 5)] = OBSTACLE
    grid = np.pad(grid, 1, constant_values=OBSTACLE)
    radius = draw(st.one_of(st.just(0.0), st.floats(0.0, 0.2)))
    scene = Scene.from_array(grid, 0.1)
    usable = np.argwhere(scene.floors[0].usable(radius))
    if not len(usable):
        usable = np.argwhere(grid == 0)
    r, c = usable[draw(st.integers(0, len(usable) - 1))]
    goal = scene.floors[0].cell_to_world(np.array([r, c]))
    field = scene.planner(0, radius).goal_field(goal)
    field._build_table()
    return field


def _check_every_block(field, order: list[int], memo: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Check the blocks of ``field``'s freshly proposed table in ``order``; its kinds and labels."""
    from pointnav_core.tangent_field import _BLOCK

    t = field._table
    w = field.planner.geo.shape[1]
    bw = t["blocks_w"]
    for b in order:
        if not t["done"][b]:
            field._check_block((b // bw) * _BLOCK * w + (b % bw) * _BLOCK, memo)
    return t["kind"].copy(), t["label"].copy()


@settings(deadline=None, max_examples=40, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(field=_wide_fields(), data=st.data())
def test_checking_blocks_with_a_memo_of_proposals_gives_the_same_table(field, data) -> None:
    """Blocks checked with the proposal memo (the fast path ``settle`` takes) leave exactly the
    table that checking each block on its own (the general path) leaves, in any block order."""
    t = field._table
    n_blocks = len(t["done"])
    order = data.draw(st.permutations(range(n_blocks)))
    start = {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in t.items()}
    want_kind, want_label = _check_every_block(field, order, None)
    t.update({k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in start.items()})
    memo = np.zeros(len(t["kind"]), dtype=np.int8)
    got_kind, got_label = _check_every_block(field, order, memo)
    assert np.array_equal(got_kind, want_kind)
    assert np.array_equal(got_label, want_label)
    # Every proposal the memo holds was checked: its cell left the unchecked state.
    assert not (t["kind"][memo > 0] == 4).any()
    note(f"blocks {n_blocks}, proposals memoised {int((memo > 0).sum())}")
