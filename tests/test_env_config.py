"""EnvConfig: one env configuration, saved and reused by every engine and by ``pointnav eval``."""

from __future__ import annotations

import dataclasses
import json
import math
import pickle

import gymnasium as gym
import numpy as np
import pytest

from pointnav_core import scenes
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.datasets import PointNavEpisode
from pointnav_core.envs.config import EnvConfig
from pointnav_core.envs.multi_pointnav import parallel_env
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.vector import VectorPointNavEnv

# Every field away from its default, and floats that only an exact writer round-trips.
FULL = {
    "robot": {"radius": 0.2, "max_linear_velocity": 0.4, "max_angular_velocity": 1.25, "drive": "holonomic"},
    "sensors": {"scan": {"n_rays": 12, "max_range": 3.3, "noise_std": 0.01}, "local_map": {"cells": 8}},
    "action_space": "discrete",
    "discrete_actions": {"forward_step": 0.1, "turn_angle": math.radians(10.0), "stop": False},
    "task": {
        "goal_in_polar": True, "goal_tolerance": 0.3, "reward_type": "geodesic", "path_range": [1.0, 4.5],
        "reward_config": {"r_collision": 0.05}, "termination_config": {"max_collisions": 40},
    },
    "max_steps": 150,
    "flatten_obs": False,
    "action_frequency": 5.0,
    "backend": "pymunk",
    "pedestrians": {"count": 6, "radius": [0.2, 0.3], "behaviour": "social_force", "orca": {"time_horizon": 3.0}},
}

YAML_TEXT = """\
sensors:
  scan: {n_rays: 16}
action_space: discrete
discrete_actions: {stop: false}
task: {goal_in_polar: true}
max_steps: 150
"""


def room() -> scenes.Scene:
    """A walled 4 x 3 m room with a wall stub, as grid cells (every engine takes it)."""
    grid = np.zeros((30, 40), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = 1
    grid[8:22, 20] = 1
    return scenes.Scene.from_array(grid, 0.1, scene_id="box")


def test_round_trip_through_dict_yaml_json_and_pickle(tmp_path):
    config = EnvConfig(**FULL)
    assert config.to_dict() == FULL  # every field as given: nothing dropped or defaulted
    assert EnvConfig.from_dict(config.to_dict()) == config
    assert json.loads(json.dumps(config.to_dict())) == config.to_dict()  # a checkpoint can carry it
    for name in ("c.yaml", "c.yml", "c.json"):
        config.save(tmp_path / name)
        again = EnvConfig.load(tmp_path / name)
        assert again == config and again.to_dict() == FULL
        assert again.discrete_actions["turn_angle"] == math.radians(10.0)  # exact, not rounded
    assert pickle.loads(pickle.dumps(config)) == config and hash(again) == hash(config)
    assert config != dataclasses.replace(config, max_steps=151)


def test_a_hand_written_yaml_file_gives_the_config_it_says(tmp_path):
    (tmp_path / "scan.yaml").write_text(YAML_TEXT)
    config = EnvConfig.load(tmp_path / "scan.yaml")
    assert config.to_dict() == {
        "robot": {"radius": 0.18, "max_linear_velocity": 0.5, "max_angular_velocity": 1.5, "drive": "differential"},
        "sensors": {"scan": {"n_rays": 16}}, "action_space": "discrete", "discrete_actions": {"stop": False},
        "task": {"goal_in_polar": True}, "max_steps": 150, "flatten_obs": True, "action_frequency": 10.0,
        "backend": "kinematic", "pedestrians": None,
    }
    assert config.robot == RobotSpec()
    # None and {} both mean a sensor's defaults: one form.
    assert EnvConfig(sensors={"scan": None}) == EnvConfig(sensors={"scan": {}})


@pytest.mark.parametrize(
    "fields, match",
    [
        ({"max_step": 150}, r"env config has an unknown key 'max_step'; valid keys are \['robot'"),
        ({"sensors": {"lidar": {}}}, "sensors has an unknown sensor 'lidar'"),
        ({"sensors": {"scan": {"n_rays": 0}}}, r"sensors\['scan'\]: n_rays"),
        ({"sensors": {"scan": {"rays": 8}}}, r"sensors\['scan'\] has an unknown key 'rays'"),
        ({"action_space": "box"}, r"action_space must be one of \['continuous', 'discrete'\]"),
        ({"discrete_actions": {"stop": False}}, 'discrete_actions needs action_space="discrete"'),
        ({"action_space": "discrete", "discrete_actions": {"stop": "no"}}, "stop must be True or False"),
        ({"task": {"goal_tol": 1}}, "task has an unknown key 'goal_tol'"),
        ({"task": {"robot_idn": 1}}, "task has an unknown key 'robot_idn'"),
        ({"task": {"goal_tolerance": 0}}, "task: goal_tolerance must be a finite number > 0"),
        ({"task": {"termination_config": {"max_steps": 9}}}, r"task\['termination_config'\] sets max_steps"),
        ({"task": {"reward_config": {"r_bonus": 1}}}, "r_bonus"),
        ({"task": {"path_range": np.array([1.0, 2.0])}}, r"task\['path_range'\] must hold only numbers"),
        ({"max_steps": 0}, "max_steps must be an integer >= 1, got 0"),
        ({"max_steps": True}, "max_steps must be an integer >= 1, got True"),
        ({"max_steps": 1.5}, "max_steps must be an integer >= 1, got 1.5"),
        ({"flatten_obs": "yes"}, "flatten_obs must be True or False"),
        ({"action_frequency": "10"}, "action_frequency must be a finite number"),
        ({"backend": "mujoco"}, r"backend must be one of \["),
        ({"robot": {"radius": -1}}, "radius must be a finite number >= 0"),
        ({"robot": {"size": 1}}, "robot has an unknown key 'size'"),
        ({"pedestrians": {"count": 3, "behaviour": "flock"}}, r"pedestrians\['behaviour'\] must be one of"),
        ({"pedestrians": {"density": -1}}, r"pedestrians\['density'\] must be a finite number >= 0"),
    ],
)
def test_bad_fields_are_refused_naming_them(fields, match):
    with pytest.raises(ValueError, match=match):
        EnvConfig.from_dict(fields)


@pytest.mark.parametrize(
    "name, text, match",
    [
        ("c.txt", "max_steps: 1", r"must be a \.yaml, \.yml, \.json file"),
        ("c.yaml", "max_steps: [1", "is not valid YAML"),
        ("c.json", "{max_steps: 1", "is not valid JSON"),
        ("c.yaml", "- max_steps", "env config must be a mapping of its fields"),
        ("c.yaml", "max_steps: 0", r"env config '.*c\.yaml': max_steps must be an integer >= 1"),
    ],
)
def test_bad_files_are_refused_naming_them(tmp_path, name, text, match):
    (tmp_path / name).write_text(text)
    with pytest.raises(ValueError, match=match):
        EnvConfig.load(tmp_path / name)


SCAN = EnvConfig(
    sensors={"scan": {"n_rays": 16}}, action_space="discrete", discrete_actions={"stop": False},
    task={"goal_in_polar": True, "path_range": [0.5, 2.5]}, max_steps=40,
)
MAP = EnvConfig(sensors={"local_map": {"cells": 8}}, robot={"drive": "holonomic", "radius": 0.15}, max_steps=60)


def _episode(yaw: float = 0.4) -> PointNavEpisode:
    start, goal = (0.6, 0.6), (3.2, 2.2)
    return PointNavEpisode(
        episode_id="e", scene_id="box", floor=0, start_position=(*start, 0.0),
        start_rotation=(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)), goal_position=(*goal, 0.0),
        goal_radius=None, geodesic_distance=3.5, robot_radius=0.18,
    )


