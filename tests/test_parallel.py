"""MultiPointNav-v0 against PettingZoo's own tests, the multi-robot rules, and bad input."""

from __future__ import annotations

import functools
import itertools
import math
import warnings

import numpy as np
import pettingzoo
import pytest
from pettingzoo.utils.conversions import parallel_to_aec

import pointnav_core  # noqa: F401  (registers the PettingZoo ids)
from pointnav_core import scenes
from pointnav_core.backends.protocol import available_backends
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.envs import multi_pointnav as parallel
from pointnav_core.envs._multi_state import STATE_FIELDS
from pointnav_core.envs.multi_pointnav import MultiPointNavEnv
from pointnav_core.envs.registration import AEC_ENV_IDS, PARALLEL_ENV_IDS, register_envs
from pointnav_core.errors import SamplingError
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID
from pointnav_core.scenes import Scene
from pointnav_core.task import PointNavigationTask, TaskStateError

# pettingzoo.test imports connect_four_v3 through its deprecated module path for a pytest
# fixture of its own, which warns at import time; that warning is upstream's, not ours.
with warnings.catch_warnings():
    warnings.filterwarnings(
        "ignore", message="The old environment creation API", category=DeprecationWarning
    )
    from pettingzoo.test import (
        api_test,
        max_cycles_test,
        parallel_api_test,
        parallel_seed_test,
        render_test,
        state_test,
    )

ENV_ID = "pointnav_core/MultiPointNav-v0"
BACKENDS = available_backends()
# api_test's advice for Dict observations (it prefers Box); the default flat observations
# pass with every warning an error.
DICT_OBS_ADVICE = (
    "Observation space for each agent probably should be gymnasium.spaces.box",
    "Observation is not a NumPy array",
)
RADIUS = RobotSpec().radius
GO = np.array([1.0, 0.0], dtype=np.float32)
YAW_PI = (0.0, 0.0, 1.0, 0.0)  # facing -x


