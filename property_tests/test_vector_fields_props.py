"""Goal-field tables settled as lookups land equal the tables settled whole.

The batched engine's tables (:class:`pointnav_core.vector.fields.FieldTables`) built in the
stepping process leave their cells unsettled and settle a cell's block on its first lookup;
tables built in a worker are settled whole. Both must answer every lookup alike, bit for
bit, whatever order the lookups come in, after the tables are joined (a pool refresh) and
moved to another device.
"""

from __future__ import annotations

import importlib.util

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pairs_geodesic import fields

from pointnav_core.geodesic import GoalField
from pointnav_core.vector.fields import FieldTables
from pointnav_core.vector.xp import make_arrays

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])


def _points(field: GoalField, rng: np.random.Generator, n: int) -> np.ndarray:
    """``n`` points over the field's grid and a cell beyond it: cell centres, corners and
    random points, usable or not."""
    geo = field.planner.geo
    h, w = geo.shape
    (ox, oy), res = geo.origin[:2], geo.resolution
    cells = rng.uniform(-1.0, [w + 1.0, h + 1.0], (n, 2))
    cells[: n // 3] = np.floor(cells[: n // 3]) + 0.5
    cells[n // 3 : n // 2] = np.floor(cells[n // 3 : n // 2])
    return cells * res + (ox, oy)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(field=fields(), seed=st.integers(0, 2**16), device=st.sampled_from(DEVICES), batches=st.integers(1, 6))
def test_tables_settled_as_lookups_land_answer_as_tables_settled_whole(field, seed, device, batches) -> None:
    rng = np.random.default_rng(seed)
    a = make_arrays(device)
    p = field.planner
    # Two fields of the same goal, each settled on its own: one whole, one by lookups.
    whole, lazy = GoalField(p, field.goal), GoalField(p, field.goal)
    other = GoalField(p, _points(field, rng, 1)[0])
    # A field the single env has looked up already (its start's block, say) is part settled.
    for some in (lazy, other):
        some.settle(rng.choice(p.usable.size, int(rng.integers(0, 8)), replace=True))
    starts = [_points(field, rng, 2), _points(field, rng, 1)]
    reach = float(rng.uniform(0.0, 2.0) * max(p.geo.shape) * p.geo.resolution)
    settled = FieldTables([whole, GoalField(p, other.goal)], a, starts, reach)
    pending = FieldTables([lazy], a, starts[:1], reach, lazy=True)
    assert pending.lazy and not settled.lazy
    # A refresh joins a lazy pool's tables to older ones; both keep settling.
    joined = FieldTables.concat(pending, FieldTables([other], a, starts[1:], reach, lazy=True))
    xy = _points(field, rng, 300)
    for part in np.array_split(rng.permutation(len(xy)), batches):
        for f in (0, 1):
            x, y = xy[part, 0], xy[part, 1]
            fs, xs, ys = a.asarray(np.full(len(part), f), a.i64), a.asarray(x), a.asarray(y)
            np.testing.assert_array_equal(a.numpy(joined.distance(fs, xs, ys)), a.numpy(settled.distance(fs, xs, ys)))
    # Moved to numpy, the tables keep what they settled and settle the rest alike.
    moved, reference = joined.to(make_arrays("numpy")), settled.to(make_arrays("numpy"))
    x, y, f = xy[::-1, 0], xy[::-1, 1], np.arange(len(xy)) % 2
    np.testing.assert_array_equal(moved.distance(f, x, y), reference.distance(f, x, y))
