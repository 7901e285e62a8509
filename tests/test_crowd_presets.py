"""Crowd presets (``pointnav_core.crowds.presets``) and fixed starts and goals: the scenarios
are what their papers describe, checked by hand-computed positions, and they repeat exactly."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pointnav_core.crowds import presets
from pointnav_core.envs.config import EnvConfig
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.errors import SamplingError


def test_circle_crossing_is_crowdnavs() -> None:
    scenario = presets.circle_crossing()
    starts = np.array(scenario.pedestrians["starts"])
    # 5 humans at 2 pi (k + 0.5) / 5 from the x axis: 36, 108, 180, 252 and 324 deg on the
    # 4 m circle, none on the robot's line x = 0 (90 and 270 deg, its goal and start), each
    # moved by at most 0.5 m in x and y (CrowdNav's noise at 1 m/s).
    want = [[4 * math.cos(math.radians(a)), 4 * math.sin(math.radians(a))] for a in (36, 108, 180, 252, 324)]
    assert (np.abs(starts - want) <= 0.5).all() and not np.array_equal(starts, want)
    for n in (2, 4, 6):  # 2 mod 4 turns by pi / 2n: 135 and 315 deg for two
        ring = presets.circle_crossing(humans=n, seed=1).pedestrians["starts"]
        assert min(abs(x) for x, _ in ring) > 4 * math.sin(math.pi / (2 * n)) - 0.5
    goals = np.array([g[0] for g in scenario.pedestrians["goals"]])
    np.testing.assert_allclose(goals, -starts)  # the opposite point, then back
    assert scenario.task["initial_pos"] == [0.0, -4.0] and scenario.task["goal_pos"] == [0.0, 4.0]
    assert scenario.pedestrians["radius"] == 0.3 and scenario.pedestrians["speed"] == 1.0


@pytest.mark.parametrize("make", [presets.circle_crossing, presets.corridor, presets.doorway])
def test_every_preset_starts_where_it_says_and_repeats(make) -> None:
    scenario = make()
    env = PointNavEnv(**scenario.env_arguments())
    env.reset(seed=0)
    np.testing.assert_array_equal(env.crowd.positions, scenario.pedestrians["starts"])
    np.testing.assert_allclose(env.backend.get_pose(0)[0][:2], scenario.task["initial_pos"])
    first = [env.step(np.array([0.5, 0.0]))[4]["pedestrian_collisions"] for _ in range(40)]
    again = PointNavEnv(**scenario.env_arguments())
    again.reset(seed=0)
    assert [again.step(np.array([0.5, 0.0]))[4]["pedestrian_collisions"] for _ in range(40)] == first
    np.testing.assert_array_equal(again.crowd.positions, env.crowd.positions)


def test_a_preset_travels_in_an_env_config() -> None:
    scenario = presets.doorway()
    config = EnvConfig(pedestrians=scenario.pedestrians, flatten_obs=False)
    assert EnvConfig.from_dict(config.to_dict()) == config
    env = PointNavEnv(scene=scenario.scene, task=scenario.task, pedestrians=scenario.pedestrians)
    env.reset(seed=1)
    np.testing.assert_array_equal(env.crowd.positions, scenario.pedestrians["starts"])


def test_fixed_goals_are_walked_in_turn() -> None:
    scenario = presets.circle_crossing(humans=3, sees_robots=False)
    env = PointNavEnv(**scenario.env_arguments())
    env.reset(seed=0)
    starts = np.array(scenario.pedestrians["starts"])
    np.testing.assert_array_equal(env.crowd.goals, -starts)
    for _ in range(300):  # 8 m at 1 m/s: 80 steps there, and some giving way at the centre
        env.step(np.zeros(2))
        if not np.array_equal(env.crowd.goals, -starts):
            break
    back = ~np.all(env.crowd.goals == -starts, axis=1)
    assert back.any()
    np.testing.assert_array_equal(env.crowd.goals[back], starts[back])  # then back to the start
    assert (np.hypot(*(env.crowd.positions[back] + starts[back]).T) < 0.1 + 1e-9).all()


def test_bad_fixed_starts_are_refused_naming_them() -> None:
    scenario = presets.corridor()
    inside_wall = [[0.0, 1.25], *scenario.pedestrians["starts"][1:]]
    env = PointNavEnv(scene=scenario.scene, task=scenario.task, pedestrians={**scenario.pedestrians, "starts": inside_wall})
    with pytest.raises(SamplingError, match=r"pedestrians\['starts'\]\[0\]"):
        env.reset(seed=0)
    with pytest.raises(ValueError, match=r"pedestrians\['count'\] must be the number of starts"):
        PointNavEnv(pedestrians={"count": 3, "starts": [[0.0, 0.0]]})
    with pytest.raises(ValueError, match=r"pedestrians\['goals'\]"):
        PointNavEnv(pedestrians={"starts": [[0.0, 0.0]], "goals": [[[1.0, 1.0]], [[2.0, 2.0]]]})
    with pytest.raises(ValueError, match=r"pedestrians\['starts'\]\[0\]"):
        PointNavEnv(pedestrians={"starts": [[0.0, "1"]]})
    assert math.isclose(presets.igibson_density()["density"], 0.125)
