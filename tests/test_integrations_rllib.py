"""RLlib: the multi-agent env passes RLlib's checker and ends episodes with ``"__all__"``
exactly when the last robots finish (also when some terminate and others are truncated on
that step), the callback reports the final infos' metrics, and PPO trains on the
registered id in a remote env runner of a loopback-only local Ray instance."""

from __future__ import annotations

import numpy as np
import pytest
import ray
import rl_cases
from ray.rllib.algorithms.ppo import PPOConfig
from ray.rllib.core.rl_module.default_model_config import DefaultModelConfig
from ray.rllib.env.multi_agent_episode import MultiAgentEpisode
from ray.rllib.env.single_agent_episode import SingleAgentEpisode
from ray.rllib.env.wrappers.pettingzoo_env import ParallelPettingZooEnv
from ray.rllib.utils.metrics.metrics_logger import MetricsLogger
from ray.rllib.utils.pre_checks.env import check_multiagent_environments
from ray.tune.registry import ENV_CREATOR, _global_registry

from pointnav_core import scenes
from pointnav_core.envs.multi_pointnav import MultiPointNavEnv
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.integrations.rllib import (
    MULTI_ENV_ID,
    SINGLE_ENV_ID,
    PointNavMetricsCallbacks,
    PointNavMultiAgentEnv,
    init_local_ray,
    make_single_env,
    register_rllib_envs,
)


def small_house() -> scenes.Scene:
    return scenes.rooms(seed=0, size=(8.0, 6.0))


@pytest.mark.parametrize("flatten_obs", [True, False])
def test_rllib_env_checker_passes(flatten_obs):
    env = PointNavMultiAgentEnv({"scene": small_house(), "n_robots": 3, "flatten_obs": flatten_obs})
    check_multiagent_environments(env)


def test_agents_are_lists_in_the_env_order_and_flat_by_default():
    env = PointNavMultiAgentEnv({"scene": small_house(), "n_robots": 3})
    assert env.possible_agents == ["robot_0", "robot_1", "robot_2"]
    obs, infos = env.reset(seed=0)
    assert list(obs) == list(infos) == env.agents == env.possible_agents
    assert list(env.observation_spaces) == list(env.action_spaces) == env.possible_agents
    assert env.get_observation_space("robot_1").shape == (8,)
    assert env.get_action_space("robot_1").shape == (2,)


def run_mixed_episode(on_step=None):
    """Step the rl_cases world to its end; return what each step gave."""
    env = PointNavMultiAgentEnv(env=rl_cases.mixed_end_world())
    obs, infos = env.reset(seed=0)
    steps = []
    for _ in range(10):
        actions = {agent: rl_cases.ACTIONS[agent] for agent in env.agents}
        result = env.step(actions)
        steps.append((actions, *result))
        if on_step is not None:
            on_step(actions, *result)
        if result[2]["__all__"] or result[3]["__all__"]:
            break
    return env, (obs, infos), steps


def test_all_is_true_exactly_on_the_step_the_last_robots_finish_mixed_ends():
    env, _, steps = run_mixed_episode()
    assert len(steps) == 5
    for t, (_, obs, rewards, terminateds, truncateds, infos) in enumerate(steps, start=1):
        stepped = [a for a in rl_cases.AGENTS if rl_cases.END_STEP[a] >= t]
        assert list(obs) == list(rewards) == list(infos) == stepped
        assert [a for a in terminateds if a != "__all__"] == stepped
        for agent in stepped:
            ends = rl_cases.END_STEP[agent] == t
            assert terminateds[agent] is (ends and rl_cases.TERMINATED[agent])
            assert truncateds[agent] is (ends and rl_cases.TRUNCATED[agent])
        # Step 5: robot_0 terminates, robot_1 is truncated: the episode was cut.
        assert terminateds["__all__"] is False
        assert truncateds["__all__"] is (t == 5)
    assert env.agents == []


def test_all_is_in_terminateds_when_no_robot_was_cut():
    tasks = [dict(task, termination_config={"max_steps": 50}) for task in rl_cases.TASKS]
    tasks[1]["goal_pos"] = (1.1, 1.5, 0.0)  # robot_1 stands inside its tolerance
    env = PointNavMultiAgentEnv(
        env=MultiPointNavEnv(scene=rl_cases.open_room(), n_robots=3, task=tasks, flatten_obs=True)
    )
    env.reset(seed=0)
    _, _, terminateds, truncateds, _ = env.step({a: rl_cases.ACTIONS[a] for a in env.agents})
    assert terminateds == {"robot_0": False, "robot_1": True, "robot_2": True, "__all__": False}
    for _ in range(4):
        _, _, terminateds, truncateds, _ = env.step({"robot_0": rl_cases.ACTIONS["robot_0"]})
    assert terminateds == {"robot_0": True, "__all__": True}
    assert truncateds == {"robot_0": False, "__all__": False}


