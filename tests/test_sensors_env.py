"""Sensors and discrete actions in the environments: spaces, layout, checkers, noise, STOP."""

from __future__ import annotations

import math
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from scan_reference import assert_within, blocked_shapes, reference_ranges
from stable_baselines3.common.env_checker import check_env as sb3_check_env

import pointnav_core  # noqa: F401  (registers the envs)
from pointnav_core.envs import multi_pointnav as parallel
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID
from pointnav_core.scenes import Scene
from pointnav_core.task.actions import MOVE_FORWARD, STOP, TURN_LEFT, TURN_RIGHT
from pointnav_core.transforms import quat2yaw

with warnings.catch_warnings():
    warnings.filterwarnings("ignore", message="The old environment creation API", category=DeprecationWarning)
    from pettingzoo.test import api_test, parallel_api_test
from pettingzoo.utils.conversions import parallel_to_aec

SENSOR_CONFIGS = [
    {"scan": {"n_rays": 16}},
    {"local_map": {"cells": 8}},
    {"local_map": {"cells": 8, "dtype": "float32"}},
    {"scan": {"n_rays": 8, "noise_std": 0.05, "dropout": 0.1}, "local_map": {"size": 2.0, "cells": 6}},
]
DICT_OBS_ADVICE = (
    "Observation space for each agent probably should be gymnasium.spaces.box",
    "Observation is not a NumPy array",
)