@pytest.mark.parametrize("config", [SCAN, MAP], ids=["scan-discrete", "map-holonomic"])
def test_every_engine_builds_the_same_spaces_and_first_observation(config):
    scene = room()
    single = PointNavEnv(scene=scene, config=config)
    made = gym.make("pointnav_core/PointNav-v0", scene=scene, config=config)
    multi = parallel_env(scene=scene, n_robots=2, config=config)
    vector = VectorPointNavEnv(2, scene=scene, config=config, seed=0, pool_size=1)
    fleet = VectorPointNavEnv(1, n_robots=2, scene=scene, config=config, seed=0, pool_size=1)
    for env in (single, made, multi, vector, fleet):
        assert env.unwrapped.config is config
    obs_space, act_space = single.observation_space, single.action_space
    n_sensor = 16 if config is SCAN else 64
    assert obs_space.shape == (8 + n_sensor,) and made.observation_space == obs_space
    assert act_space == (gym.spaces.Discrete(3) if config is SCAN else gym.spaces.Box(-1, 1, (3,), np.float32))
    assert made.action_space == act_space
    for agent in multi.possible_agents:
        assert multi.observation_space(agent) == obs_space and multi.action_space(agent) == act_space
    for env in (vector, fleet):
        assert env.single_observation_space == obs_space and env.single_action_space == act_space
    # Step limits, in actions, everywhere.
    assert single.task.max_steps == multi.max_cycles == vector.max_steps == fleet.max_cycles == config.max_steps
    # The same episode gives the same first observation in the single env and the batched engine.
    first, _ = single.reset(seed=0, options={"episode": _episode()})
    batched, _ = vector.reset(options={"episodes": [_episode(), _episode(1.0)]})
    np.testing.assert_allclose(batched[0], first, rtol=1e-6, atol=1e-6)
    assert not np.allclose(batched[1], first)  # another heading sees another scan or map


def test_arguments_the_config_sets_are_refused_beside_it():
    scene = room()
    with pytest.raises(ValueError, match=r"robot given beside config, which sets it: change the config instead \(dataclasses.replace"):
        PointNavEnv(scene=scene, robot={"radius": 0.2}, config=SCAN)
    with pytest.raises(ValueError, match="sensors, action_space given beside config, which sets them"):
        parallel_env(scene=scene, sensors=None, action_space="continuous", config=SCAN)
    with pytest.raises(ValueError, match="max_episode_steps given beside config"):
        VectorPointNavEnv(1, scene=scene, max_episode_steps=10, config=SCAN)
    with pytest.raises(ValueError, match="max_episode_steps=10 given beside config, which sets max_steps=40"):
        gym.make("pointnav_core/PointNav-v0", scene=scene, config=SCAN, max_episode_steps=10)
    with pytest.raises(ValueError, match="config must be an EnvConfig or None"):
        PointNavEnv(config=SCAN.to_dict())
    with pytest.raises(ValueError, match="config.backend is 'pymunk', but the batched engine"):
        VectorPointNavEnv(1, scene=scene, config=dataclasses.replace(SCAN, backend="pymunk"))
    with pytest.raises(ValueError, match="config.flatten_obs is False"):
        VectorPointNavEnv(1, scene=scene, config=dataclasses.replace(SCAN, flatten_obs=False))
    # Arguments a config does not hold go beside it; an explicit max_cycles wins over max_steps.
    env = parallel_env(scene=scene, n_robots=3, max_cycles=25, render_mode="rgb_array", config=SCAN)
    assert env.max_cycles == 25 and env.tasks[2].max_steps == 40
