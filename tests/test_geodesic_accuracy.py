"""Accuracy of get_shortest_path against the exact continuous geodesic (issue: foundation).

Floor plans with walls, door gaps and rotated furniture are built with shapely, rasterised
with ``Scene.from_polygons`` at 0.05 m, and every distance is compared with the exact
visibility-graph geodesic computed here from the same polygons grown by the robot radius.
"""

import numpy as np
import shapely
from geodesic_reference import ContinuousGeodesic, house_plan

from pointnav_core.scenes import Scene

RADIUS = 0.2


def relative_errors(seeds=(0, 1, 2), pairs_per_plan=70):
    errors = []
    for seed in seeds:
        outline, obstacles = house_plan(seed)
        reference = ContinuousGeodesic(outline, obstacles, RADIUS)
        scene = Scene.from_polygons(outline, obstacles, resolution=0.05)
        rng = np.random.default_rng(seed)
        done = 0
        while done < pairs_per_plan:
            _, start = scene.get_random_point(0, robot=RADIUS, rng=rng)
            _, goal = scene.get_random_point(0, reference_point=start, robot=RADIUS, rng=rng)
            start = start[:2] + rng.uniform(-0.02, 0.02, 2)
            goal = goal[:2] + rng.uniform(-0.02, 0.02, 2)
            if not all(shapely.contains_xy(reference.free, *p) for p in (start, goal)):
                continue
            exact = reference.distance(start, goal)
            if exact < 0.5:
                continue
            _, dist = scene.get_shortest_path(0, start, goal, entire_path=True, robot=RADIUS)
            assert dist is not None
            errors.append(abs(dist - exact) / exact)
            done += 1
    return np.array(errors)


def test_geodesic_matches_continuous_reference_within_half_a_percent():
    errors = relative_errors()
    assert len(errors) >= 200
    assert np.median(errors) <= 0.005, np.median(errors)
    assert np.percentile(errors, 95) <= 0.010, np.percentile(errors, 95)
