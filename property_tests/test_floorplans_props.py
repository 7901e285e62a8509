"""Properties of every generated floor plan, over seeds, sizes and generators."""

from __future__ import annotations

import numpy as np
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage

from pointnav_core import floorplans
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID, TraversableMap
from pointnav_core.testing.strategies import floor_plans

RESOLUTION = 0.1  # coarse enough to be quick, fine enough for 0.12 m walls
ROBOT_RADIUS = 0.2

# Each example generates and rasterises a whole plan (tens of milliseconds), so these run a
# half of the active profile's examples, and timing is no part of the property.
PLAN_SETTINGS = settings(max_examples=max(10, settings().max_examples // 2), deadline=None)


@PLAN_SETTINGS
@given(plan=floor_plans())
def test_every_plan_is_one_connected_free_region_inside_its_centred_outline(plan):
    for obstacle in plan.obstacles:
        assert plan.outline.covers(obstacle)
    xmin, ymin, xmax, ymax = plan.outline.bounds
    assert np.allclose([xmin + xmax, ymin + ymax], 0.0)

    codes, origin = plan.rasterize(RESOLUTION)
    assert (codes == FREE).any()
    usable = TraversableMap(codes, RESOLUTION, origin).usable(ROBOT_RADIUS)
    _, n_components = ndimage.label(usable)  # 4-connected, as the planner
    assert n_components == 1


@PLAN_SETTINGS
@given(plan=floor_plans())
def test_rasterised_cells_take_the_class_of_their_centre(plan):
    codes, origin = plan.rasterize(RESOLUTION)
    centres = TraversableMap(codes, RESOLUTION, origin).cell_to_world(np.argwhere(np.ones_like(codes)))
    x, y = centres[:, 0], centres[:, 1]
    # Reference: each obstacle on its own (prepared copies), not rasterize's union.
    obstacles = shapely.from_wkb(shapely.to_wkb(np.array(plan.obstacles, dtype=object)))
    shapely.prepare(obstacles)
    inside = shapely.intersects_xy(plan.outline, x, y)
    blocked = shapely.intersects_xy(obstacles[:, None], x, y).any(axis=0)
    expected = np.where(~inside, VOID, np.where(blocked, OBSTACLE, FREE)).reshape(codes.shape)
    assert np.array_equal(codes, expected)


@PLAN_SETTINGS
@given(kind=st.sampled_from(["rooms", "maze", "clutter"]), seed=st.integers(0, 2**32 - 1))
def test_the_same_seed_gives_the_same_plan(kind, seed):
    make = getattr(floorplans, kind)
    assert make(seed, size=(10.0, 10.0)) == make(seed, size=(10.0, 10.0))
