"""Discrete actions in the batched engine: hand-calculated moves, turns, contacts, STOP, bad input,
one robot per world and several.

The step-for-step comparisons with ``PointNavEnv(action_space="discrete")`` and with
``parallel_env(action_space="discrete")`` over random scenes are in
``property_tests/test_vector_props.py`` and ``property_tests/test_vector_fleet_props.py``.
"""

from __future__ import annotations

import importlib.util
import math

import gymnasium as gym
import numpy as np
import pytest

from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.vector import VectorPointNavEnv

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])
FORWARD, LEFT, RIGHT, STOP = 0, 1, 2, 3


def room(rows: int = 30, cols: int = 40) -> Scene:
    grid = np.zeros((rows, cols), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return Scene.from_array(grid, 0.1)


def make(n: int, device: str, stop: bool = True, **task: object) -> VectorPointNavEnv:
    return VectorPointNavEnv(n, scene=room(), device=device, action_space="discrete",
                             discrete_actions={"stop": stop}, task={"goal_in_polar": True, **task})


@pytest.mark.parametrize("device", DEVICES)
def test_forward_moves_then_stop_at_the_goal_by_hand(device: str) -> None:
    # Facing the goal 2 m ahead: each MOVE_FORWARD is 0.25 m, so after 7 the robot is 0.25 m
    # away (inside the 0.5 m tolerance); with STOP the episode goes on until STOP.
    env = make(2, device)
    to_np = env.arrays.numpy
    env.reset(options={"episodes": [((1.0, 1.5), 0.0, (3.0, 1.5))] * 2})
    total = np.zeros(2)
    for _ in range(7):
        obs, reward, terminated, truncated, info = env.step(np.array([FORWARD, FORWARD]))
        total += to_np(reward)
        assert not to_np(terminated).any() and not to_np(truncated).any()
    np.testing.assert_allclose(to_np(obs)[:, 0], 0.25, atol=1e-6)  # rho, m
    np.testing.assert_allclose(to_np(info["path_length"]), 1.75, atol=1e-9)
    # World 0 stops (a success), world 1 turns: it neither moves nor ends.
    obs, reward, terminated, _, info = env.step(np.array([STOP, LEFT]))
    total += to_np(reward)
    assert to_np(terminated).tolist() == [True, False]
    assert to_np(info["success"]).tolist() == [True, False]
    np.testing.assert_allclose(total[0], 1.75 + 10.0, atol=1e-9)  # geodesic progress + r_pointgoal
    np.testing.assert_allclose(to_np(info["spl"]), [1.0, 0.0])
    assert to_np(info["episode_length"]).tolist() == [8, 8]
    np.testing.assert_allclose(to_np(obs)[1, 1], -math.radians(10.0), atol=1e-6)  # the goal swung right
    np.testing.assert_allclose(to_np(info["path_length"])[1], 1.75, atol=1e-12)
    np.testing.assert_allclose(env.arrays.numpy(env.state.x)[1], 2.75, atol=1e-12)


@pytest.mark.parametrize("device", DEVICES)
def test_without_stop_reaching_the_goal_succeeds(device: str) -> None:
    env = make(1, device, stop=False)
    to_np = env.arrays.numpy
    env.reset(options={"episodes": [((1.0, 1.5), 0.0, (3.0, 1.5))]})
    ends = [bool(to_np(env.step(np.array([FORWARD]))[2])[0]) for _ in range(7)]
    assert ends == [False] * 6 + [True]


@pytest.mark.parametrize("device", DEVICES)
def test_a_move_into_a_wall_ends_at_the_contact(device: str) -> None:
    # Facing the wall x <= 0.1 m from x = 0.4 m: 0.12 m of free travel for a 0.18 m disc. The
    # control steps of 0.05 m reach 0.35, 0.30, then touch at 0.28; the move ends there.
    env = make(1, device, stop=False)
    to_np = env.arrays.numpy
    env.reset(options={"episodes": [((0.4, 1.5), math.pi, (3.0, 1.5))]})
    obs, reward, _, _, info = env.step(np.array([FORWARD]))
    np.testing.assert_allclose(to_np(env.state.x), [0.28], atol=1e-9)
    assert to_np(info["collisions"]).tolist() == [1] and to_np(info["in_contact"]).tolist() == [True]
    np.testing.assert_allclose(to_np(info["path_length"]), [0.12], atol=1e-9)
    np.testing.assert_allclose(to_np(obs)[0, 2], 0.2, atol=1e-6)  # the last control step: 0.02 m in 0.1 s
    np.testing.assert_allclose(to_np(reward), [-0.12 - 0.1], atol=1e-9)  # receding from the goal, one collision


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize(
    "actions",
    [np.array([0.0, 1.0]), np.array([0, 3]), np.array([-1, 0]), np.array([[0, 0]]), np.zeros((2, 2), np.int64),
     np.array([True, False]), [0.5, 1.0], np.array([0, 1, 2])],
)
def test_bad_discrete_actions_are_refused(device: str, actions: object) -> None:
    env = make(2, device, stop=False)
    env.reset(options={"episodes": [((1.0, 1.5), 0.0, (3.0, 1.5))] * 2})
    before = env.arrays.numpy(env.state.x)
    with pytest.raises(ValueError, match="actions"):
        env.step(actions)
    np.testing.assert_array_equal(env.arrays.numpy(env.state.x), before)


def test_discrete_actions_need_the_discrete_space() -> None:
    with pytest.raises(ValueError, match="discrete_actions"):
        VectorPointNavEnv(1, scene=room(), discrete_actions={"stop": False})
    with pytest.raises(ValueError, match="forward_step"):
        VectorPointNavEnv(1, scene=room(), action_space="discrete", discrete_actions={"forward_step": -1.0})


def test_starts_per_goal_share_goals_with_exact_geodesics() -> None:
    env = VectorPointNavEnv(3, scene=room(), seed=1, pool_size=2, starts_per_goal=5, action_space="discrete")
    env.reset()
    pool = env.pool
    assert len(pool) == 10 and pool.pool_size == 10
    goals = np.stack([pool.gx, pool.gy], 1)
    for g in range(2):  # each goal's five episodes share it (and its field)
        block = slice(5 * g, 5 * g + 5)
        assert (goals[block] == goals[5 * g]).all() and (pool.field[block] == g).all()
    # An empty room: the geodesic is the straight line; all within the derived path_range.
    straight = np.hypot(pool.gx - pool.sx, pool.gy - pool.sy)
    np.testing.assert_allclose(pool.d0, straight, atol=1e-9)
    low, high = env.task.path_range
    assert (pool.d0 > low).all() and (pool.d0 < high).all()
    assert len({(round(x, 9), round(y, 9)) for x, y in zip(pool.sx, pool.sy)}) == 10  # distinct starts


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize(("stop", "sensors"), [(True, None), (False, None), (False, {"scan": {"n_rays": 16}})])
def test_discrete_matches_single_envs_in_clutter(device: str, stop: bool, sensors: dict | None) -> None:
    from vector_reference import compare, random_episodes

    from pointnav_core.floor.maps import VOID

    rng = np.random.default_rng(11)
    grid = np.zeros((22, 28), np.uint8)
    grid[rng.random(grid.shape) < 0.1] = OBSTACLE
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[10:13, 3:6] = VOID
    scene = Scene.from_array(grid, 0.1)
    episodes = random_episodes(scene, 6, rng)
    episodes = [(s, yaw, s if k % 2 else g) for k, (s, yaw, g) in enumerate(episodes)]  # some goals at the start
    n = 4 if stop else 3
    p = np.array([0.55, 0.2, 0.2, 0.05][:n])
    actions = rng.choice(n, size=(300, 6), p=p / p.sum())
    stats = compare(scene, episodes, actions, device=device, sensors=sensors, action_space="discrete",
                    discrete_actions={"stop": stop},
                    task={"reward_type": "geodesic", "termination_config": {"max_steps": 40, "max_collisions": 20}})
    # The case exercised what it claims: contacts, successes and autoresets.
    assert stats["contacts"] > 0 and stats["successes"] > 0 and stats["autoresets"] > 0


def test_fleet_discrete_actions_need_the_discrete_space() -> None:
    with pytest.raises(ValueError, match="discrete_actions"):
        VectorPointNavEnv(2, n_robots=2, scene=room(), discrete_actions={"stop": False})
    with pytest.raises(ValueError, match="action_space"):
        VectorPointNavEnv(2, n_robots=2, scene=room(), action_space="multi")


@pytest.mark.parametrize("device", DEVICES)
def test_a_refreshed_pool_keeps_each_episode_on_its_goal_field(device: str) -> None:
    # An empty room: every geodesic is the straight line, whichever pool an episode came from.
    env = VectorPointNavEnv(4, scene=room(), device=device, seed=2, pool_size=1, starts_per_goal=3,
                            max_episode_steps=2, action_space="discrete", discrete_actions={"stop": False})
    env.reset()
    to_np = env.arrays.numpy
    for t in range(8):
        if t in (1, 4):
            env.refresh_pool(wait=True)
        _, _, _, _, info = env.step(np.full(4, FORWARD))
        st = env.state
        x, y, gx, gy = (to_np(v) for v in (st.x, st.y, st.goal_x, st.goal_y))
        np.testing.assert_allclose(to_np(info["distance_to_goal"]), np.hypot(gx - x, gy - y), atol=1e-9)
    assert env.pool.pool_size == 3  # the refreshed pool holds three starts per goal too


# ---------------------------------------------------------------- several robots per world


def make_fleet(n: int, device: str, stop: bool = True, **kwargs: object) -> VectorPointNavEnv:
    return VectorPointNavEnv(n, n_robots=2, scene=room(), device=device, action_space="discrete",
                             discrete_actions={"stop": stop}, task={"goal_in_polar": True}, pool_size=1, seed=0,
                             **kwargs)


@pytest.mark.parametrize("device", DEVICES)
def test_fleet_robots_run_together_for_the_longest_action_by_hand(device: str) -> None:
    # Robot 0 moves 0.25 m in 5 control steps; robot 1 turns 10 deg in 2 and then stands
    # for the other 3 (no command, as the multi-robot env steps it), so its velocity is 0.
    env = make_fleet(1, device)
    to_np = env.arrays.numpy
    assert env.action_space == gym.spaces.MultiDiscrete(np.full((1, 2), 4))
    env.reset(options={"episodes": [[((1.0, 1.5), 0.0, (2.5, 1.5)), ((1.0, 2.5), 0.0, (1.0, 2.5))]]})
    obs, reward, terminated, _, info = env.step(np.array([[FORWARD, LEFT]]))
    obs = to_np(obs)
    np.testing.assert_allclose(to_np(env.state.x)[0], [1.25, 1.0], atol=1e-12)
    np.testing.assert_allclose(to_np(env.state.yaw)[0], [0.0, math.radians(10.0)], atol=1e-12)
    np.testing.assert_allclose(obs[0, 0, [2, 7]], [0.5, 0.0], atol=1e-6)  # 0.05 m in the last 0.1 s
    np.testing.assert_allclose(obs[0, 1, 2:], 0.0, atol=1e-7)  # stood still in the last control steps
    np.testing.assert_allclose(to_np(reward)[0], [0.25, 0.0], atol=1e-9)
    assert to_np(info["episode_length"]).tolist() == [[1, 1]]
    # Robot 1 calls STOP on its goal: a success with SPL 1; it parks and is inactive from then on.
    _, reward, terminated, _, info = env.step(np.array([[RIGHT, STOP]]))
    assert to_np(terminated).tolist() == [[False, True]] and to_np(info["success"]).tolist() == [[False, True]]
    np.testing.assert_allclose(to_np(reward)[0, 1], 10.0, atol=1e-9)
    np.testing.assert_allclose(to_np(info["spl"])[0], [0.0, 1.0])
    obs, reward, terminated, _, info = env.step(np.array([[STOP, FORWARD]]))  # robot 1's is ignored
    assert to_np(info["active"]).tolist() == [[False, False]]
    assert to_np(terminated).tolist() == [[True, False]] and to_np(info["success"]).tolist() == [[False, False]]
    np.testing.assert_allclose(to_np(env.state.x)[0], [1.25, 1.0], atol=1e-12)


@pytest.mark.parametrize("device", DEVICES)
def test_fleet_move_into_a_parked_robot_ends_at_the_contact_by_hand(device: str) -> None:
    # Robot 1 parks at x = 1.6 m (STOP on its goal); robot 0, at x = 1.0 m facing it, has
    # 0.6 - 2 x 0.18 = 0.24 m of free travel: four control steps of 0.05 m, then the touch.
    env = make_fleet(1, device)
    to_np = env.arrays.numpy
    env.reset(options={"episodes": [[((1.0, 1.5), 0.0, (1.0, 2.5)), ((1.6, 1.5), 0.0, (1.6, 1.5))]]})
    env.step(np.array([[RIGHT, STOP]]))
    env.step(np.array([[LEFT, FORWARD]]))
    info = env.step(np.array([[FORWARD, FORWARD]]))[4]
    np.testing.assert_allclose(to_np(env.state.x)[0], [1.24, 1.6], atol=1e-9)
    assert to_np(info["in_contact"]).tolist() == [[True, False]]
    assert to_np(info["collisions"]).tolist() == [[1, 0]]
    np.testing.assert_allclose(to_np(info["path_length"])[0, 0], 0.24, atol=1e-9)


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize(
    "actions",
    [np.array([[0, 0], [0, 3]]), np.array([[-1, 0], [0, 0]]), np.zeros(2, np.int64), np.zeros((2, 2, 1), np.int64),
     np.zeros((3, 2), np.int64), np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[True, False], [False, True]]),
     np.full((2, 2), np.nan), [[0.5, 1.0], [0.0, 0.0]], [[0, 1], [2, 5]]],
)
def test_fleet_bad_discrete_actions_are_refused(device: str, actions: object) -> None:
    env = make_fleet(2, device, stop=False)
    env.reset()
    before = env.arrays.numpy(env.state.x)
    with pytest.raises(ValueError, match="actions"):
        env.step(actions)
    np.testing.assert_array_equal(env.arrays.numpy(env.state.x), before)


