"""The episode generator obeys Habitat's rules, checked against references written here."""

from __future__ import annotations

import math
from collections import deque

import numpy as np
import pytest

from pointnav_core import SamplingError, Scene
from pointnav_core.datasets import (
    EpisodeDataset,
    GeneratorConfig,
    generate_episodes,
    island_radius,
)

RES = 0.1
RADIUS = 0.18


def _island_grid() -> np.ndarray:
    """4 x 7 m: a 3.8 m square room, and behind a wall a 2.8 x 1.1 m pocket (an island)."""
    free = np.zeros((40, 70), bool)
    free[1:39, 1:39] = True
    free[1:12, 41:69] = True
    return free


def _divided_grid() -> np.ndarray:
    """8 x 8 m room with a wall across half of it, so geodesic/euclidean ratios vary."""
    free = np.zeros((80, 80), bool)
    free[1:79, 1:79] = True
    free[39:41, 1:50] = False
    return free


def _pillar_grid() -> np.ndarray:
    """7 x 7 m room with a grid of 0.3 m pillars: most ratios fall between 1.0 and 1.1."""
    free = np.zeros((70, 70), bool)
    free[1:69, 1:69] = True
    for r in range(8, 66, 10):
        for c in range(8, 66, 10):
            free[r : r + 3, c : c + 3] = False
    return free


def _reference_usable(free: np.ndarray, radius: float) -> np.ndarray:
    """Free cells whose centre is at least ``radius`` from every blocked cell square."""
    rows, cols = np.nonzero(~free)
    x0, y0 = cols * RES, rows * RES
    usable = np.zeros_like(free)
    for r, c in zip(*np.nonzero(free)):
        px, py = (c + 0.5) * RES, (r + 0.5) * RES
        dx = np.maximum(np.maximum(x0 - px, px - (x0 + RES)), 0.0)
        dy = np.maximum(np.maximum(y0 - py, py - (y0 + RES)), 0.0)
        usable[r, c] = np.hypot(dx, dy).min() >= radius
    return usable


def _flood_islands(usable: np.ndarray) -> tuple[np.ndarray, dict[int, float]]:
    """8-connected flood fill of usable cells; radius of each island about its centroid."""
    labels = np.zeros(usable.shape, int)
    radii: dict[int, float] = {}
    n = 0
    for seed in zip(*np.nonzero(usable)):
        if labels[seed]:
            continue
        n += 1
        labels[seed] = n
        queue, cells = deque([seed]), [seed]
        while queue:
            r, c = queue.popleft()
            for dr in (-1, 0, 1):
                for dc in (-1, 0, 1):
                    q = (r + dr, c + dc)
                    if (
                        0 <= q[0] < usable.shape[0]
                        and 0 <= q[1] < usable.shape[1]
                        and usable[q]
                        and not labels[q]
                    ):
                        labels[q] = n
                        queue.append(q)
                        cells.append(q)
        pts = (np.array(cells)[:, ::-1] + 0.5) * RES
        radii[n] = float(np.hypot(*(pts - pts.mean(axis=0)).T).max())
    return labels, radii


def _cell(xy) -> tuple[int, int]:
    return int(math.floor(xy[1] / RES)), int(math.floor(xy[0] / RES))


def test_no_start_or_goal_on_a_small_island():
    free = _island_grid()
    labels, radii = _flood_islands(_reference_usable(free, RADIUS))
    assert len(radii) == 2
    small = [k for k, r in radii.items() if r < 1.5]
    assert len(small) == 1  # the pocket: the rule has something to reject
    scene = Scene.from_array(free, RES)
    # The ratio filter is off here (threshold 1): this test is about islands, and it is fast.
    episodes = generate_episodes(
        scene, "islands", 60, seed=1, config=GeneratorConfig(ratio_threshold=1.0)
    )
    for ep in episodes:
        assert radii[labels[_cell(ep.start_xy)]] >= 1.5
        assert radii[labels[_cell(ep.goal_xy)]] >= 1.5
    # The library's island radius is the reference's, for both islands.
    for label, reference in radii.items():
        r, c = np.argwhere(labels == label)[0]
        assert island_radius(scene, 0, ((c + 0.5) * RES, (r + 0.5) * RES), RADIUS) == pytest.approx(
            reference, abs=1e-9
        )
    # Without the rule, the pocket does get episodes (so the check above could fail).
    loose_rules = GeneratorConfig(island_radius_limit=0.0, ratio_threshold=1.0)
    loose = generate_episodes(scene, "islands", 60, seed=1, config=loose_rules)
    assert any(labels[_cell(ep.start_xy)] in small for ep in loose)


def test_distances_in_range_and_equal_to_the_library_geodesic():
    free = _divided_grid()
    config = GeneratorConfig(geodesic_range=(2.0, 6.0))
    episodes = generate_episodes(Scene.from_array(free, RES), "divided", 30, seed=2, config=config)
    fresh = Scene.from_array(free, RES)  # no caches shared with the generator's scene
    for ep in episodes:
        assert 2.0 <= ep.geodesic_distance <= 6.0
        _, length = fresh.get_shortest_path(
            0, ep.start_xy, ep.goal_xy, entire_path=True, robot=RADIUS
        )
        assert abs(length - ep.geodesic_distance) <= 1e-6
        assert fresh.is_usable(0, ep.start_xy, RADIUS) and fresh.is_usable(0, ep.goal_xy, RADIUS)
        assert ep.robot_radius == RADIUS and ep.goal_radius == 0.5


