"""Several robots per world in the batched engine: shapes, the active mask by hand, bad input."""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest
from fleet_reference import compare_fleet, fleet_episodes

from pointnav_core.floor.maps import OBSTACLE, VOID
from pointnav_core.scenes import Scene
from pointnav_core.vector import VectorPointNavEnv

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])
INFO_KEYS = ("success", "spl", "soft_spl", "path_length", "geodesic_dist", "distance_to_goal", "collisions",
             "episode_length", "in_contact", "reward_potential", "reward_collision", "reward_pointgoal",
             "autoreset", "active")


def room(rows: int = 30, cols: int = 40) -> Scene:
    grid = np.zeros((rows, cols), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return Scene.from_array(grid, 0.1)


# Robot 0 faces its goal 0.52 m ahead (tolerance 0.2 m, 0.05 m a step): 0.17 m are left
# after 7 steps, at x = 1.35. Robot 1 stands 0.85 m further on, facing it, with a far goal.
HEAD_ON = [[((1.0, 1.5), 0.0, (1.52, 1.5)), ((2.2, 1.5), math.pi, (1.0, 2.5))]]
TASK = {"goal_tolerance": 0.2}


@pytest.mark.parametrize("device", DEVICES)
def test_shapes_and_types(device: str) -> None:
    env = VectorPointNavEnv(3, n_robots=4, scene=room(), task=TASK, device=device, seed=0, pool_size=2)
    assert isinstance(env, VectorPointNavEnv)
    assert env.observation_space.shape == (3, 4, 8) and env.action_space.shape == (3, 4, 2)
    to_np = env.arrays.numpy
    obs, info = env.reset()
    assert to_np(obs).shape == (3, 4, 8) and to_np(obs).dtype == np.float32
    assert sorted(info) == sorted(INFO_KEYS) and all(to_np(v).shape == (3, 4) for v in info.values())
    assert to_np(info["active"]).all()
    obs, reward, terminated, truncated, info = env.step(np.zeros((3, 4, 2)))
    assert to_np(obs).shape == (3, 4, 8) and to_np(obs).dtype == np.float32
    assert to_np(reward).dtype == np.float64 and to_np(reward).shape == (3, 4)
    assert to_np(terminated).dtype == np.bool_ and to_np(truncated).dtype == np.bool_
    assert to_np(info["active"]).dtype == np.bool_ and to_np(info["episode_length"]).tolist() == [[1] * 4] * 3
    # Starts and goals came from the multi-robot env's sampler: apart by its rules.
    p = env.pool
    sx, sy, gx, gy = (to_np(v) for v in (p.sx, p.sy, p.gx, p.gy))
    for e in range(len(p)):
        for i in range(4):
            for j in range(i):
                assert math.dist((sx[e, i], sy[e, i]), (sx[e, j], sy[e, j])) >= 2 * 0.18
                assert math.dist((gx[e, i], gy[e, i]), (gx[e, j], gy[e, j])) >= max(0.4, 0.36, 0.1)


def test_one_robot_keeps_the_one_robot_engine() -> None:
    env = VectorPointNavEnv(2, scene=room(), pool_size=1, seed=0)
    assert type(env) is VectorPointNavEnv
    assert env.reset()[0].shape == (2, 8)


@pytest.mark.parametrize("device", DEVICES)
def test_a_parked_robot_blocks_until_the_world_resets(device: str) -> None:
    env = VectorPointNavEnv(1, n_robots=2, scene=room(), task=TASK, device=device, max_cycles=20)
    to_np = env.arrays.numpy
    first, _ = env.reset(options={"episodes": HEAD_ON})
    arrive, drive = [[1.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [1.0, 0.0]]
    for step in range(1, 8):
        obs, reward, terminated, _, info = env.step(np.array([arrive]))
        assert to_np(terminated)[0].tolist() == [step == 7, False]
        assert to_np(info["active"])[0].tolist() == [step < 7, True]
    assert to_np(info["success"])[0].tolist() == [True, False]
    assert abs(float(to_np(env.state.x)[0, 0]) - 1.35) < 1e-9
    # Robot 0 is no agent any more: its action is ignored and its entries are zero.
    for step in range(8, 21):
        obs, reward, terminated, truncated, info = env.step(np.array([drive]) + [[1.0, 1.0], [0.0, 0.0]])
        assert (to_np(obs)[0, 0] == 0.0).all() and to_np(reward)[0, 0] == 0.0
        assert not to_np(info["active"])[0, 0] and to_np(info["episode_length"])[0, 0] == 0
        # Robot 1 closes 0.85 m to 0.36 m (two radii) in 9.8 steps, then rests on robot 0.
        assert bool(to_np(info["in_contact"])[0, 1]) == (step >= 17)
    x1 = float(to_np(env.state.x)[0, 1])
    assert abs(x1 - (1.35 + 0.36)) < 1e-8
    assert to_np(info["collisions"])[0, 1] == 4
    # max_cycles = 20: robot 1 is truncated, no robot is left, the next step resets the world.
    assert to_np(truncated)[0].tolist() == [False, True] and not to_np(info["active"]).any()
    obs, reward, terminated, truncated, info = env.step(np.array([drive]))
    assert to_np(info["autoreset"]).all() and to_np(info["active"]).all()
    np.testing.assert_array_equal(to_np(obs), to_np(first))
    assert (to_np(reward) == 0.0).all() and not to_np(terminated).any() and not to_np(truncated).any()


@pytest.mark.parametrize("device", DEVICES)
def test_a_removed_robot_lets_the_others_pass(device: str) -> None:
    env = VectorPointNavEnv(1, n_robots=2, scene=room(), task=TASK, device=device, finished="remove")
    to_np = env.arrays.numpy
    env.reset(options={"episodes": HEAD_ON})
    for _ in range(7):
        env.step(np.array([[[1.0, 0.0], [0.0, 0.0]]]))
    for _ in range(13):
        _, _, _, _, info = env.step(np.array([[[0.0, 0.0], [1.0, 0.0]]]))
        assert not to_np(info["in_contact"]).any()
    assert abs(float(to_np(env.state.x)[0, 1]) - (2.2 - 13 * 0.05)) < 1e-9  # through robot 0's place


SCAN = {"scan": {"n_rays": 4, "fov": 2 * math.pi, "max_range": 5.6}}  # bearings -pi, -pi/2, 0, pi/2


@pytest.mark.parametrize("device", DEVICES)
def test_scan_shapes_and_bounds(device: str) -> None:
    env = VectorPointNavEnv(3, n_robots=4, scene=room(), task=TASK, sensors=SCAN, device=device, seed=0, pool_size=2)
    assert env.observation_space.shape == (3, 4, 12)
    assert (env.single_observation_space.high[8:] == np.float32(5.6)).all()
    assert (env.single_observation_space.low[8:] == 0.0).all()
    obs, _ = env.reset()
    for _ in range(3):
        obs, *_ = env.step(np.random.default_rng(0).uniform(-1, 1, (3, 4, 2)))
        got = env.arrays.numpy(obs)
        assert got.shape == (3, 4, 12) and got.dtype == np.float32
        assert (got[..., 8:] >= 0.0).all() and (got[..., 8:] <= np.float32(5.6)).all()


@pytest.mark.parametrize("finished", ["park", "remove"])
@pytest.mark.parametrize("device", DEVICES)
def test_scans_see_the_other_robot_until_it_leaves(device: str, finished: str) -> None:
    # HEAD_ON in a room whose free floor spans x, y in [0.1, 3.9] x [0.1, 2.9] m; radius 0.18 m.
    env = VectorPointNavEnv(1, n_robots=2, scene=room(), task=TASK, sensors=SCAN, device=device, finished=finished)
    to_np = env.arrays.numpy
    obs = to_np(env.reset(options={"episodes": HEAD_ON})[0])[0, :, 8:]
    # Each looks ahead at the other's disc, 1.2 m between centres; robot 0 behind at the wall
    # 0.9 m away, robot 1 1.7 m, both 1.4 m from the side walls.
    np.testing.assert_allclose(obs[0], [0.9, 1.4, 1.2 - 0.18, 1.4], atol=1e-6)
    np.testing.assert_allclose(obs[1], [3.9 - 2.2, 1.4, 1.2 - 0.18, 1.4], atol=1e-6)
    for _ in range(7):  # robot 0 arrives at x = 1.35 and finishes in the 7th step
        obs = to_np(env.step(np.array([[[1.0, 0.0], [0.0, 0.0]]]))[0])[0, :, 8:]
    assert abs(obs[1, 2] - (2.2 - 1.35 - 0.18)) < 1e-6  # still seen in the step it finished
    obs = to_np(env.step(np.array([[[0.0, 0.0], [0.0, 0.0]]]))[0])[0, :, 8:]
    assert (obs[0] == 0.0).all()  # no agent any more
    # Parked, it is still in the way; removed, robot 1 sees the far wall at x = 0.1 m.
    want = 2.2 - 1.35 - 0.18 if finished == "park" else 2.2 - 0.1
    assert abs(obs[1, 2] - want) < 1e-6


def test_noisy_scans_repeat_with_the_seed_and_change_no_episode() -> None:
    noisy = {"scan": {"n_rays": 8, "noise_std": 0.05, "dropout": 0.1}}
    actions = np.random.default_rng(3).uniform(-1, 1, (12, 2, 3, 2))

    def run(sensors: dict) -> np.ndarray:
        env = VectorPointNavEnv(2, n_robots=3, scene=room(), task=TASK, sensors=sensors, seed=5, pool_size=2)
        out = [env.reset(seed=7)[0]]
        out += [env.step(a)[0] for a in actions]
        return np.stack(out)

    first, again, exact = run(noisy), run(noisy), run({"scan": {"n_rays": 8}})
    np.testing.assert_array_equal(first, again)
    np.testing.assert_array_equal(first[..., :8], exact[..., :8])  # the same episodes and motion
    seen = exact[..., 8:] < np.float32(5.6)  # noise only on returns; dropout reads max_range
    assert (first[..., 8:][seen] != exact[..., 8:][seen]).mean() > 0.5
    assert (first[..., 8:][~seen] == np.float32(5.6)).all()


@pytest.mark.parametrize("sensors", [None, {"scan": {"n_rays": 12, "max_range": 2.0, "min_range": 0.05}}])
@pytest.mark.parametrize("device", DEVICES)
def test_crowded_worlds_match_parallel_envs(device: str, sensors: dict | None) -> None:
    # A 1.6 x 2 m room, four robots each: they meet each other and the parked ones often;
    # a hole at one end takes robots that drive into it out of the world.
    rng = np.random.default_rng(1)
    grid = np.zeros((20, 16), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[5, 5] = OBSTACLE
    grid[16:19, 1:15] = VOID
    scene = Scene.from_array(grid, 0.1)
    actions = rng.uniform(-1.2, 1.2, (150, 4, 4, 2)).astype(np.float32)
    actions[rng.random((150, 4, 4)) < 0.5, 0] = 1.0
    task = {"reward_type": "geodesic", "goal_tolerance": 0.2, "termination_config": {"max_steps": 60, "max_collisions": 10}}
    for finished in ("park", "remove"):
        stats = compare_fleet(scene, fleet_episodes(scene, 4, 4, rng), actions, task=task, device=device,
                              finished=finished, max_cycles=45, sensors=sensors)
        # The run exercised what it claims to: robot contacts, parked robots, ends, autoresets.
        assert stats["robot_contacts"] > 10 and stats["parked_steps"] > 100
        assert stats["successes"] > 0 and stats["autoresets"] > 0 and stats["falls"] > 0


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("actions", [np.zeros((2, 2)), np.zeros((2, 3, 2)), np.zeros((2, 2, 3)), np.zeros((3, 2, 2)),
                                     np.zeros((2, 2, 2)) + [[[np.nan, 0.0], [0.0, 0.0]]] * 2,
                                     np.zeros((2, 2, 2)) + [[[0.0, 0.0], [0.0, np.inf]]] * 2])
def test_bad_actions_are_refused(device: str, actions: np.ndarray) -> None:
    env = VectorPointNavEnv(2, n_robots=2, scene=room(), task=TASK, device=device, pool_size=1, seed=0)
    env.reset()
    before = env.arrays.numpy(env.state.x)
    with pytest.raises(ValueError, match="actions"):
        env.step(actions)
    np.testing.assert_array_equal(env.arrays.numpy(env.state.x), before)


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"n_robots": 2, "finished": "vanish"}, "finished"), ({"n_robots": 2, "max_cycles": 0}, "max_cycles"),
    ({"max_cycles": 10}, "max_cycles"), ({"finished": "park"}, "finished"),
    ({"n_robots": 2, "sensors": {"lidar": {}}}, "sensors"), ({"n_robots": 2, "pool_size": 0}, "pool_size"),
    ({"n_robots": 2, "robot": [{}, {"drive": "holonomic"}]}, "robot"), ({"n_robots": 2, "device": "tpu"}, "device"),
])
def test_unsupported_arguments_are_named(kwargs: dict, name: str) -> None:
    with pytest.raises(ValueError, match=name):
        VectorPointNavEnv(**{"num_envs": 1, "scene": room(), "task": TASK, **kwargs})


