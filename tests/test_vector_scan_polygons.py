"""The batched engine's range scan on polygon floors (ProcTHOR houses, floor plans).

The single env's scan sees a floor's obstacle polygons edge by edge as well as its cells;
the batched scan calls the same definitions (``sensors.raycast.polygon_hits`` on the array
path, ``sensors._raycast_kernel.polygon_range`` compiled), so it is held equal to it bit
for bit, to one ``PointNavEnv`` per world step for step, and to a shapely reference.
"""

from __future__ import annotations

import functools
import importlib.util
from pathlib import Path

import numpy as np
import pytest
import shapely
from fleet_reference import compare_fleet, fleet_episodes
from scan_reference import assert_within, blocked_shapes, reference_ranges
from shapely import affinity
from vector_reference import compare, random_actions, random_episodes

from pointnav_core.scenes import Scene
from pointnav_core.sensors.raycast import ScanGeometry, cast_rays
from pointnav_core.vector.scan import ScanTables, cast_batch, compiled_available
from pointnav_core.vector.xp import make_arrays

HOUSE = Path(__file__).parent / "data" / "procthor" / "procthor_train_1.json"
TASK = {"reward_type": "geodesic", "termination_config": {"max_steps": 40, "max_collisions": 20}}
SCAN = {"scan": {"n_rays": 24, "max_range": 3.0, "noise_std": 0.01, "dropout": 0.05}}
DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])
compiled = pytest.mark.skipif(not compiled_available(), reason="polygon floors need the compiled contacts (numba)")


def random_plan(seed: int) -> Scene:
    """A 4 x 3 m room at 0.1 m with random turned boxes, thin walls and pillars (no cell
    under most of them: only their edges block)."""
    rng = np.random.default_rng(seed)
    parts = []
    for _ in range(6):
        x, y = rng.uniform(0.5, 3.5), rng.uniform(0.5, 2.5)
        w, h = rng.uniform(0.02, 0.5), rng.uniform(0.02, 0.5)
        box = shapely.box(x - w / 2, y - h / 2, x + w / 2, y + h / 2)
        parts.append(affinity.rotate(box, rng.uniform(0.0, 180.0)))
    parts.append(shapely.Point(rng.uniform(1, 3), rng.uniform(1, 2)).buffer(0.2, quad_segs=5))
    return Scene.from_polygons(shapely.box(0.0, 0.0, 4.0, 3.0), parts, resolution=0.1)