def small_scene() -> Scene:
    """A 4 m x 3 m walled room with a block and a hole in it."""
    grid = np.full((30, 40), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[10:20, 15:18] = OBSTACLE
    grid[3:6, 30:34] = VOID
    return Scene.from_array(grid, 0.1)


# ------------------------------------------------------------------------------ spaces


def test_dict_and_flat_observations_hold_the_sensors_in_the_documented_order():
    sensors = {"local_map": {"cells": 4}, "scan": {"n_rays": 5}}  # dict order does not matter
    env = PointNavEnv(scene=small_scene(), sensors=sensors)
    obs, _ = env.reset(seed=0)
    assert list(obs) == ["xy_pos_to_goal", "robot_lin_vel", "robot_ang_vel", "scan", "local_map"]
    assert obs["scan"].shape == (5,) and obs["scan"].dtype == np.float32
    assert obs["local_map"].shape == (4, 4) and obs["local_map"].dtype == np.uint8
    assert env.observation_space.contains(obs)
    flat_env = PointNavEnv(scene=small_scene(), sensors=sensors, flatten_obs=True)
    flat, _ = flat_env.reset(seed=0)
    assert flat.shape == (8 + 5 + 16,) and flat.dtype == np.float32
    want = np.concatenate([obs[k].astype(np.float32).ravel() for k in obs])
    np.testing.assert_array_equal(flat, want)
    assert flat_env.observation_space.contains(flat)


def test_observations_are_fresh_arrays():
    env = PointNavEnv(scene=small_scene(), sensors={"scan": {"n_rays": 4}, "local_map": {"cells": 4}})
    a, _ = env.reset(seed=0)
    b, *_ = env.step(np.zeros(2, np.float32))
    for key in a:
        assert not np.shares_memory(a[key], b[key])


def test_gymnasium_make_and_the_parallel_env_take_sensors():
    env = gym.make("pointnav_core/PointNav-v0", scene=small_scene(), sensors={"scan": {"n_rays": 7}})
    obs, _ = env.reset(seed=0)
    assert obs["scan"].shape == (7,)
    penv = parallel.parallel_env(flatten_obs=False, scene=small_scene(), n_robots=2, sensors={"local_map": {"cells": 3}})
    observations, _ = penv.reset(seed=0)
    assert observations["robot_1"]["local_map"].shape == (3, 3)
    # Every robot's task has its own sensor objects.
    assert penv.tasks[0].observation_terms["local_map"] is not penv.tasks[1].observation_terms["local_map"]


@pytest.mark.parametrize(
    "sensors, match",
    [
        ({"lidar": {}}, "unknown sensor 'lidar'"),
        ({"scan": {"rays": 3}}, "unknown key 'rays'"),
        ({"scan": {"n_rays": 0}}, "n_rays"),
        ({"scan": {"n_rays": -2}}, "n_rays"),
        ({"scan": {"fov": 7.0}}, "fov"),
        ({"scan": {"min_range": 2.0, "max_range": 1.0}}, "min_range"),
        ({"scan": {"max_range": "5"}}, "max_range"),
        ({"scan": {"noise_std": True}}, "noise_std"),
        ({"local_map": {"cells": 0}}, "cells"),
        ({"local_map": {"size": -1.0}}, "size"),
        ({"local_map": {"dtype": "int8"}}, "dtype"),
        ({"local_map": 3}, "local_map"),
        (["scan"], "sensors"),
    ],
)
def test_bad_sensor_configuration_raises_naming_it(sensors, match):
    with pytest.raises(ValueError, match=match):
        PointNavEnv(scene=small_scene(), sensors=sensors)
    with pytest.raises(ValueError, match=match):
        parallel.parallel_env(scene=small_scene(), sensors=sensors)


def test_sensors_with_a_ready_task_or_twice_raise():
    from pointnav_core.sensors import RangeScan
    from pointnav_core.task import PointNavigationTask

    with pytest.raises(ValueError, match="ready PointNavigationTask"):
        PointNavEnv(scene=small_scene(), task=PointNavigationTask(), sensors={"scan": {}})
    with pytest.raises(ValueError, match="already has"):
        PointNavEnv(scene=small_scene(), task={"observation_terms": [RangeScan()]}, sensors={"scan": {}})


# ------------------------------------------------------------------------------ checkers


@pytest.mark.parametrize("sensors", SENSOR_CONFIGS)
@pytest.mark.parametrize("action_space", ["continuous", "discrete"])
def test_checkers_pass_with_each_sensor(sensors, action_space):
    kwargs = {"scene": small_scene(), "sensors": sensors, "action_space": action_space}
    check_env(PointNavEnv(**kwargs), skip_render_check=True)
    sb3_check_env(PointNavEnv(**kwargs), warn=False)
    sb3_check_env(PointNavEnv(flatten_obs=True, **kwargs), warn=False)
    parallel_api_test(parallel.parallel_env(flatten_obs=False, n_robots=2, **kwargs), num_cycles=100)
    api_test(parallel_to_aec(parallel.parallel_env(n_robots=2, flatten_obs=True, **kwargs)), num_cycles=100)
    with warnings.catch_warnings():
        for message in DICT_OBS_ADVICE:
            warnings.filterwarnings("ignore", message=message, category=UserWarning)
        api_test(parallel_to_aec(parallel.parallel_env(flatten_obs=False, n_robots=2, **kwargs)), num_cycles=100)


# ------------------------------------------------------------------------------ readings


def test_the_scan_of_each_robot_agrees_with_the_reference_and_sees_the_others():
    scene = small_scene()
    tmap = scene.floors[0]
    penv = parallel.parallel_env(flatten_obs=False, scene=scene, n_robots=3, sensors={"scan": {"n_rays": 32, "min_range": 0.0}})
    observations, _ = penv.reset(seed=4)
    for _ in range(3):
        observations, *_ = penv.step({a: np.array([1.0, 0.5], np.float32) for a in penv.agents})
    shapes = blocked_shapes(tmap.codes, tmap.resolution, tmap.origin)
    poses = [penv.backend.get_pose(i) for i in range(3)]
    for i, agent in enumerate(penv.possible_agents):
        (x, y, _), quat = poses[i]
        discs = [(p[0][0], p[0][1], 0.18) for j, p in enumerate(poses) if j != i]
        angles = penv.tasks[i].observation_terms["scan"].angles
        loose, strict = reference_ranges(shapes, (x, y), quat2yaw(quat) + angles, 5.6, discs)
        # float32 observations: within a float32 ulp of 5.6 m, plus the reference's 1e-4.
        assert_within(observations[agent]["scan"].astype(np.float64), loose, strict, atol=1e-4)


def test_noise_off_is_deterministic_and_noise_on_reproduces_under_the_same_seed():
    def run(seed, **scan):
        env = PointNavEnv(scene=small_scene(), sensors={"scan": {"n_rays": 16, **scan}})
        obs, _ = env.reset(seed=seed)
        out = [obs["scan"], env.task.get_goal_pos()]
        for _ in range(5):
            obs, *_ = env.step(np.array([0.5, 0.2], np.float32))
            out.append(obs["scan"])
        env.reset()
        out.append(env.step(np.zeros(2, np.float32))[0]["scan"])
        return out

    def same(a, b):
        return all(np.array_equal(u, v) for u, v in zip(a, b))

    assert same(run(1), run(1))
    noisy = run(1, noise_std=0.05, dropout=0.2)
    assert same(noisy, run(1, noise_std=0.05, dropout=0.2))
    assert not same(noisy, run(2, noise_std=0.05, dropout=0.2))
    assert not same(noisy, run(1))
    # Noise draws from no generator: the episodes (goals) are those of the noiseless env.
    np.testing.assert_array_equal(noisy[1], run(1)[1])
    scans = np.array(noisy[:1] + noisy[2:])
    assert ((scans >= 0.0) & (scans <= 5.6)).all()


def test_min_range_readings_read_max_range():
    scene = small_scene()
    # A robot 0.25 m from the west wall facing it (the wall face is at x = 0.1).
    env = PointNavEnv(
        scene=scene,
        task={"initial_pos": (0.35, 1.5, 0.0), "initial_quat": (0.0, 0.0, 1.0, 0.0), "goal_pos": (3.0, 1.5, 0.0)},
        sensors={"scan": {"n_rays": 1, "min_range": 0.3, "max_range": 2.0}},
    )
    obs, _ = env.reset(seed=0)
    assert obs["scan"].tolist() == [pytest.approx(2.0)]
    env = PointNavEnv(
        scene=scene,
        task={"initial_pos": (0.35, 1.5, 0.0), "initial_quat": (0.0, 0.0, 1.0, 0.0), "goal_pos": (3.0, 1.5, 0.0)},
        sensors={"scan": {"n_rays": 1, "min_range": 0.2, "max_range": 2.0}},
    )
    obs, _ = env.reset(seed=0)
    assert obs["scan"].tolist() == [pytest.approx(0.25)]


def test_local_map_is_egocentric_heading_up_from_first_principles():
    scene = small_scene()
    tmap = scene.floors[0]
    cells, size = 9, 1.8
    penv = parallel.parallel_env(flatten_obs=False, scene=scene, n_robots=2, sensors={"local_map": {"size": size, "cells": cells}})
    observations, _ = penv.reset(seed=3)
    (x, y, _), quat = penv.backend.get_pose(0)
    (ox, oy, _), _ = penv.backend.get_pose(1)
    yaw = float(quat2yaw(quat))
    got = observations["robot_0"]["local_map"]
    step = size / cells
    for i in range(cells):
        for j in range(cells):
            ahead = (cells / 2 - i - 0.5) * step  # row 0 is ahead
            left = (cells / 2 - j - 0.5) * step  # column 0 is on the left
            wx = x + ahead * math.cos(yaw) - left * math.sin(yaw)
            wy = y + ahead * math.sin(yaw) + left * math.cos(yaw)
            col = math.floor((wx - tmap.origin[0]) / tmap.resolution)
            row = math.floor((wy - tmap.origin[1]) / tmap.resolution)
            if math.hypot(wx - ox, wy - oy) <= 0.18:
                want = 3
            elif 0 <= row < tmap.shape[0] and 0 <= col < tmap.shape[1]:
                want = {FREE: 0, OBSTACLE: 1, VOID: 2}[int(tmap.codes[row, col])]
            else:
                want = 2
            assert got[i, j] == want, (i, j)


# ------------------------------------------------------------------------------ discrete


def open_env(**kwargs) -> PointNavEnv:
    grid = np.full((40, 40), FREE, dtype=np.uint8)
    return PointNavEnv(
        scene=Scene.from_array(grid, 0.1),
        action_space="discrete",
        task={"initial_pos": (1.0, 2.0, 0.0), "initial_quat": (0.0, 0.0, 0.0, 1.0), "goal_pos": (2.0, 2.0, 0.0),
              "goal_tolerance": 0.3},
        **kwargs,
    )


def test_discrete_actions_move_exactly_a_quarter_metre_and_ten_degrees():
    env = open_env()
    assert env.action_space == gym.spaces.Discrete(4)
    env.reset(seed=0)
    _, _, _, _, info = env.step(MOVE_FORWARD)
    (x, y, _), _ = env.backend.get_pose(0)
    assert (x, y) == (pytest.approx(1.25, abs=1e-12), pytest.approx(2.0, abs=1e-12))
    assert info["path_length"] == pytest.approx(0.25, abs=1e-12) and info["episode_length"] == 1
    env.step(TURN_LEFT)
    assert float(quat2yaw(env.backend.get_pose(0)[1])) == pytest.approx(math.radians(10), abs=1e-12)
    env.step(np.int64(TURN_RIGHT))
    env.step(np.array([TURN_RIGHT]))
    assert float(quat2yaw(env.backend.get_pose(0)[1])) == pytest.approx(-math.radians(10), abs=1e-12)


def test_with_stop_success_needs_stop_within_tolerance():
    env = open_env()
    env.reset(seed=0)
    for _ in range(3):  # 1.75 m: within 0.3 m of the goal, but no STOP yet
        *_, terminated, _, info = env.step(MOVE_FORWARD)
    assert not terminated and not info["success"]
    *_, terminated, _, info = env.step(STOP)
    assert terminated and info["success"] and info["reward_breakdown"]["pointgoal"] == 10.0
    assert info["spl"] > 0.0
    env.reset(seed=0)
    *_, terminated, _, info = env.step(STOP)  # 1 m away: ends, failed
    assert terminated and not info["success"] and info["reward_breakdown"]["pointgoal"] == 0.0


def test_without_stop_the_seeds_rule_holds_and_the_steps_are_configurable():
    env = open_env(discrete_actions={"stop": False, "forward_step": 0.5, "turn_angle": math.radians(30)})
    assert env.action_space == gym.spaces.Discrete(3)
    env.reset(seed=0)
    *_, terminated, _, info = env.step(MOVE_FORWARD)
    assert not terminated
    *_, terminated, _, info = env.step(MOVE_FORWARD)  # at 2.0: on the goal
    assert terminated and info["success"]
    env.reset(seed=0)
    env.step(TURN_LEFT)
    assert float(quat2yaw(env.backend.get_pose(0)[1])) == pytest.approx(math.radians(30), abs=1e-12)


def test_a_forward_move_into_a_wall_stops_there_and_counts_one_collision():
    grid = np.full((10, 40), FREE, dtype=np.uint8)
    grid[:, 20] = OBSTACLE  # the wall's face at x = 2.0
    env = PointNavEnv(
        scene=Scene.from_array(grid, 0.1),
        action_space="discrete",
        task={"initial_pos": (1.7, 0.5, 0.0), "initial_quat": (0.0, 0.0, 0.0, 1.0), "goal_pos": (0.5, 0.5, 0.0)},
    )
    env.reset(seed=0)
    *_, info = env.step(MOVE_FORWARD)
    (x, _, _), _ = env.backend.get_pose(0)
    assert x == pytest.approx(2.0 - 0.18, abs=1e-6) and info["collisions"] == 1


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"action_space": "box"}, "action_space"),
        ({"action_space": "discrete", "discrete_actions": {"step": 1}}, "unknown key 'step'"),
        ({"action_space": "discrete", "discrete_actions": {"forward_step": -1.0}}, "forward_step"),
        ({"action_space": "discrete", "discrete_actions": {"turn_angle": 4.0}}, "turn_angle"),
        ({"action_space": "discrete", "discrete_actions": {"stop": 1}}, "stop"),
        ({"discrete_actions": {"stop": True}}, "discrete_actions"),
    ],
)
def test_bad_action_configuration_raises_naming_it(kwargs, match):
    with pytest.raises(ValueError, match=match):
        PointNavEnv(scene=small_scene(), **kwargs)


