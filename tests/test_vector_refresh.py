"""Fresh episodes while the worlds run (``refresh_pool``), and the joined goal fields."""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest

from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.vector import VectorPointNavEnv
from pointnav_core.vector.fields import FieldTables
from pointnav_core.vector.xp import make_arrays

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])


def walled_room() -> Scene:
    # 4 x 3 m, a wall from the bottom up to y = 2 m at x = 2 m: geodesics bend round it.
    grid = np.zeros((30, 40), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[:20, 20] = OBSTACLE
    return Scene.from_array(grid, 0.1)


@pytest.mark.parametrize("device", DEVICES)
def test_joined_field_tables_answer_as_their_parts_and_as_straight_lines(device: str) -> None:
    scene, spec = walled_room(), RobotSpec()
    goals = [(0.6, 0.6), (3.4, 0.6), (1.0, 2.5)]
    fields = [scene.goal_field(0, g, robot=spec) for g in goals]
    a = make_arrays(device)
    first, second = FieldTables([f.field for f in fields[:2]], a), FieldTables([fields[2].field], a)
    joined = FieldTables.concat(first, second)
    rng = np.random.default_rng(0)
    xy = rng.uniform([0.3, 0.3], [3.7, 2.7], (300, 2))
    xy = xy[[scene.is_usable(0, p, spec) for p in xy]]
    n = len(xy)
    for f, (table, index) in enumerate([(first, 0), (first, 1), (second, 0)]):
        idx = a.asarray(np.full(n, index), a.i64)
        part = a.numpy(table.distance(idx, a.asarray(xy[:, 0]), a.asarray(xy[:, 1])))
        got = a.numpy(joined.distance(a.asarray(np.full(n, f), a.i64), a.asarray(xy[:, 0]), a.asarray(xy[:, 1])))
        np.testing.assert_array_equal(got, part)
        # Points on the goal's side of the wall's top (y > 2.3 m, or the goal's own half
        # below it) see the goal: the geodesic is the straight line.
        gx, gy = goals[f]
        seen = (xy[:, 1] > 2.3) & (gy > 2.3) | ((xy[:, 0] < 1.7) == (gx < 1.7)) & ((xy[:, 0] < 1.7) | (xy[:, 0] > 2.3))
        np.testing.assert_allclose(got[seen], np.hypot(xy[seen, 0] - gx, xy[seen, 1] - gy), atol=1e-9)
        assert (got[~seen] >= np.hypot(xy[~seen, 0] - gx, xy[~seen, 1] - gy) - 1e-9).all()


def _run(env: VectorPointNavEnv, actions: np.ndarray, refresh_at: int | None = None, wait: bool = True):
    to_np = env.arrays.numpy
    obs, _ = env.reset(seed=3)
    rows = [(to_np(obs), None, None, None, None)]
    for t, act in enumerate(actions):
        if t == refresh_at:
            env.refresh_pool(wait=wait)
            if not wait:  # the build runs beside the steps; here it is ready by the next one
                assert env._refresh is not None
                env._refresh.wait()
        obs, reward, terminated, truncated, info = env.step(env.arrays.asarray(act))
        rows.append((
            to_np(obs), to_np(reward), to_np(terminated | truncated), to_np(info["geodesic_dist"]),
            to_np(info["distance_to_goal"]),
        ))
    return rows


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("wait", [True, False])
def test_a_refresh_keeps_running_episodes_and_draws_new_ones_after(device: str, wait: bool) -> None:
    make = lambda: VectorPointNavEnv(
        6, scene=walled_room(), device=device, seed=1, pool_size=3,
        task={"termination_config": {"max_steps": 12}, "reward_type": "geodesic"},
    )
    actions = np.random.default_rng(5).uniform(-1, 1, (60, 6, 2))
    plain, refreshed = make(), make()
    base = _run(plain, actions)
    old_d0 = sorted(plain.arrays.numpy(plain.pool.d0).tolist())
    got = _run(refreshed, actions, refresh_at=5, wait=wait)
    # Every world runs the very same episode until its first end after the refresh.
    ended = np.zeros(6, bool)
    for t in range(1, len(base)):
        same = ~ended
        np.testing.assert_array_equal(got[t][0][same], base[t][0][same])
        np.testing.assert_array_equal(got[t][1][same], base[t][1][same])
        np.testing.assert_array_equal(got[t][4][same], base[t][4][same])  # by the goal's field
        if t > 5:
            ended |= base[t][2]
    assert ended.all(), "every world should have ended an episode (max_steps 12)"
    # The old episodes are gone once no world runs one: the pool is the new one alone,
    # of the same size, with other episodes, and the later episodes come from it.
    pool = refreshed.pool
    assert refreshed._old_from is None and len(pool) == 3
    new_d0 = refreshed.arrays.numpy(pool.d0)
    assert sorted(new_d0.tolist()) != old_d0
    late = got[-1][3]
    assert np.isin(late, new_d0).all()
    if not wait:  # the worker's pool is the one the same seeds give here
        np.testing.assert_array_equal(new_d0, plain_refreshed(make))
    refreshed.close()


def plain_refreshed(make) -> np.ndarray:
    env = make()
    actions = np.random.default_rng(5).uniform(-1, 1, (6, 6, 2))
    _run(env, actions, refresh_at=5, wait=True)
    return env.arrays.numpy(env._fresh.d0 if env._fresh is not None else env.pool.d0)


@pytest.mark.parametrize("device", DEVICES)
def test_several_robots_refresh_too(device: str) -> None:
    env = VectorPointNavEnv(
        3, n_robots=2, scene=walled_room(), device=device, seed=0, pool_size=2, max_cycles=8
    )
    env.reset(seed=0)
    before = env.arrays.numpy(env.pool.d0).copy()
    env.refresh_pool(wait=True)
    assert len(env.pool) == 4  # the new episodes, then the old ones still run
    for _ in range(10):  # max_cycles 8: every world ends and resets
        env.step(np.zeros((3, 2, 2)))
    assert len(env.pool) == 2 and not np.array_equal(env.arrays.numpy(env.pool.d0), before)


def test_refresh_is_refused_before_reset_and_with_fixed_episodes() -> None:
    env = VectorPointNavEnv(1, scene=walled_room(), seed=0, pool_size=1)
    with pytest.raises(RuntimeError, match="reset"):
        env.refresh_pool()
    env.reset(options={"episodes": [((0.6, 0.6), 0.0, (1.0, 2.5))]})
    with pytest.raises(ValueError, match="fixed episodes"):
        env.refresh_pool()
    env.reset()  # back to pools: a refresh is accepted
    env.refresh_pool(wait=True)
    assert not math.isnan(float(env.arrays.numpy(env.pool.d0)[0]))
