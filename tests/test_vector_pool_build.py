"""Pools over many scenes: each scene's part built in worker processes, the same arrays."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pointnav_core.errors import SamplingError
from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.utils.workers import usable_cores
from pointnav_core.vector import VectorPointNavEnv
from pointnav_core.vector.pool_build import PARALLEL_SCENES, pool_workers


def room(width: int, height: int = 25) -> Scene:
    # A walled room of ``width`` x ``height`` cells at 0.1 m, a wall half across its middle.
    grid = np.zeros((height, width), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[height // 2, : width // 2] = OBSTACLE
    return Scene.from_array(grid, 0.1)


def arrays(pool: object) -> dict[str, bytes]:
    """Every array of a pool, as bytes, and what its field tables answer: each field's
    distance at 9 points of every cell of its window (the tables' own arrays differ: a
    pool built here settles its cells as lookups land, in the order they land)."""
    out = {k: np.asarray(v).tobytes() for k, v in vars(pool).items() if isinstance(v, np.ndarray)}
    t = pool.fields
    for f in range(len(t)):
        rows, width = int(t.rows[f]), int(t.width[f])
        r, c = np.divmod(np.arange(rows * width), width)
        u = np.array([0.01, 0.5, 0.99])
        x = (t.col0[f] + c[:, None, None] + u[None, :, None] + 0 * u[None, None, :]).ravel() * t.res[f] + t.ox[f]
        y = (t.row0[f] + r[:, None, None] + 0 * u[None, :, None] + u[None, None, :]).ravel() * t.res[f] + t.oy[f]
        out[f"fields.distance {f}"] = np.asarray(t.distance(np.full(len(x), f), x, y)).tobytes()
    return out


@pytest.mark.parametrize(("n_robots", "disk_cache"), [(1, True), (2, True), (1, False)])
def test_a_pool_built_in_workers_answers_as_the_pool_built_here(n_robots: int, disk_cache: bool,
                                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    # With the geometry disk cache, a worker only samples and the fields settle here as
    # lookups land (each made again from its scene's sampler); without it the worker settles them.
    if not disk_cache:
        monkeypatch.setenv("POINTNAV_CACHE_DIR", "off")
    widths = (30, 40, 50)
    worlds = [room(w) for w in widths]
    kwargs = {"seed": 7, "pool_size": 2, "starts_per_goal": 2, "n_robots": n_robots, "progress": False}
    here = VectorPointNavEnv(6, scene=worlds, workers=1, **kwargs)
    there = VectorPointNavEnv(6, scene=worlds, workers=2, **kwargs)
    obs_here, _ = here.reset()
    obs_there, _ = there.reset()
    mine, theirs = arrays(here.pool), arrays(there.pool)
    assert mine.keys() == theirs.keys() and len(mine) > 10
    assert here.pool.fields.lazy and there.pool.fields.lazy == disk_cache
    for key in mine:
        assert mine[key] == theirs[key], key
    np.testing.assert_array_equal(obs_here, obs_there)
    # The parts are in scene order: every episode lies inside its own room (walls at 0.1 m).
    pool = here.pool
    scene = np.asarray(pool.scene) if n_robots == 1 else np.repeat(np.arange(3), 4)[:, None]
    for xs in (np.asarray(pool.sx), np.asarray(pool.gx)):
        assert np.all(xs < 0.1 * (np.asarray(widths)[scene] - 1)) and np.all(xs > 0.1)
    assert np.all(np.asarray(pool.d0) >= np.hypot(np.asarray(pool.gx) - pool.sx, np.asarray(pool.gy) - pool.sy) - 1e-9)


def test_a_worker_error_names_its_scene_and_keeps_its_type() -> None:
    # The middle room is too small for the path range: its sampler gives up, in a worker as here.
    worlds = [room(60, 40), room(12, 12), room(60, 40)]
    task = {"path_range": (3.0, 4.0)}
    with pytest.raises(SamplingError):
        VectorPointNavEnv(2, scene=worlds, task=task, seed=0, pool_size=1, workers=1).reset()
    env = VectorPointNavEnv(2, scene=worlds, task=task, seed=0, pool_size=1, workers=2)
    with pytest.raises(SamplingError, match=r"^scene 1: "):
        env.reset()


def test_the_progress_bar_counts_the_scenes(capsys: pytest.CaptureFixture[str]) -> None:
    VectorPointNavEnv(2, scene=[room(30), room(40)], seed=0, pool_size=1, workers=1, progress=True).reset()
    err = capsys.readouterr().err
    assert "pool scenes" in err and "2/2" in err
    VectorPointNavEnv(2, scene=[room(30), room(40)], seed=0, pool_size=1, workers=1, progress=False).reset()
    assert "pool scenes" not in capsys.readouterr().err


def test_workers_default_to_the_cores_for_many_scenes_and_are_checked() -> None:
    assert pool_workers(None, PARALLEL_SCENES - 1) == 1
    assert pool_workers(None, 100) == min(usable_cores(), 100)
    assert pool_workers(8, 3) == 3 and pool_workers(1, 50) == 1
    for bad in (0, -1, True, 2.0, "2"):
        with pytest.raises(ValueError, match="workers must be an integer >= 1"):
            VectorPointNavEnv(1, scene=room(30), workers=bad)
    for bad in ("yes", 1, math.nan):
        with pytest.raises(ValueError, match="progress must be None, True or False"):
            VectorPointNavEnv(1, scene=room(30), progress=bad)