def small_scene() -> Scene:
    """A 4 m x 3 m walled room with a block in it."""
    grid = np.full((30, 40), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[10:20, 15:18] = OBSTACLE
    return Scene.from_array(grid, 0.1)


def corridor_scene() -> Scene:
    """A 6 m corridor, 0.6 m wide inside: two robots of radius 0.18 cannot pass."""
    grid = np.full((8, 60), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return Scene.from_array(grid, 0.1)


CORRIDOR_Y = 0.4  # the corridor's centre line


def lane(start_x: float, goal_x: float, facing: str = "+x", **task) -> dict:
    """Task arguments for a robot on the corridor's centre line, facing +x or -x."""
    quat = (0.0, 0.0, 0.0, 1.0) if facing == "+x" else YAW_PI
    return {
        "initial_pos": (start_x, CORRIDOR_Y, 0.0),
        "initial_quat": quat,
        "goal_pos": (goal_x, CORRIDOR_Y, 0.0),
        **task,
    }


def small_house(seed: int) -> Scene:
    return scenes.rooms(seed=seed, size=(8.0, 6.0))


def xy(env: MultiPointNavEnv, i: int) -> tuple[float, float]:
    x, y, _ = env.backend.get_pose(i)[0].tolist()
    return x, y


def forward(env: MultiPointNavEnv, speed: float = 1.0) -> dict[str, np.ndarray]:
    return {agent: np.array([speed, 0.0], dtype=np.float32) for agent in env.agents}


def still(env: MultiPointNavEnv) -> dict[str, np.ndarray]:
    return forward(env, 0.0)


# ------------------------------------------------------------------------------ upstream tests


@pytest.mark.parametrize("backend", BACKENDS)
def test_parallel_api_test_passes(backend):
    env = parallel.parallel_env(scene=small_scene(), n_robots=3, backend=backend)
    parallel_api_test(env, num_cycles=1000)


@pytest.mark.parametrize("backend", BACKENDS)
def test_aec_api_test_passes_with_flat_observations(backend):
    env = parallel.parallel_env(
        scene=small_scene(), n_robots=3, backend=backend, flatten_obs=True
    )
    api_test(parallel_to_aec(env), num_cycles=300)


def test_api_tests_pass_in_the_default_configuration_with_warnings_as_errors():
    # The registered env exactly as users get it: the default house, robots and tasks.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        parallel_api_test(pettingzoo.make("parallel", ENV_ID), num_cycles=200)
        api_test(pettingzoo.make("aec", ENV_ID), num_cycles=200)


def test_aec_api_test_passes_with_dict_observations_apart_from_its_box_advice():
    env = parallel.parallel_env(scene=small_scene(), n_robots=3, flatten_obs=False)
    with warnings.catch_warnings():
        for message in DICT_OBS_ADVICE:
            warnings.filterwarnings("ignore", message=message, category=UserWarning)
        # Still checks every observation lies in its Dict space with float32 leaves.
        api_test(parallel_to_aec(env), num_cycles=300)


def test_render_test_passes():
    render_test(functools.partial(parallel.env, scene=small_scene(), n_robots=3))


def test_max_cycles_test_passes_on_the_module():
    max_cycles_test(parallel)


def test_state_test_passes():
    state_test(
        parallel.env(scene=small_scene(), n_robots=3),
        parallel.parallel_env(scene=small_scene(), n_robots=3),
    )


def test_upstream_parallel_seed_test_passes():
    parallel_seed_test(functools.partial(parallel.parallel_env, scene=small_scene(), n_robots=3))


@pytest.mark.parametrize("backend", BACKENDS)
def test_same_seed_gives_identical_runs_over_many_steps(backend):
    # Upstream's parallel_seed_test stops after one step; this runs 250, across resets.
    def make():
        return parallel.parallel_env(
            scene=small_scene(), n_robots=3, backend=backend, max_cycles=60,
            task={"termination_config": {"max_collisions": 20}},
        )

    env1, env2 = make(), make()
    rng = np.random.default_rng(7)
    out1, out2 = env1.reset(seed=123), env2.reset(seed=123)
    steps = 0
    for _ in range(250):
        if not env1.agents:
            assert not env2.agents
            out1, out2 = env1.reset(), env2.reset()
        else:
            actions = {
                a: rng.uniform(-1.0, 1.0, 2).astype(np.float32) for a in env1.possible_agents
            }
            actions = {a: actions[a] for a in env1.agents}
            out1, out2 = env1.step(actions), env2.step(actions)
            steps += 1
        for d1, d2 in zip(out1, out2):
            assert d1.keys() == d2.keys()
            for agent in d1:
                a, b = d1[agent], d2[agent]
                if isinstance(a, dict) and "xy_pos_to_goal" in a:
                    for key in a:
                        assert a[key].dtype == b[key].dtype == np.float32
                        np.testing.assert_array_equal(a[key], b[key])
                elif isinstance(a, np.ndarray):  # the default flat observation
                    assert a.dtype == b.dtype == np.float32
                    np.testing.assert_array_equal(a, b)
                else:
                    assert a == b and type(a) is type(b)
        assert env1.agents == env2.agents
        np.testing.assert_array_equal(env1.state(), env2.state())
    assert steps >= 200


def test_different_seeds_give_different_episodes():
    env = parallel.parallel_env(scene=small_scene(), n_robots=2)
    env.reset(seed=1)
    first = env.state()
    env.reset(seed=2)
    assert not np.array_equal(first, env.state())
    env.reset(seed=1)
    np.testing.assert_array_equal(first, env.state())


# ------------------------------------------------------------------------------ registry


def test_pettingzoo_make_builds_the_registered_parallel_env():
    register_envs()  # idempotent, and no "overriding" warning
    assert ENV_ID in PARALLEL_ENV_IDS and ENV_ID in pettingzoo.parallel_registry
    env = pettingzoo.make("parallel", ENV_ID, scene=small_scene(), n_robots=3)
    assert isinstance(env, MultiPointNavEnv)
    assert env.possible_agents == ["robot_0", "robot_1", "robot_2"]
    assert env.max_cycles == 500
    env = pettingzoo.make("parallel", ENV_ID, scene=small_scene(), max_cycles=7)
    assert env.max_cycles == 7


def test_pettingzoo_make_builds_the_aec_form():
    assert ENV_ID in AEC_ENV_IDS and ENV_ID in pettingzoo.aec_registry
    env = pettingzoo.make("aec", ENV_ID, scene=small_scene())
    assert isinstance(env, pettingzoo.AECEnv)
    assert isinstance(env.unwrapped, MultiPointNavEnv)


def test_metadata_name_matches_the_id_and_the_module_functions_agree():
    assert MultiPointNavEnv.metadata["name"] == ENV_ID.split("/")[1]
    assert isinstance(parallel.raw_env(scene=small_scene()), pettingzoo.AECEnv)
    aec = parallel.env(scene=small_scene())
    assert isinstance(aec.unwrapped, MultiPointNavEnv)


# ------------------------------------------------------------------------------ spaces, API


@pytest.mark.parametrize("flat", [True, False])
def test_spaces_are_cached_per_agent_and_match_the_single_robot_env(flat):
    env = parallel.parallel_env(
        scene=small_scene(),
        n_robots=2,
        robot=[{}, {"drive": "holonomic", "radius": 0.15}],
        flatten_obs=flat,
    )
    for agent in env.possible_agents:
        assert env.observation_space(agent) is env.observation_space(agent)
        assert env.action_space(agent) is env.action_space(agent)
    assert env.action_space("robot_0").shape == (2,)
    assert env.action_space("robot_1").shape == (3,)
    assert env.action_space("robot_0") is not env.action_space("robot_1")
    single = pointnav_core.PointNavEnv(scene=small_scene(), flatten_obs=flat)
    assert env.observation_space("robot_0") == single.observation_space
    with pytest.raises(KeyError, match="unknown agent 'robot_9'"):
        env.observation_space("robot_9")


def test_flat_observations_are_the_low_dim_vector():
    env = parallel.parallel_env(scene=small_scene(), n_robots=2, flatten_obs=True)
    obs, _ = env.reset(seed=0)
    for agent, o in obs.items():
        assert o.shape == (8,) and o.dtype == np.float32
        assert env.observation_space(agent).contains(o)


def test_reset_gives_every_agent_its_task_info_and_obs():
    env = parallel.parallel_env(scene=small_scene(), n_robots=3)
    obs, infos = env.reset(seed=0)
    assert env.agents == env.possible_agents == list(obs) == list(infos)
    for i, agent in enumerate(env.agents):
        assert infos[agent]["episode_length"] == 0
        assert "spl" in infos[agent] and "geodesic_dist" in infos[agent]
        assert env.observation_space(agent).contains(obs[agent])
        assert env.tasks[i].robot_idn == i
    _, rewards, terms, truncs, infos = env.step(forward(env))
    for agent in env.possible_agents:
        assert type(rewards[agent]) is float
        assert type(terms[agent]) is bool and type(truncs[agent]) is bool
        assert infos[agent]["episode_length"] == 1


def test_observations_are_fresh_arrays():
    env = parallel.parallel_env(scene=small_scene(), n_robots=2, flatten_obs=True)
    obs1, _ = env.reset(seed=0)
    obs2, *_ = env.step(still(env))
    assert obs1["robot_0"] is not obs2["robot_0"]
    assert not np.shares_memory(obs1["robot_0"], obs2["robot_0"])


def test_state_holds_every_robots_pose_goal_and_activity():
    env = parallel.parallel_env(scene=small_scene(), n_robots=3)
    with pytest.raises(TaskStateError, match="reset"):
        env.state()
    env.reset(seed=0)
    state = env.state()
    assert state.shape == env.state_space.shape == (8 * 3,) and state.dtype == np.float32
    assert env.state_space.contains(state)
    rows = state.reshape(3, len(STATE_FIELDS))
    for i, row in enumerate(rows):
        x, y = xy(env, i)
        np.testing.assert_allclose(row[:2], (x, y), atol=1e-5)
        np.testing.assert_allclose(row[4:6], env.tasks[i].goal_xy, atol=1e-5)
        assert row[7] == 1.0


def test_env_exposes_what_render_env_needs():
    env = parallel.parallel_env(scene=small_scene(), n_robots=3, render_mode="rgb_array")
    assert isinstance(env.tasks, list) and len(env.tasks) == len(env.robots) == 3
    assert env.scene is not None and env.backend.n_robots == 3
    env.reset(seed=0)
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3


def test_render_without_a_mode_warns_and_human_mode_says_it_is_unsupported():
    env = parallel.parallel_env(scene=small_scene())
    env.reset(seed=0)
    with pytest.warns(UserWarning, match="without specifying any render mode"):
        assert env.render() is None
    human = parallel.parallel_env(scene=small_scene(), render_mode="human")
    human.reset(seed=0)
    with pytest.raises(NotImplementedError, match="rgb_array"):
        human.render()


# ------------------------------------------------------------------------------ multi-robot rules


@pytest.mark.parametrize("house", range(3))
def test_eight_robots_in_a_small_house_never_start_overlapping(house):
    env = parallel.parallel_env(scene=small_house(house), n_robots=8)
    tol = env.tasks[0].goal_tolerance
    for seed in range(6):
        env.reset(seed=seed)
        starts = [xy(env, i) for i in range(8)]
        goals = [env.tasks[i].goal_xy for i in range(8)]
        for i, j in itertools.combinations(range(8), 2):
            assert math.dist(starts[i], starts[j]) >= 2 * RADIUS - 1e-9, (seed, i, j)
            assert math.dist(goals[i], goals[j]) >= 2 * tol, (seed, i, j)
        for i in range(8):
            assert env.backend.is_valid_pose(i, starts[i])


def test_robots_with_fixed_starts_are_placed_first():
    # In a 1.2 m room, a robot sampled first would often stand on robot 1's fixed start.
    grid = np.full((14, 14), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    env = parallel.parallel_env(
        scene=Scene.from_array(grid, 0.1),
        n_robots=2,
        # No path_range: the default one starts at 1 m, more than this room offers.
        task=[
            {"goal_tolerance": 0.1, "path_range": None},
            {"goal_tolerance": 0.1, "path_range": None, "initial_pos": (0.7, 0.7, 0.0)},
        ],
    )
    for seed in range(30):
        env.reset(seed=seed)
        assert xy(env, 1) == pytest.approx((0.7, 0.7))
        assert math.dist(xy(env, 0), xy(env, 1)) >= 2 * RADIUS - 1e-9


def corridor_env(backend: str, tasks: list[dict], **kwargs) -> MultiPointNavEnv:
    return parallel.parallel_env(
        scene=corridor_scene(), n_robots=len(tasks), backend=backend, task=tasks, **kwargs
    )


@pytest.mark.parametrize("backend", BACKENDS)
def test_head_on_meeting_in_a_corridor_is_a_collision_for_both_robots(backend):
    env = corridor_env(
        backend,
        [
            lane(1.5, 5.5, "+x"),
            lane(3.5, 0.5, "-x"),
        ],
    )
    env.reset(seed=0)
    met = None
    for step in range(1, 30):
        _, rewards, terms, truncs, infos = env.step(forward(env))
        assert not any(terms.values()) and not any(truncs.values())
        hits = [infos[a]["collisions"] for a in ("robot_0", "robot_1")]
        if met is None and any(hits):
            met = step
            # The first contact is a collision for both, in the same step.
            assert hits == [1, 1]
            for agent in ("robot_0", "robot_1"):
                assert infos[agent]["reward_breakdown"]["collision"] == pytest.approx(-0.1)
        assert math.dist(xy(env, 0), xy(env, 1)) >= 2 * RADIUS - 1e-3
    # They start 2 m apart (1.64 m between discs) and close at 1 m/s.
    assert met is not None and 15 <= met <= 19
    assert infos["robot_0"]["collisions"] == infos["robot_1"]["collisions"] > 1


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("finished", ["park", "remove"])
def test_a_parked_robot_blocks_others_and_a_removed_one_does_not(backend, finished):
    env = corridor_env(
        backend,
        [
            # Starts within goal_tolerance of its goal: done on the first step, then parked.
            lane(2.0, 2.1, goal_tolerance=0.2),
            lane(4.0, 0.5, "-x", goal_tolerance=0.2),
        ],
        finished=finished,
    )
    env.reset(seed=0)
    _, _, terms, _, infos = env.step(still(env))
    assert terms == {"robot_0": True, "robot_1": False} and infos["robot_0"]["success"]
    assert env.agents == ["robot_1"]
    parked_at = env.backend.get_pose(0)[0]
    for _ in range(60):  # 3 m at 0.05 m per step (1.64 m to the parked robot)
        _, _, terms, truncs, infos = env.step(forward(env))
        if not env.agents:
            break
    x1, _ = xy(env, 1)
    if finished == "park":
        assert env.backend.is_present(0)
        assert x1 >= 2.0 + 2 * RADIUS - 1e-3  # stopped at the parked robot
        assert infos["robot_1"]["collisions"] > 0
        np.testing.assert_allclose(env.backend.get_pose(0)[0], parked_at, atol=1e-6)
        assert env.state()[7] == 0.0  # robot_0 is inactive in the state
    else:
        assert not env.backend.is_present(0)
        assert x1 < 2.0 - 2 * RADIUS  # drove through where robot 0 stands
        assert infos["robot_1"]["collisions"] == 0


def test_a_finished_agent_never_reappears_in_agents():
    env = corridor_env(
        "kinematic",
        [
            lane(2.0, 2.1, goal_tolerance=0.2),
            lane(4.0, 5.5, goal_tolerance=0.2),
        ],
        max_cycles=50,
    )
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    seen_after = []
    while env.agents:
        actions = {a: rng.uniform(-1, 1, 2).astype(np.float32) for a in env.agents}
        obs, *_ = env.step(actions)
        seen_after.append(list(env.agents))
        if len(seen_after) > 1:
            assert "robot_0" not in obs
    assert seen_after[0] == ["robot_1"]
    assert all("robot_0" not in agents for agents in seen_after)
    env.reset(seed=0)
    assert env.agents == ["robot_0", "robot_1"]  # a reset brings everyone back


def test_max_cycles_truncates_every_agent_at_once():
    env = parallel.parallel_env(scene=small_scene(), n_robots=3, max_cycles=5)
    env.reset(seed=0)
    for step in range(1, 6):
        _, _, terms, truncs, infos = env.step(still(env))
        assert all(truncs.values()) == (step == 5)
        assert not any(terms.values())
    assert env.agents == []
    assert infos["robot_0"]["episode_length"] == 5
    assert env.state()[7::8].tolist() == [0.0, 0.0, 0.0]


def test_a_robot_that_falls_leaves_the_world():
    grid = np.full((8, 40), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = OBSTACLE
    grid[1:-1, 30:] = VOID  # a drop at x = 3 m
    env = parallel.parallel_env(
        scene=Scene.from_array(grid, 0.1),
        n_robots=2,
        task=[
            {"initial_pos": (2.6, 0.4, 0), "initial_quat": (0, 0, 0, 1), "goal_pos": (0.5, 0.4, 0)},
            {"initial_pos": (1.0, 0.4, 0), "goal_pos": (2.0, 0.4, 0)},
        ],
    )
    env.reset(seed=0)
    for _ in range(20):
        actions = {a: GO if a == "robot_0" else np.zeros(2, np.float32) for a in env.agents}
        _, _, terms, _, infos = env.step(actions)
        if terms.get("robot_0"):
            break
    assert infos["robot_0"]["termination_conditions"]["falling"]["done"]
    assert "robot_0" not in env.agents
    assert not env.backend.is_present(0)  # even with finished="park"
    assert env.state_space.contains(env.state())


# ------------------------------------------------------------------------------ bad input


@pytest.mark.parametrize("n_robots", [0, -1, 1.5, True, "2"])
def test_n_robots_must_be_a_positive_integer(n_robots):
    with pytest.raises(ValueError, match="n_robots must be an integer >= 1"):
        parallel.parallel_env(scene=small_scene(), n_robots=n_robots)


def test_a_task_list_of_the_wrong_length_is_an_error():
    match = r"task must be .* one entry per robot \(n_robots=3\), got a list of 2"
    with pytest.raises(ValueError, match=match):
        parallel.parallel_env(scene=small_scene(), n_robots=3, task=[{}, {}])


def test_a_robot_list_of_the_wrong_length_is_an_error():
    with pytest.raises(ValueError, match=r"robot must be .* \(n_robots=2\), got a list of 3"):
        parallel.parallel_env(scene=small_scene(), n_robots=2, robot=[{}, {}, {}])


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"task": [{}, {"colour": 1}]}, r"task\[1\] has an unknown key 'colour'"),
        ({"task": [{}, {"goal_tolerance": -1}]}, r"task\[1\]: goal_tolerance"),
        ({"task": [{}, {"robot_idn": 0}]}, r"task\[1\] sets robot_idn=0, but the env\w* sets robot_idn=1"),
        ({"task": PointNavigationTask()}, "single PointNavigationTask"),
        ({"task": [{}, {"floor": 3}]}, r"task\[1\]: floor must be in \[0, 1\)"),
        ({"robot": [{}, {"drive": "tank"}]}, r"robot\[1\]: drive must be one of"),
        ({"task": [{"initial_pos": (1, 1)}, {"initial_pos": (1.2, 1)}]}, "fixed starts must be"),
        ({"task": [{"goal_pos": (0.8, 1)}, {"goal_pos": (1.2, 1)}]}, "goals must be distinct"),
        ({"max_cycles": 0}, "max_cycles must be an integer >= 1"),
        ({"finished": "explode"}, r"finished must be one of \['park', 'remove'\]"),
        ({"render_mode": "ansi"}, "render_mode must be None or one of"),
        ({"flatten_obs": "yes"}, "flatten_obs must be True or False"),
        ({"backend": "bullet"}, "backend must be one of"),
        ({"scene": "house"}, "scene must be a pointnav_core Scene"),
    ],
)
def test_bad_arguments_fail_at_construction_naming_the_parameter(kwargs, match):
    kwargs = {"scene": small_scene(), "n_robots": 2, **kwargs}
    with pytest.raises(ValueError, match=match):
        parallel.parallel_env(**kwargs)