def inside_a_free_cell(scene: Scene) -> tuple[float, float]:
    """A point inside an obstacle polygon whose cell is not OBSTACLE (only the polygon can
    say it is inside: the single scan reads 0 there)."""
    tmap = scene.floors[0]
    codes, res, (ox, oy) = np.asarray(tmap.codes), tmap.resolution, tmap.origin
    for poly in tmap.collision.polygons:
        x0, y0, x1, y1 = poly.bounds
        for x in np.linspace(x0, x1, 23)[1:-1]:
            for y in np.linspace(y0, y1, 23)[1:-1]:
                if poly.contains(shapely.Point(x, y)) and codes[int((y - oy) // res), int((x - ox) // res)] != 1:
                    return float(x), float(y)
    raise AssertionError("no polygon point in a free cell")


@functools.cache
def floors() -> dict[str, Scene]:
    return {"procthor": Scene.from_procthor(HOUSE, resolution=0.1), "random": random_plan(7)}


@compiled
@pytest.mark.parametrize(("which", "device"), [("procthor", "numpy"), *(("random", d) for d in DEVICES)])
def test_polygon_floors_with_the_scan_match_single_envs(which: str, device: str) -> None:
    scene = floors()[which]
    assert len(scene.floors[0].collision.polygons)  # a polygon floor, not its cells
    rng = np.random.default_rng(3)
    stats = compare(scene, random_episodes(scene, 4, rng), random_actions(rng, (50, 4)), task=TASK, device=device,
                    sensors=SCAN)
    # Every observation (low_dim and the noisy scan, float32) equal within 1e-5.
    assert stats["obs_diff"] <= 1e-5, stats
    assert stats["ends"] >= 2, stats


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("method", ["array", "numba"])
def test_cast_batch_equals_the_single_scan_on_polygon_floors(method: str, device: str) -> None:
    if method == "numba" and not compiled_available():
        pytest.skip("numba is not installed")
    a = make_arrays(device)
    scenes = list(floors().values())
    tables = ScanTables(scenes, 0, a)
    rng = np.random.default_rng(1)
    w, r, angles, max_range = 6, 3, np.linspace(-np.pi, np.pi, 40, endpoint=False), 3.0
    scene = np.arange(w) % 2
    xy = np.array([[scenes[k].get_random_point(0, rng=rng)[1][:2] for _ in range(r)] for k in scene])
    # Robot 0 of world 0 inside a wall of the house; of world 1 inside a part of the plan
    # where no OBSTACLE cell is (only the polygon says it is inside).
    xy[0, 0] = scenes[0].floors[0].collision.polygons[0].representative_point().coords[0]
    xy[1, 0] = inside_a_free_cell(scenes[1])
    yaw = rng.uniform(-np.pi, np.pi, (w, r))
    present = np.ones((w, r), bool)
    present[2, 1] = False
    got = cast_batch(tables, a.asarray(scene, a.i64), a.asarray(xy[..., 0]), a.asarray(xy[..., 1]), a.asarray(yaw),
                     a.asarray(present, a.boolean), 0.18, a.asarray(angles), max_range, method=method)
    got = a.numpy(got) if a.is_torch else got
    geos = [ScanGeometry(one.floors[0]) for one in scenes]
    for i in range(w):
        geo = geos[scene[i]]
        seen = np.flatnonzero(present[i])
        discs = np.column_stack([xy[i, seen], np.full(len(seen), 0.18)])
        own = np.full(r, -1)
        own[seen] = np.arange(len(seen))
        ref = cast_rays(geo, xy[i], yaw[i], angles, max_range, discs=discs, own_disc=own, method="array")
        ref[~present[i]] = max_range
        assert np.array_equal(got[i], ref), (i, np.abs(got[i] - ref).max())
    assert (got[0, 0] == 0.0).all() and (got[1, 0] == 0.0).all()  # origins inside a polygon


@pytest.mark.parametrize("method", ["array", "numba"])
def test_the_batched_scan_sees_thin_walls_as_shapely_does(method: str) -> None:
    if method == "numba" and not compiled_available():
        pytest.skip("numba is not installed")
    scene = random_plan(7)
    tmap = scene.floors[0]
    shapes = blocked_shapes(tmap.codes, tmap.resolution, tmap.origin, tmap.collision.polygons)
    tables = ScanTables([scene], 0, make_arrays("numpy"))
    rng = np.random.default_rng(5)
    angles = np.linspace(-np.pi, np.pi, 32, endpoint=False)
    polygon_rays = 0
    for _ in range(4):
        p = np.asarray(scene.get_random_point(0, rng=rng)[1][:2])
        yaw = float(rng.uniform(-np.pi, np.pi))
        got = cast_batch(tables, np.zeros(1, np.int64), p[None, None, :1].reshape(1, 1), p[1:].reshape(1, 1),
                         np.full((1, 1), yaw), np.ones((1, 1), bool), 0.18, angles, 3.0, method=method)[0, 0]
        loose, strict = reference_ranges(shapes, p, yaw + angles, 3.0)
        assert_within(got, loose, strict, 1e-9)
        grid_only = cast_rays(ScanGeometry(Scene.from_array(tmap.codes, 0.1).floors[0]), p[None], [yaw], angles, 3.0)
        polygon_rays += int((got < grid_only[0] - 1e-3).sum())
    assert polygon_rays >= 5  # rays stopped by polygon edges that no cell covers


@compiled
def test_robots_scan_polygon_edges_and_each_other_as_parallel_envs_do() -> None:
    # Three robots a world: each scan sees the plan's edges and the other robots' discs.
    scene = random_plan(7)
    rng = np.random.default_rng(4)
    task = {"reward_type": "geodesic", "goal_tolerance": 0.2, "termination_config": {"max_steps": 40}}
    stats = compare_fleet(scene, fleet_episodes(scene, 2, 3, rng), random_actions(rng, (40, 2, 3)), task=task,
                          sensors=SCAN)
    assert stats["ends"] > 0, stats
