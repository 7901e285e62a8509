"""Unreachable pairs: one convention (``math.inf``) and a proof that costs two label lookups."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from shapely.geometry import box

from pointnav_core.floor import reachability
from pointnav_core.scenes import Scene


def split_scene() -> Scene:
    grid = np.ones((20, 20), bool)
    grid[:, 10] = False  # a wall from edge to edge: x in [1.0, 1.1] at 0.1 m cells
    return Scene.from_array(grid, resolution=0.1)


def test_every_query_says_inf_for_an_unreachable_pair():
    scene = split_scene()
    a, b = (0.5, 1.0), (1.6, 1.0)
    assert reachability.disconnected(scene.floors[0], 0.05, a, b)
    assert scene.get_shortest_path(0, a, b, robot=0.05) == (None, math.inf)
    assert scene.get_shortest_path(0, a, b, entire_path=True, robot=0.05) == (None, math.inf)
    assert scene.geodesic_distance(0, a, b, robot=0.05) == math.inf
    field = scene.goal_field(0, b, robot=0.05)
    assert field.distance(*a) == math.inf and field.exact_distance(a) == math.inf
    assert field.path(a) == (None, math.inf)
    # The same side: connected, and a finite length.
    assert not reachability.disconnected(scene.floors[0], 0.05, a, (0.5, 1.8))
    assert scene.geodesic_distance(0, a, (0.5, 1.8), robot=0.05) == pytest.approx(0.8)


def test_a_door_no_row_of_cell_centres_runs_through_is_not_cut():
    # A gap at y in [1.0, 1.37] in a wall at x in [1.0, 1.1]: a disc of radius 0.18 fits
    # only with its centre at y in [1.18, 1.19], where no cell centre (y = k / 10 + 0.05)
    # lies, so the cell components split here; the over-connected labels must not.
    scene = Scene.from_polygons(box(0, 0, 3, 3), [box(1.0, 0, 1.1, 1.0), box(1.0, 1.37, 1.1, 3.0)], 0.1)
    tmap = scene.floors[0]
    a, b = (0.5, 1.185), (1.6, 1.185)
    assert tmap.component_at(a, 0.18) != tmap.component_at(b, 0.18)  # the cells' split
    assert not reachability.disconnected(tmap, 0.18, a, b)
    assert math.isfinite(scene.geodesic_distance(0, a, b, robot=0.18))


def test_disconnected_is_never_claimed_for_a_pair_the_planner_joins():
    rng = np.random.default_rng(7)
    claimed = 0
    for _ in range(25):
        grid = rng.random((14, 14)) > 0.5
        scene = Scene.from_array(grid, resolution=0.1)
        tmap = scene.floors[0]
        radius = float(rng.choice([0.0, 0.08, 0.12, 0.16]))
        cells = np.argwhere(tmap.usable(radius))
        if len(cells) < 2:
            continue
        for _ in range(8):
            i, j = rng.choice(len(cells), 2, replace=False)
            a, b = tmap.cell_to_world(cells[i]), tmap.cell_to_world(cells[j])
            if reachability.disconnected(tmap, radius, a, b):
                claimed += 1
                points, _ = scene.planner(0, radius).shortest_path(a, b)  # no early exit there
                assert points is None, (a, b, radius)
    assert claimed > 10  # the check has teeth


def test_an_unreachable_pair_on_a_1024_map_is_answered_in_milliseconds():
    rng = np.random.default_rng(0)
    grid = rng.random((1024, 1024)) > 0.3
    grid[:, 500:504] = False
    scene = Scene.from_array(grid, resolution=0.05)
    tmap = scene.floors[0]
    reachability.reach_labels(tmap, 0.0)  # once per floor and radius (about 0.2 s)
    free = np.argwhere(tmap.usable(0.0))
    left, right = free[free[:, 1] < 500], free[free[:, 1] > 503]
    times = []
    for k in range(1, 6):
        a, b = tmap.cell_to_world(left[k * len(left) // 7]), tmap.cell_to_world(right[k * len(right) // 7])
        start = time.perf_counter()
        assert scene.get_shortest_path(0, a, b) == (None, math.inf)
        times.append(time.perf_counter() - start)
    assert np.median(times) < 0.010