def test_goals_of_point_robots_with_next_to_no_tolerance_are_still_a_cell_apart():
    # A tolerance of 0 is refused (no episode could succeed); 1 mm is next to none.
    tasks = [
        {"goal_tolerance": 0.001, "goal_pos": (1.0, 1.0)},
        {"goal_tolerance": 0.001, "goal_pos": (1.05, 1.0)},
    ]
    with pytest.raises(ValueError, match=r"goals must be distinct.* = 0\.1 m apart"):
        parallel.parallel_env(scene=small_scene(), n_robots=2, robot={"radius": 0.0}, task=tasks)
    tasks[1]["goal_pos"] = (1.1, 1.0)
    parallel.parallel_env(scene=small_scene(), n_robots=2, robot={"radius": 0.0}, task=tasks)


def test_task_lists_may_hold_ready_tasks_with_their_own_index():
    tasks = [PointNavigationTask(robot_idn=0), PointNavigationTask(robot_idn=1, goal_tolerance=0.3)]
    env = parallel.parallel_env(scene=small_scene(), n_robots=2, task=tasks)
    assert env.tasks == tasks
    with pytest.raises(ValueError, match=r"task\[0\] has robot_idn=1"):
        parallel.parallel_env(scene=small_scene(), n_robots=2, task=tasks[::-1])