@pytest.mark.parametrize(("episode", "words"), [
    ([((1.0, 1.5), 0.0, (1.5, 1.5))], "one .* per robot"),
    ([((1.0, 1.5), 0.0, (1.5, 1.5)), ((1.2, 1.5), 0.0, (2.5, 2.5))], "start overlapping"),
    ([((1.0, 1.5), 0.0, (1.5, 1.5)), ((2.0, 1.5), 0.0, (1.5, 1.8))], "goals"),
    ([((1.0, 1.5), 0.0, (1.5, 1.5)), ((0.05, 1.5), 0.0, (2.5, 2.5))], "not usable"),
])
def test_bad_fixed_episodes_are_refused(episode: list, words: str) -> None:
    env = VectorPointNavEnv(1, n_robots=2, scene=room(), task=TASK)
    with pytest.raises(ValueError, match=r"options\['episodes'\]\[0\].*" + words):
        env.reset(options={"episodes": [episode]})


def test_fields_without_labels_after_fields_with_labels() -> None:
    # A goal behind a wall has labels (the way round it); one in open floor has none.
    from pointnav_core.vector.fields import FieldTables
    from pointnav_core.vector.xp import make_arrays

    grid = np.zeros((30, 30), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[15, 1:25] = OBSTACLE
    behind = Scene.from_array(grid, 0.1).goal_field(0, (0.5, 2.5), robot=0.18)
    open_floor = room(30, 30).goal_field(0, (2.0, 0.6), robot=0.18)
    assert len(behind.field.labels.node) > 0 and len(open_floor.field.labels.node) == 0
    tables = FieldTables([behind.field, open_floor.field], make_arrays("numpy"))
    x, y = np.array([0.5, 2.0]), np.array([0.6, 1.0])
    got = tables.distance(np.array([0, 1]), x, y)
    # From (0.5, 0.6) round the wall's end at x = 2.5 and back, at least the two legs' straight parts.
    assert got[0] > math.dist((0.5, 0.6), (2.5, 1.5)) + math.dist((2.5, 1.6), (0.5, 2.5))
    assert abs(got[1] - 0.4) < 1e-12  # straight to the goal


def test_starts_per_goal_share_each_episodes_goals_with_exact_geodesics() -> None:
    env = VectorPointNavEnv(3, n_robots=3, scene=room(), seed=1, pool_size=2, starts_per_goal=4, task=TASK)
    env.reset()
    pool, r = env.pool, 3
    assert len(pool) == 8 and pool.pool_size == 8
    sx, sy, gx, gy, d0, field = (np.asarray(v) for v in (pool.sx, pool.sy, pool.gx, pool.gy, pool.d0, pool.field))
    for g in range(2):  # each goal set's four episodes share its goals and goal fields
        block = slice(4 * g, 4 * g + 4)
        assert (gx[block] == gx[4 * g]).all() and (gy[block] == gy[4 * g]).all()
        assert (field[block] == field[4 * g]).all()
    assert len(set(field.ravel().tolist())) == 2 * r  # one field per sampled robot goal
    # Every set of starts is clear: the robots' discs do not overlap.
    for e in range(8):
        for i in range(r):
            for j in range(i + 1, r):
                assert math.hypot(sx[e, i] - sx[e, j], sy[e, i] - sy[e, j]) >= 2 * 0.18 - 1e-9
    # An empty room: the geodesic is the straight line; each robot's within its path_range.
    np.testing.assert_allclose(d0, np.hypot(gx - sx, gy - sy), atol=1e-9)
    for i, task in enumerate(env._samplers[0].tasks):
        low, high = task.path_range
        assert (d0[:, i] > low).all() and (d0[:, i] < high).all()
    assert len({(round(x, 9), round(y, 9)) for x, y in zip(sx.ravel(), sy.ravel())}) == 8 * r  # distinct starts


@pytest.mark.parametrize("device", DEVICES)
def test_starts_per_goal_episodes_play_on_their_goal_fields(device: str) -> None:
    # An empty room: every geodesic is the straight line, whichever start set or refreshed
    # pool an episode came from.
    env = VectorPointNavEnv(4, n_robots=2, scene=room(), device=device, seed=2, pool_size=1, starts_per_goal=3,
                            task={**TASK, "reward_type": "geodesic"}, max_cycles=2)
    env.reset()
    to_np = env.arrays.numpy
    for t in range(8):
        if t in (1, 4):
            env.refresh_pool(wait=True)
        _, _, _, _, info = env.step(np.tile([1.0, 0.3], (4, 2, 1)))
        st = env.state
        x, y, gx, gy = (to_np(v) for v in (st.x, st.y, st.goal_x, st.goal_y))
        active = to_np(info["active"]) | to_np(info["autoreset"])
        want = np.hypot(gx - x, gy - y)
        np.testing.assert_allclose(to_np(info["distance_to_goal"])[active], want[active], atol=1e-9)
    assert env.pool.pool_size == 3  # the refreshed pool holds three sets of starts per goal set too
