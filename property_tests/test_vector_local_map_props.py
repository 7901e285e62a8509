"""The batched local map against an independent shapely reference.

For random grid floors (obstacle cells, VOID, the map's edge), random poses of up to four
robots per world (some absent, of one radius or each of its own), map sizes from a fraction of a cell to several metres and
1 to 12 cells a side, computed in blocks of 1 to 6 worlds (the CPU's blocks), every code of :meth:`VectorLocalMap.values` (numpy, and torch on the
CPU) equals ``local_map_reference.reference_map`` (shapely squares and discs), except at a
tie: a cell centre within 1e-9 m of a cell edge or a disc's rim.
"""

from __future__ import annotations

import importlib.util
from unittest import mock

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from local_map_reference import reference_map

from pointnav_core.floor.maps import OBSTACLE, VOID
from pointnav_core.scenes import Scene
from pointnav_core.sensors import LocalMap
from pointnav_core.vector import local_map as local_map_module
from pointnav_core.vector.floors import FloorTables
from pointnav_core.vector.local_map import VectorLocalMap
from pointnav_core.vector.xp import make_arrays

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])


@pytest.mark.parametrize("device", DEVICES)
@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    rows=st.integers(1, 20),
    cols=st.integers(1, 20),
    res=st.sampled_from([0.05, 0.1, 0.25]),
    worlds=st.integers(1, 5),
    block=st.integers(1, 6),
    n_robots=st.integers(1, 4),
    size=st.floats(0.01, 4.0),
    cells=st.integers(1, 12),
    radius=st.floats(0.01, 0.5),
    own_radii=st.booleans(),
)
def test_local_map_matches_shapely(
    device: str, seed: int, rows: int, cols: int, res: float, worlds: int, block: int, n_robots: int, size: float,
    cells: int, radius: float, own_radii: bool,
) -> None:
    rng = np.random.default_rng(seed)
    grid = np.zeros((rows, cols), np.uint8)
    grid[rng.random((rows, cols)) < 0.3] = OBSTACLE
    grid[rng.random((rows, cols)) < 0.1] = VOID
    scene = Scene.from_array(grid, res, origin=(float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1))))
    ox, oy = scene.floors[0].origin[:2]
    # Poses on the map and up to a metre around it; robots close together often.
    x = rng.uniform(ox - 1.0, ox + cols * res + 1.0, (worlds, n_robots))
    y = rng.uniform(oy - 1.0, oy + rows * res + 1.0, (worlds, n_robots))
    x[:, 1:] = np.where(rng.random((worlds, n_robots - 1)) < 0.5, x[:, :1] + rng.uniform(-0.5, 0.5, (worlds, n_robots - 1)), x[:, 1:])
    y[:, 1:] = np.where(rng.random((worlds, n_robots - 1)) < 0.5, y[:, :1] + rng.uniform(-0.5, 0.5, (worlds, n_robots - 1)), y[:, 1:])
    yaw = rng.uniform(-3 * np.pi, 3 * np.pi, (worlds, n_robots))
    present = rng.random((worlds, n_robots)) < 0.8
    # One radius for all, or each robot its own (down to a tenth of the drawn one).
    radii = radius * rng.uniform(0.1, 1.0, (worlds, n_robots)) if own_radii else np.full((worlds, n_robots), radius)
    a = make_arrays(device)
    lm = VectorLocalMap(LocalMap(size=size, cells=cells), FloorTables([scene], 0, radius, a))
    # The CPU's blocks of ``block`` worlds (one block when it is >= worlds).
    with mock.patch.object(local_map_module, "CPU_BLOCK", block * n_robots * cells * cells):
        got = a.numpy(lm.values(a.asarray(np.zeros(worlds), a.i64), a.asarray(x), a.asarray(y), a.asarray(yaw),
                                a.asarray(present, a.boolean), a.asarray(radii) if own_radii else radius))
    assert got.shape == (worlds, n_robots, cells * cells)
    for w in range(worlds):
        for i in range(n_robots):
            discs = [(x[w, j], y[w, j], radii[w, j]) for j in range(n_robots) if j != i and present[w, j]]
            want, ties = reference_map(scene, x[w, i], y[w, i], yaw[w, i], discs, size, cells)
            bad = (got[w, i] != want) & ~ties
            assert not bad.any(), f"world {w}, robot {i}: cells {np.flatnonzero(bad)}: {got[w, i][bad]} vs {want[bad]}"