def test_all_is_in_truncateds_when_max_cycles_cuts_every_robot():
    env = PointNavMultiAgentEnv({"scene": small_house(), "n_robots": 2, "max_cycles": 3})
    env.reset(seed=0)
    for t in range(1, 4):
        _, _, terminateds, truncateds, _ = env.step(
            {a: np.zeros(2, np.float32) for a in env.agents}
        )
        assert terminateds["__all__"] is False
        assert truncateds["__all__"] is (t == 3)


def test_rllib_episode_takes_the_mixed_end_and_is_done_only_at_its_end():
    env = PointNavMultiAgentEnv(env=rl_cases.mixed_end_world())
    episode = MultiAgentEpisode(
        observation_space=env.observation_spaces, action_space=env.action_spaces
    )
    callbacks = PointNavMetricsCallbacks()
    logger = MetricsLogger()
    obs, infos = env.reset(seed=0)
    episode.add_env_reset(observations=obs, infos=infos)
    t = 0
    while not episode.is_done:
        t += 1
        actions = {agent: rl_cases.ACTIONS[agent] for agent in env.agents}
        obs, rewards, terminateds, truncateds, infos = env.step(actions)
        episode.add_env_step(
            obs, actions, rewards, infos, terminateds=terminateds, truncateds=truncateds
        )
        callbacks.on_episode_step(episode=episode)
        assert episode.is_done is (t == 5)
    callbacks.on_episode_end(episode=episode, metrics_logger=logger, env_index=0)

    # Each robot's final info, read on the step it finished, as computed by hand.
    stash = episode.custom_data[PointNavMetricsCallbacks._STASH]
    for agent, expected in rl_cases.EXPECTED.items():
        assert stash[agent] == pytest.approx(expected)
    for key, expected in rl_cases.EXPECTED_MEANS.items():
        assert logger.peek(("pointnav", key)) == pytest.approx(expected)
    assert logger.peek(("pointnav", "success")) == pytest.approx(2 / 3)


def test_callback_reads_single_robot_episodes_too():
    # robot_2 of rl_cases alone: its goal is inside the tolerance, success on step 1.
    task = rl_cases.TASKS[2]
    env = make_single_env({"scene": rl_cases.open_room(), "task": task})
    episode = SingleAgentEpisode()
    logger = MetricsLogger()
    obs, info = env.reset(seed=0)
    episode.add_env_reset(obs, info)
    obs, reward, terminated, truncated, info = env.step(rl_cases.ACTIONS["robot_2"])
    episode.add_env_step(
        obs, rl_cases.ACTIONS["robot_2"], reward, info, terminated=terminated, truncated=truncated
    )
    PointNavMetricsCallbacks().on_episode_end(episode=episode, metrics_logger=logger, env_index=0)
    for key, expected in rl_cases.EXPECTED["robot_2"].items():
        assert logger.peek(("pointnav", key)) == pytest.approx(expected)


def test_render_takes_no_argument_and_rllibs_own_wrapper_can_render():
    world = MultiPointNavEnv(scene=small_house(), n_robots=2, render_mode="rgb_array")
    env = PointNavMultiAgentEnv(env=world)
    env.reset(seed=0)
    assert env.render().shape[2] == 3
    upstream = ParallelPettingZooEnv(world)  # calls render(self.render_mode)
    assert upstream.render().shape[2] == 3
    assert world.render("rgb_array").shape[2] == 3
    with pytest.raises(ValueError, match="render_mode given at construction"):
        world.render("human")


def test_single_env_creator_gives_flat_observations():
    env = make_single_env({"scene": small_house()})
    assert isinstance(env, PointNavEnv) and env.observation_space.shape == (8,)


@pytest.fixture(scope="module")
def local_ray():
    init_local_ray(num_cpus=2, log_to_driver=False)
    yield
    ray.shutdown()


def test_ppo_trains_on_the_registered_id_in_a_remote_env_runner(local_ray):
    assert {node["NodeManagerAddress"] for node in ray.nodes()} == {"127.0.0.1"}
    assert register_rllib_envs() == (SINGLE_ENV_ID, MULTI_ENV_ID)
    assert _global_registry.contains(ENV_CREATOR, MULTI_ENV_ID)
    config = (
        PPOConfig()
        .environment(
            MULTI_ENV_ID, env_config={"scene": small_house(), "n_robots": 2, "max_cycles": 20}
        )
        .multi_agent(policies={"shared"}, policy_mapping_fn=lambda agent, *args, **kwargs: "shared")
        # One remote runner: it builds the env from the registry in another process.
        .env_runners(num_env_runners=1, num_envs_per_env_runner=1)
        .training(train_batch_size_per_learner=80, minibatch_size=40, num_epochs=1)
        .rl_module(model_config=DefaultModelConfig(fcnet_hiddens=[16]))
        .callbacks(PointNavMetricsCallbacks)
    )
    algo = config.build_algo()
    try:
        result = algo.train()
    finally:
        algo.stop()
    runners = result["env_runners"]
    assert runners["num_env_steps_sampled"] >= 80
    assert set(runners["pointnav"]) == {"success", "spl", "soft_spl", "collisions"}
    assert 0.0 <= runners["pointnav"]["success"] <= 1.0