def test_default_range_is_habitats():
    assert GeneratorConfig().geodesic_range == (1.0, 30.0)
    episodes = generate_episodes(Scene.from_array(_divided_grid(), RES), "divided", 20, seed=3)
    assert all(1.0 <= ep.geodesic_distance <= 30.0 for ep in episodes)


def test_ratio_filter_keep_rate_matches_habitat_formula():
    scene = Scene.from_array(_pillar_grid(), RES)
    stats: dict = {}
    episodes = generate_episodes(scene, "pillars", 50, seed=4, stats=stats)
    trials = stats["ratio_trials"]
    assert len(trials) > 400
    ratios = np.array([r for r, _ in trials])
    kept = np.array([k for _, k in trials], dtype=float)
    assert ratios.min() >= 1.0 - 1e-9 and ratios.max() < 1.1
    for lo, hi in ((1.0, 1.02), (1.02, 1.05), (1.05, 1.1), (1.0, 1.1)):
        sel = (ratios >= lo) & (ratios < hi)
        assert sel.sum() >= 100, (lo, hi, sel.sum())
        p = np.minimum(20.0 * (ratios[sel] - 0.98) ** 2, 1.0)  # Habitat's _ratio_sample_rate
        expected = p.mean()
        sigma = math.sqrt((p * (1 - p)).sum()) / sel.sum()
        assert abs(kept[sel].mean() - expected) <= 4 * sigma + 1e-3, (
            lo,
            hi,
            kept[sel].mean(),
            expected,
        )
    # Every kept low-ratio pair became an episode; the filter's counter adds up.
    assert stats["rejected"]["ratio filter"] == int((1 - kept).sum())
    low = [ep for ep in episodes if ep.geodesic_distance / math.dist(ep.start_xy, ep.goal_xy) < 1.1]
    assert len(low) == int(kept.sum())


def test_same_floor_and_floor_recorded():
    free = _divided_grid()
    scene = Scene.from_array([free, free[::-1].copy()], RES, heights=[0.0, 3.0])
    episodes = generate_episodes(scene, "two-floors", 40, seed=5)
    assert {ep.floor for ep in episodes} == {0, 1}
    for ep in episodes:
        height = 3.0 * ep.floor
        assert ep.start_position[2] == ep.goal_position[2] == height
        assert math.isfinite(
            scene.geodesic_distance(ep.floor, ep.start_xy, ep.goal_xy, robot=RADIUS)
        )


def test_start_yaw_is_random():
    episodes = generate_episodes(Scene.from_array(_divided_grid(), RES), "divided", 80, seed=6)
    yaws = np.array([ep.start_yaw for ep in episodes]) % (2 * math.pi)
    counts = np.histogram(yaws, bins=4, range=(0, 2 * math.pi))[0]
    assert counts.min() >= 8, counts
    for ep in episodes:
        qx, qy, qz, qw = ep.start_rotation
        assert qx == qy == 0.0 and math.hypot(qz, qw) == pytest.approx(1.0, abs=1e-12)


def test_same_seed_same_bytes_other_seed_other_bytes():
    def build(seed: int) -> bytes:
        scene = Scene.from_array(_divided_grid(), RES)
        return EpisodeDataset(generate_episodes(scene, "divided", 15, seed=seed)).to_bytes()

    assert build(7) == build(7)
    assert build(7) != build(8)


def test_stats_do_not_change_the_episodes():
    scene = Scene.from_array(_divided_grid(), RES)
    assert generate_episodes(scene, "d", 10, seed=9) == generate_episodes(
        scene, "d", 10, seed=9, stats={}
    )


def test_impossible_rules_raise_sampling_error():
    free = np.zeros((12, 12), bool)
    free[1:11, 1:11] = True  # 1 x 1 m: no geodesic reaches 1 m
    config = GeneratorConfig(max_goals_per_episode=20, island_radius_limit=0.0)
    with pytest.raises(SamplingError, match=r"episode 0 on scene 'tiny'.*geodesic out of range"):
        generate_episodes(Scene.from_array(free, RES), "tiny", 1, seed=0, config=config)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"geodesic_range": (5.0, 1.0)}, "min < max"),
        ({"geodesic_range": (True, 3.0)}, r"geodesic_range\[0\]"),
        ({"ratio_threshold": "1.1"}, "ratio_threshold"),
        ({"island_radius_limit": -1.0}, "island_radius_limit"),
        ({"retries_per_goal": 0}, "retries_per_goal"),
        ({"robot_radius": math.nan}, "robot_radius"),
    ],
)
def test_bad_config(kwargs, match):
    with pytest.raises(ValueError, match=match):
        GeneratorConfig(**kwargs)