@pytest.mark.parametrize("action", [4, -1, 1.0, True, "0", np.array([0, 1]), np.array([0.0])])
def test_bad_discrete_actions_raise_and_move_nothing(action):
    env = open_env()
    env.reset(seed=0)
    before = env.backend.get_pose(0)[0]
    with pytest.raises(ValueError, match="discrete action"):
        env.step(action)
    np.testing.assert_array_equal(env.backend.get_pose(0)[0], before)
    penv = parallel.parallel_env(scene=small_scene(), n_robots=2, action_space="discrete")
    penv.reset(seed=0)
    with pytest.raises(ValueError, match="robot_1: action must be an integer"):
        penv.step({"robot_0": 0, "robot_1": action})


def test_multi_robot_discrete_steps_run_together_and_stop_ends_each():
    penv = parallel.parallel_env(scene=small_scene(), n_robots=2, action_space="discrete")
    penv.reset(seed=0)
    before = [penv.backend.get_pose(i)[0] for i in range(2)]
    _, _, terminations, _, infos = penv.step({"robot_0": MOVE_FORWARD, "robot_1": STOP})
    assert terminations["robot_1"] and not infos["robot_1"]["success"]  # STOP far from the goal
    assert "robot_1" not in penv.agents
    moved = [float(np.hypot(*(penv.backend.get_pose(i)[0] - before[i])[:2])) for i in range(2)]
    assert moved[1] == 0.0
    assert moved[0] == pytest.approx(0.25, abs=1e-9) or infos["robot_0"]["collisions"] == 1
    assert infos["robot_0"]["episode_length"] == 1


