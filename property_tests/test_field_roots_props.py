"""The floor's cell links give the roots found link by link.

The floor's cell links (:class:`pointnav_core.geodesic.cell_links.CellLinks`: every usable
cell centre's clear links, found once per floor) give, through ``roots.table_roots``, exactly
the kinds, labels and distances of ``roots.compiled_roots``, which tests each candidate
link's segment itself; each cell's links are those the one-point query finds. (Settling a
goal field's cells in batches makes exactly the one-point decision, with numba's kernels and
on their numpy paths alike: ``property_tests/test_compiled_paths.py``, checks in
``tests/pairs_geodesic.py``, with the scenes drawn here.)
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from pairs_geodesic import fields

from pointnav_core.geodesic import roots
from pointnav_core.geodesic.cell_links import CellLinks, cell_centres


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(field=fields())
def test_roots_from_cell_links_equal_the_roots_found_link_by_link(field) -> None:
    pytest.importorskip("numba")
    p = field.planner
    if not p.n_nodes or not field.goal_usable:
        return
    links = CellLinks.build(p)
    cells = np.flatnonzero(p.usable.ravel())
    xs, ys = cell_centres(p, cells)
    tables = field.arc_tables()
    got = roots.table_roots(field, tables, links, cells, xs, ys)
    want = roots.compiled_roots(field, tables, xs, ys)
    for a, b in zip(got, want):
        np.testing.assert_array_equal(a, b)
    # Every link is clear and lands on its node's arc: the same links the one-point query
    # finds (Planner.point_links), in a cell's order.
    for i in cells[:: max(1, len(cells) // 25)].tolist():
        x, y = cell_centres(p, np.array([i]))
        lo, n = links.first[i], links.count[i]
        mine = sorted(zip(links.node[lo : lo + n].tolist(), (1 - 2 * links.side[lo : lo + n]).tolist()))
        theirs = sorted((c, s) for c, s, _, _ in p.point_links(float(x[0]), float(y[0])))
        assert mine == theirs