@pytest.mark.parametrize("device", DEVICES)
def test_fleet_discrete_matches_parallel_envs_in_a_crowded_room(device: str) -> None:
    # A 1.6 x 2 m room with a hole at one end, four robots a world: they meet each other,
    # the parked ones and the walls; some fall, some stop on their goal.
    from fleet_reference import compare_fleet, fleet_episodes

    from pointnav_core.floor.maps import VOID

    rng = np.random.default_rng(3)
    grid = np.zeros((20, 16), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[5, 5] = OBSTACLE
    grid[16:19, 1:15] = VOID
    scene = Scene.from_array(grid, 0.1)
    actions = rng.choice(4, size=(120, 4, 4), p=[0.6, 0.15, 0.15, 0.1])
    task = {"reward_type": "geodesic", "goal_tolerance": 0.2, "termination_config": {"max_steps": 40, "max_collisions": 10}}
    for finished in ("park", "remove"):
        stats = compare_fleet(scene, fleet_episodes(scene, 4, 4, rng, goal_gap=0.4, at_start=0.5), actions, task=task, device=device,
                              finished=finished, max_cycles=45, action_space="discrete",
                              discrete_actions={"forward_step": 0.15})
        # The run exercised what it claims to: robot contacts, parked robots, STOP, falls, autoresets.
        assert stats["robot_contacts"] > 0 and stats["parked_steps"] > 100 and stats["stops"] > 0
        assert stats["successes"] > 0 and stats["autoresets"] > 0 and stats["falls"] > 0