def test_a_holonomic_robot_moves_and_turns_the_same():
    env = open_env(robot={"drive": "holonomic"})
    env.reset(seed=0)
    env.step(TURN_LEFT)
    env.step(MOVE_FORWARD)
    (x, y, _), quat = env.backend.get_pose(0)
    yaw = math.radians(10)
    assert float(quat2yaw(quat)) == pytest.approx(yaw, abs=1e-12)
    assert (x, y) == (pytest.approx(1.0 + 0.25 * math.cos(yaw), abs=1e-9), pytest.approx(2.0 + 0.25 * math.sin(yaw), abs=1e-9))


def test_robots_cast_together_exactly_as_each_alone():
    from pointnav_core.sensors import cast_rays, other_robot_discs

    penv = parallel.parallel_env(flatten_obs=False, scene=small_scene(), n_robots=4, sensors={"scan": {"n_rays": 24, "min_range": 0.0}})
    observations, _ = penv.reset(seed=5)
    scans = [penv.tasks[i].observation_terms["scan"] for i in range(4)]
    assert scans[0]._share is not None and all(s._share is scans[0]._share for s in scans)
    for _ in range(4):
        observations, *_ = penv.step({a: np.array([0.8, -0.4], np.float32) for a in penv.agents})
    for i, agent in enumerate(penv.agents):
        (x, y, _), quat = penv.backend.get_pose(i)
        alone = cast_rays(
            scans[i]._geometry, [(x, y)], [float(quat2yaw(quat))], scans[i].angles, 5.6,
            discs=other_robot_discs(penv, i, 0),
        )[0]
        np.testing.assert_allclose(observations[agent]["scan"], alone.astype(np.float32), rtol=0, atol=1e-6)