def test_goals_that_cannot_be_made_distinct_raise_sampling_error():
    # Five goals pairwise >= 1.6 m apart do not fit in the 2.24 m square a robot's centre
    # can reach in this 2.6 m room.
    grid = np.full((28, 28), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    env = parallel.parallel_env(
        scene=Scene.from_array(grid, 0.1), n_robots=5, task={"goal_tolerance": 0.8}
    )
    with pytest.raises(SamplingError, match="distinct from the other robots' goals"):
        env.reset(seed=0)
    assert env.agents == []
    with pytest.raises(TaskStateError, match="failed half-way"):
        env.step({})


def snapshot(env: MultiPointNavEnv) -> tuple:
    poses = [env.backend.get_pose(i)[0].tolist() for i in range(len(env.robots))]
    steps = [t.episode_length for t in env.tasks]
    return list(env.agents), poses, steps, env.state().tolist()


def finished_robot_0_env() -> MultiPointNavEnv:
    env = corridor_env(
        "kinematic",
        [
            lane(2.0, 2.1, goal_tolerance=0.2),
            lane(4.0, 5.5, goal_tolerance=0.2),
        ],
    )
    env.reset(seed=0)
    env.step(still(env))
    assert env.agents == ["robot_1"]
    return env



@pytest.mark.parametrize(
    ("actions", "match"),
    [
        ({"robot_1": GO, "robot_0": GO}, "action for robot_0, which is not alive"),
        ({"robot_0": GO}, "missing action for robot_1"),
        ({}, "missing action for robot_1"),
        ({"robot_1": None}, "missing action for robot_1: got None"),
        ({"robot_7": GO}, "missing action for robot_1"),
        ({"robot_1": GO, "robot_7": GO}, "unknown agent 'robot_7'"),
        ({"robot_1": np.array([np.nan, 0.0])}, "robot_1: action must be finite"),
        ({"robot_1": np.zeros(3)}, r"robot_1: action must have shape \(2,\)"),
        ({"robot_1": "fast"}, "robot_1: action must be an array of 2 real numbers"),
        ([GO], "actions must be a dict"),
    ],
    ids=[
        "not-alive", "missing", "empty", "none", "unknown-instead", "unknown-extra", "nan",
        "shape", "text", "not-a-dict",
    ],
)
def test_bad_actions_raise_and_change_nothing(actions, match):
    env = finished_robot_0_env()
    before = snapshot(env)
    with pytest.raises(ValueError, match=match):
        env.step(actions)
    assert snapshot(env) == before
    env.step({"robot_1": GO})  # the env still works
    assert env.tasks[1].episode_length == 2


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_non_finite_action_names_its_agent_and_changes_nothing(backend):
    env = corridor_env(backend, [lane(0.5, 1.5), lane(2.5, 3.5), lane(4.5, 5.5)])
    env.reset(seed=0)
    before = snapshot(env)
    actions = {"robot_0": GO, "robot_1": [0.5, np.inf], "robot_2": np.array([np.nan, 0.0])}
    with pytest.raises(ValueError, match=r"^robot_1: action must be finite"):
        env.step(actions)
    assert snapshot(env) == before
    env.step({agent: GO for agent in env.agents})  # the env still works
    assert [t.episode_length for t in env.tasks] == [1, 1, 1]


def test_step_before_reset_and_after_the_end_is_a_state_error():
    env = parallel.parallel_env(scene=small_scene(), n_robots=2, max_cycles=1)
    with pytest.raises(TaskStateError, match="call reset"):
        env.step({})
    env.reset(seed=0)
    env.step(still(env))
    assert env.agents == []
    with pytest.raises(TaskStateError, match="every agent's episode has ended"):
        env.step({})


def test_reset_options_must_be_a_dict_or_none():
    env = parallel.parallel_env(scene=small_scene())
    env.reset(seed=0, options={"anything": 1})
    with pytest.raises(ValueError, match="options must be None or a dict"):
        env.reset(options=3)
