"""Stable-Baselines3: the registered env passes SB3's checker, the multi-robot VecEnv keeps
each robot's final info, and the callback logs the success rate the final infos give."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import rl_cases
from stable_baselines3 import PPO
from stable_baselines3.common.env_checker import check_env
from stable_baselines3.common.logger import KVWriter, Logger
from stable_baselines3.common.vec_env import DummyVecEnv, VecMonitor

from pointnav_core import scenes
from pointnav_core.envs.multi_pointnav import MultiPointNavEnv
from pointnav_core.integrations.sb3 import (
    MultiRobotVecEnv,
    PointNavMetricsCallback,
    make_vec_env,
)

ENV_ID = "pointnav_core/PointNav-v0"


def small_house() -> scenes.Scene:
    return scenes.rooms(seed=0, size=(8.0, 6.0))


class Capture(KVWriter):
    """An SB3 logger output that keeps every dump."""

    def __init__(self) -> None:
        self.dumps: list[dict] = []

    def write(self, key_values, key_excluded, step=0) -> None:
        self.dumps.append(dict(key_values))


def capture_logger() -> tuple[Logger, Capture]:
    capture = Capture()
    return Logger(folder=None, output_formats=[capture]), capture


# ------------------------------------------------------------------------------ single robot


@pytest.mark.parametrize(
    "kwargs",
    [
        {},
        {"flatten_obs": True},
        {"backend": "pymunk", "scene": "small"},
        {"robot": {"drive": "holonomic"}, "scene": "small"},
        {"task": {"goal_in_polar": True, "reward_type": "geodesic"}, "scene": "small"},
    ],
    ids=["default", "flat", "pymunk", "holonomic", "polar-geodesic"],
)
def test_sb3_check_env_passes_on_the_registered_env(kwargs):
    if kwargs.get("scene") == "small":
        kwargs = {**kwargs, "scene": small_house()}
    env = gym.make(ENV_ID, **kwargs)
    check_env(env.unwrapped, warn=True)


def test_callback_logs_the_final_infos_of_single_robot_episodes():
    venv = DummyVecEnv(
        [
            lambda: gym.make(
                ENV_ID,
                scene=small_house(),
                flatten_obs=True,
                task={"termination_config": {"max_steps": 8}},
            )
        ]
    )
    model = PPO("MlpPolicy", venv, n_steps=16, batch_size=16, n_epochs=1, seed=0)
    logger, capture = capture_logger()
    model.set_logger(logger)
    callback = PointNavMetricsCallback()
    model.learn(16, callback=callback)
    assert callback.episodes == 2  # 16 steps of 8-step episodes
    last = capture.dumps[-1]
    assert 0.0 <= last["pointnav/success_rate"] <= 1.0
    assert last["pointnav/episodes"] == 2


# ------------------------------------------------------------------------------ many robots


def scripted_step(venv: MultiRobotVecEnv):
    return venv.step(np.stack([rl_cases.ACTIONS[agent] for agent in rl_cases.AGENTS]))


def test_vec_env_keeps_final_infos_through_a_mixed_termination_and_truncation():
    venv = MultiRobotVecEnv(rl_cases.mixed_end_world())
    assert venv.num_envs == 3
    first = venv.reset()
    assert [info["episode_length"] for info in venv.reset_infos] == [0, 0, 0]

    obs, rewards, dones, infos = scripted_step(venv)  # step 1: robot_2 reaches its goal
    assert dones.tolist() == [False, False, True]
    final_2 = infos[2]
    assert final_2["success"] and final_2["episode_length"] == 1
    assert final_2["TimeLimit.truncated"] is False
    np.testing.assert_array_equal(final_2["terminal_observation"], obs[2])

    for _ in range(3):  # steps 2-4: robot_2's slot is idle
        obs, rewards, dones, infos = scripted_step(venv)
        assert dones.tolist() == [False, False, False]
        assert infos[2] == {"idle": True} and rewards[2] == 0.0
        np.testing.assert_array_equal(obs[2], final_2["terminal_observation"])

    # Step 5: robot_0 terminates (success) and robot_1 is truncated on the same step; the
    # world is reset, and the step's infos are still the final ones, not the reset's.
    obs, rewards, dones, infos = scripted_step(venv)
    assert dones.tolist() == [True, True, False]
    assert infos[2] == {"idle": True}
    for k, agent in enumerate(rl_cases.AGENTS[:2]):
        assert infos[k]["episode_length"] == 5
        assert infos[k]["TimeLimit.truncated"] is (
            rl_cases.TRUNCATED[agent] and not rl_cases.TERMINATED[agent]
        )
    # robot_0's final observation: its goal 0.47 m ahead (the new episode's: 0.72 m).
    assert infos[0]["terminal_observation"][0] == pytest.approx(0.47)
    assert first[0][0] == pytest.approx(0.72)
    assert infos[0]["success"] is True and infos[1]["success"] is False
    np.testing.assert_array_equal(obs, first)  # fixed starts: the new episode starts alike
    assert [info["episode_length"] for info in venv.reset_infos] == [0, 0, 0]

    obs, rewards, dones, infos = scripted_step(venv)  # every slot is live again
    assert all("idle" not in info for info in infos)
    assert dones.tolist() == [False, False, True]


def test_callback_logs_the_success_rate_of_the_final_infos():
    venv = MultiRobotVecEnv(rl_cases.mixed_end_world())
    model = PPO("MlpPolicy", venv, n_steps=8, batch_size=24)
    logger, capture = capture_logger()
    model.set_logger(logger)
    callback = PointNavMetricsCallback()
    callback.init_callback(model)
    venv.reset()
    for _ in range(5):  # one whole episode of the world
        _, _, dones, infos = scripted_step(venv)
        callback.update_locals({"dones": dones, "infos": infos})
        callback.on_step()
    logger.dump()
    logged = capture.dumps[-1]
    assert logged["pointnav/episodes"] == 3
    expected = rl_cases.EXPECTED_MEANS
    assert logged["pointnav/success_rate"] == pytest.approx(2 / 3)
    assert logged["pointnav/success_rate"] == pytest.approx(expected["success"])
    assert logged["pointnav/spl"] == pytest.approx(expected["spl"])
    assert logged["pointnav/soft_spl"] == pytest.approx(expected["soft_spl"])
    assert logged["pointnav/collisions"] == pytest.approx(expected["collisions"])
    assert callback.summary().startswith("last 3 of 3 episodes: success rate 0.67, SPL 0.67")


def test_ppo_learns_on_the_vec_env_across_world_resets():
    venv = VecMonitor(
        make_vec_env(n_worlds=2, n_robots=2, scene=small_house(), max_cycles=6, seed=0)
    )
    model = PPO("MlpPolicy", venv, n_steps=12, batch_size=48, n_epochs=1, seed=0)
    logger, capture = capture_logger()
    model.set_logger(logger)
    callback = PointNavMetricsCallback()
    model.learn(48, callback=callback)
    assert callback.episodes >= 8  # every robot's episode ends at least every 6 steps
    assert {"pointnav/success_rate", "pointnav/spl", "pointnav/soft_spl"} <= set(capture.dumps[-1])
    assert capture.dumps[-1]["rollout/ep_len_mean"] <= 6


def test_seed_seeds_each_world_at_the_next_reset():
    def reset(seed):
        venv = make_vec_env(n_worlds=2, n_robots=2, scene=small_house())
        assert venv.seed(seed) == [seed, seed, seed + 1, seed + 1]
        return venv.reset()

    np.testing.assert_array_equal(reset(3), reset(3))
    assert not np.array_equal(reset(3), reset(4))
    # World 1 of seed 3 is world 0 of seed 4.
    np.testing.assert_array_equal(reset(3)[2:], reset(4)[:2])


def test_attribute_and_method_access_act_on_each_slots_world():
    venv = make_vec_env(n_worlds=2, n_robots=2, scene=small_house(), max_cycles=9)
    venv.reset()
    assert venv.get_attr("max_cycles") == [9, 9, 9, 9]
    venv.set_attr("max_cycles", 4, indices=[1])  # slot 1 lives in world 0
    assert venv.get_attr("max_cycles") == [4, 4, 9, 9]
    states = venv.env_method("state", indices=[0, 1, 3])
    assert states[0] is states[1]  # called once for world 0
    assert states[0].shape == (16,) and not np.array_equal(states[0], states[2])
    assert venv.env_is_wrapped(MultiPointNavEnv) == [True] * 4
    assert venv.env_is_wrapped(gym.Wrapper) == [False] * 4


def test_dict_observations_are_stacked_per_key():
    venv = make_vec_env(n_robots=2, scene=small_house(), flatten_obs=False)
    obs = venv.reset()
    assert {key: value.shape for key, value in obs.items()} == {
        "xy_pos_to_goal": (2, 2),
        "robot_lin_vel": (2, 3),
        "robot_ang_vel": (2, 3),
    }


def test_robots_must_share_their_spaces():
    world = MultiPointNavEnv(
        scene=small_house(), robot=[{"drive": "differential"}, {"drive": "holonomic"}]
    )
    with pytest.raises(ValueError, match="same action space"):
        MultiRobotVecEnv(world)
    with pytest.raises(ValueError, match="its own env object"):
        MultiRobotVecEnv([world, world])