def test_render_draws_the_scan_rays_and_hits():
    from pointnav_core.render.glyphs import SCAN_HIT_COLOR, SCAN_RAY_COLOR, ScanGlyph

    def colours(frame, colour):
        return int((frame == np.array(colour, np.uint8)).all(axis=2).sum())

    env = PointNavEnv(scene=small_scene(), sensors={"scan": {"n_rays": 16}}, render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    assert colours(frame, SCAN_RAY_COLOR) > 0 and colours(frame, SCAN_HIT_COLOR) > 0
    plain = PointNavEnv(scene=small_scene(), render_mode="rgb_array")
    plain.reset(seed=0)
    frame = plain.render()
    assert colours(frame, SCAN_RAY_COLOR) == 0 and colours(frame, SCAN_HIT_COLOR) == 0
    with pytest.raises(ValueError, match="ends_xy"):
        ScanGlyph(origin_xy=(0.0, 0.0), ends_xy=[[1.0, 0.0]], hit=[True, False])


def test_multi_robot_render_draws_every_robots_scan():
    from pointnav_core.render.glyphs import SCAN_HIT_COLOR

    penv = parallel.parallel_env(scene=small_scene(), n_robots=2, sensors={"scan": {"n_rays": 8}}, render_mode="rgb_array")
    penv.reset(seed=0)
    frame = penv.render()
    assert (frame == np.array(SCAN_HIT_COLOR, np.uint8)).all(axis=2).sum() > 0
