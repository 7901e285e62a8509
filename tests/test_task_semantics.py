"""What PointNavigationTask computes, step by step, on tiny maps where it can be done by hand.

Maps are 0.1 m grids with a one-cell wall around them; the robot has radius 0.1 m and drives
0.05 m per step at full forward speed (0.5 m/s at 10 Hz), so positions are easy to predict.

Every test that runs an episode runs on every registered backend (the ``backend`` fixture;
the ids are the backend names) with the same hand-computed numbers: in open space both
shipped backends move a robot exactly along its drive's arc, and against these axis-aligned
walls the kinematic backend's sliding and pymunk's frictionless contact response end the
robot in the same place (to within pymunk's 1e-6 m contact slop) and flag the same steps.
Where expectations depend on where the robot ends up, they are computed from the positions
the env reports.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pointnav_core import scenes
from pointnav_core.backends.protocol import available_backends, get_backend
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID
from pointnav_core.scenes import Scene
from pointnav_core.task import PointNavigationTask, TaskState, TaskStateError
from pointnav_core.task.rewards import PointGoalReward
from pointnav_core.task.terminations import TerminationCondition
from pointnav_core.transforms import quat2yaw

RES = 0.1
ROBOT = RobotSpec(radius=0.1)
STEP = 0.05  # metres per step at full forward speed
FORWARD = np.array([1.0, 0.0], dtype=np.float32)
BACKWARD = np.array([-1.0, 0.0], dtype=np.float32)
STOP = np.zeros(2, dtype=np.float32)


def quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def room(rows: int = 20, cols: int = 60) -> np.ndarray:
    """A walled room: free inside x in (0.1, cols/10 - 0.1), y in (0.1, rows/10 - 0.1)."""
    grid = np.full((rows, cols), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return grid


@pytest.fixture(params=available_backends())
def backend(request) -> str:
    """Every registered backend, by name (the test ids)."""
    return request.param


def make_env(backend: str, grid: np.ndarray | list[np.ndarray], **task) -> PointNavEnv:
    return PointNavEnv(scene=Scene.from_array(grid, RES), robot=ROBOT, task=task, backend=backend)


def planar_distance(env: PointNavEnv, xy) -> float:
    pos = env.task.get_current_pos(env)
    return math.hypot(xy[0] - pos[0], xy[1] - pos[1])


# ------------------------------------------------------------------------------ rewards


def test_l2_potential_reward_matches_the_formula_on_every_step(backend):
    goal = (3.0, 1.0)
    env = make_env(
        backend,
        room(),
        initial_pos=(1.0, 1.0, 0.0),
        initial_quat=quat(0.0),
        goal_pos=(*goal, 0.0),
        reward_config={"r_potential": 2.0},
    )
    _, info = env.reset(seed=0)
    assert info["potential_metric"] == "l2"
    previous = 2.0
    actions = [FORWARD] * 10 + [np.array([0.5, 1.0], np.float32)] * 5 + [BACKWARD] * 3
    for k, action in enumerate(actions, start=1):
        _, reward, terminated, truncated, info = env.step(action)
        current = planar_distance(env, goal)
        breakdown = info["reward_breakdown"]
        assert breakdown["potential"] == pytest.approx(2.0 * (previous - current), abs=1e-12)
        assert breakdown["collision"] == 0.0
        assert breakdown["pointgoal"] == 0.0
        assert sum(breakdown.values()) == reward
        assert (terminated, truncated) == (False, False)
        if k == 10:  # ten steps straight ahead: 0.5 m closer, reward 2 * 0.5 in total
            assert env.task.get_current_pos(env)[:2] == pytest.approx([1.5, 1.0], abs=1e-12)
            assert current == pytest.approx(1.5, abs=1e-12)
        previous = current


def test_slack_costs_r_slack_every_step_and_is_absent_by_default(backend):
    goal = (3.0, 1.0)
    kw = {"initial_pos": (1.0, 1.0, 0.0), "initial_quat": quat(0.0), "goal_pos": (*goal, 0.0)}
    env = make_env(backend, room(), reward_config={"r_slack": 0.25}, **kw)
    env.reset(seed=0)
    total = 0.0
    for _ in range(12):  # 0.6 m straight ahead: potential 2.0 -> 1.4, twelve costs of 0.25
        _, reward, _, _, info = env.step(FORWARD)
        assert list(info["reward_breakdown"]) == ["potential", "collision", "pointgoal", "slack"]
        assert info["reward_breakdown"]["slack"] == -0.25
        total += reward
    assert total == pytest.approx((2.0 - 1.4) - 12 * 0.25, abs=1e-9)
    plain = make_env(backend, room(), **kw)  # OmniGibson's task: no slack term at all
    plain.reset(seed=0)
    assert list(plain.step(FORWARD)[4]["reward_breakdown"]) == ["potential", "collision", "pointgoal"]


@pytest.mark.parametrize("bad", [-0.01, True, "0.01", float("nan")])
def test_a_bad_r_slack_is_refused_by_name(bad):
    with pytest.raises(ValueError, match="r_slack"):
        PointNavigationTask(reward_config={"r_slack": bad})


def wall_with_gap() -> np.ndarray:
    """4 m x 4 m room split by a wall at x in [2.0, 2.1] from y = 0 up to y = 3.0."""
    grid = room(40, 40)
    grid[:30, 20] = OBSTACLE
    return grid


def test_geodesic_potential_reward_uses_the_geodesic_distance_around_the_wall(backend):
    start, goal = (1.0, 1.0), (3.0, 1.0)
    env = make_env(
        backend,
        wall_with_gap(),
        initial_pos=(*start, 0.0),
        initial_quat=quat(math.pi / 2),  # facing +y, along the wall
        goal_pos=(*goal, 0.0),
        reward_type="geodesic",
    )
    _, info = env.reset(seed=0)
    assert info["potential_metric"] == "geodesic"
    # By hand: the robot's centre (radius r = 0.1 m) wraps the wall's two top corners,
    # (2.0, 3.0) then (2.1, 3.0): a tangent, an arc up to the top of the first circle, the
    # 0.1 m segment along y = 3.1, an arc down the second circle, a tangent to the goal.
    r = ROBOT.radius

    def by_hand(x: float, y: float) -> float:
        d1 = math.hypot(x - 2.0, y - 3.0)
        leave = (math.atan2(y - 3.0, x - 2.0) - math.acos(r / d1)) % (2 * math.pi)
        d2 = math.hypot(goal[0] - 2.1, goal[1] - 3.0)
        arrive = math.atan2(goal[1] - 3.0, goal[0] - 2.1) + math.acos(r / d2)
        arcs = r * (leave - math.pi / 2) + r * (math.pi / 2 - arrive)
        return math.sqrt(d1 * d1 - r * r) + arcs + 0.1 + math.sqrt(d2 * d2 - r * r)

    assert info["geodesic_dist"] == pytest.approx(by_hand(*start), abs=1e-9)
    assert info["geodesic_dist"] > 2.0 + 2.0  # far longer than the straight line (2 m)
    previous = info["distance_to_goal"]
    for _ in range(20):
        _, reward, _, _, info = env.step(FORWARD)
        pos = env.task.get_current_pos(env)
        current = env.scene.geodesic_distance(0, pos, goal, robot=ROBOT)
        assert info["distance_to_goal"] == pytest.approx(current, abs=1e-12)
        assert current == pytest.approx(by_hand(pos[0], pos[1]), abs=1e-9)
        assert info["reward_breakdown"]["potential"] == pytest.approx(previous - current, abs=1e-12)
        assert sum(info["reward_breakdown"].values()) == reward
        previous = current


def test_unreachable_goal_uses_l2_potential_for_the_whole_episode(backend):
    grid = room(20, 40)
    grid[:, 20] = OBSTACLE  # two closed rooms
    env = make_env(
        backend,
        grid,
        initial_pos=(1.0, 1.0, 0.0),
        initial_quat=quat(0.0),
        goal_pos=(3.0, 1.0, 0.0),
        reward_type="geodesic",
    )
    _, info = env.reset(seed=0)
    assert info["geodesic_dist"] == math.inf
    assert info["potential_metric"] == "l2"
    previous = 2.0
    for _ in range(5):
        _, reward, _, _, info = env.step(FORWARD)
        current = planar_distance(env, (3.0, 1.0))
        assert info["reward_breakdown"]["potential"] == pytest.approx(previous - current, abs=1e-12)
        assert math.isfinite(reward)
        assert info["potential_metric"] == "l2"
        assert info["spl"] == 0.0 and info["soft_spl"] == 0.0
        assert info["distance_to_goal"] == math.inf
        previous = current


def test_geodesic_potential_stays_finite_while_the_robot_slides_along_a_wall(backend):
    # Standing against a wall, the robot's centre is in a cell whose centre is closer to
    # the wall than its radius; the geodesic must still be defined there.
    env = make_env(
        backend,
        room(20, 60),
        initial_pos=(3.0, 1.0, 0.0),
        initial_quat=quat(math.radians(80)),  # nearly straight at the top wall
        goal_pos=(5.0, 1.5, 0.0),
        reward_type="geodesic",
    )
    env.reset(seed=0)
    touched = 0
    for _ in range(40):
        _, reward, _, _, info = env.step(FORWARD)
        touched += env.backend.in_contact(0)
        assert math.isfinite(reward)
        assert math.isfinite(info["distance_to_goal"])
        assert info["distance_to_goal"] >= planar_distance(env, (5.0, 1.5)) - 1e-9
    assert touched > 10  # it really did slide along the wall


def test_collision_penalty_exactly_on_the_steps_that_touch_the_wall(backend):
    # The right wall's inner face is at x = 5.9, so the robot's centre stops at x = 5.8.
    env = make_env(
        backend,
        room(),
        initial_pos=(5.025, 1.0, 0.0),
        initial_quat=quat(0.0),
        goal_pos=(1.0, 1.0, 0.0),
        reward_config={"r_collision": 0.25},
    )
    env.reset(seed=0)
    contacts = []
    for k in range(1, 21):
        _, reward, terminated, _, info = env.step(FORWARD)
        free_x = 5.025 + STEP * k  # where it would be without the wall
        expect_contact = free_x > 5.8
        assert info["reward_breakdown"]["collision"] == (-0.25 if expect_contact else 0.0)
        assert sum(info["reward_breakdown"].values()) == reward
        contacts.append(expect_contact)
        assert info["collisions"] == sum(contacts)
        assert not terminated
    assert contacts.index(True) == 15  # the 16th step is the first to touch
    assert env.task.get_current_pos(env)[0] == pytest.approx(5.8, abs=1e-6)
    for _ in range(3):  # backing away touches nothing
        _, _, _, _, info = env.step(BACKWARD)
        assert info["reward_breakdown"]["collision"] == 0.0
        assert info["collisions"] == 5


def test_max_collision_ends_the_episode_when_the_counter_exceeds_max_collisions(backend):
    env = make_env(
        backend,
        room(),
        initial_pos=(5.025, 1.0, 0.0),
        initial_quat=quat(0.0),
        goal_pos=(1.0, 1.0, 0.0),
        termination_config={"max_collisions": 3},
    )
    env.reset(seed=0)
    for k in range(1, 19):  # contacts on steps 16, 17, 18: the counter reaches 3
        _, _, terminated, truncated, info = env.step(FORWARD)
        assert (terminated, truncated) == (False, False), k
    _, _, terminated, truncated, info = env.step(FORWARD)  # step 19: the 4th contact
    assert (terminated, truncated) == (True, False)
    assert info["collisions"] == 4
    assert info["termination_conditions"]["max_collision"] == {"done": True, "success": False}
    assert info["success"] is False and info["done"] is True
    assert env.task.state is TaskState.DONE


def test_goal_reward_is_paid_on_the_success_step_only(backend):
    env = make_env(
        backend,
        room(),
        initial_pos=(1.0, 1.0, 0.0),
        initial_quat=quat(0.0),
        goal_pos=(2.02, 1.0, 0.0),
        goal_tolerance=0.5,
        reward_config={"r_pointgoal": 7.0},
    )
    env.reset(seed=0)
    steps = 0
    while True:
        _, reward, terminated, truncated, info = env.step(FORWARD)
        steps += 1
        if terminated:
            break
        assert info["reward_breakdown"]["pointgoal"] == 0.0
        assert info["spl"] == 0.0  # reported on every step, 0 until success
    # Distance 1.02 - 0.05 k < 0.5 first at k = 11.
    assert steps == 11
    assert info["reward_breakdown"]["pointgoal"] == 7.0
    assert sum(info["reward_breakdown"].values()) == reward
    assert info["success"] is True and truncated is False
    assert info["termination_conditions"]["pointgoal"] == {"done": True, "success": True}
    assert info["path_length"] == pytest.approx(11 * STEP, abs=1e-12)
    assert info["spl"] == 1.0  # drove straight: L = 0.55 <= d0 = 1.02
    assert info["soft_spl"] == pytest.approx(1.0 - 0.47 / 1.02, abs=1e-9)


# ------------------------------------------------------------------------------ episode end


@pytest.mark.parametrize("episodes", [3])
def test_timeout_truncates_after_exactly_max_steps_in_every_episode(episodes, backend):
    env = make_env(backend, room(), initial_pos=(1.0, 1.0, 0.0), goal_pos=(5.0, 1.0, 0.0),
                   termination_config={"max_steps": 5})
    for _ in range(episodes):
        env.reset()
        for k in range(1, 5):
            _, _, terminated, truncated, info = env.step(STOP)
            assert (terminated, truncated) == (False, False)
            assert info["episode_length"] == k
        _, _, terminated, truncated, info = env.step(STOP)
        assert (terminated, truncated) == (False, True)
        assert info["episode_length"] == 5
        assert info["termination_conditions"]["timeout"] == {"done": True, "success": False}
        assert info["done"] is True and info["success"] is False


def test_timeout_and_success_on_the_same_step_are_both_reported(backend):
    env = make_env(backend, room(), initial_pos=(1.0, 1.0, 0.0), initial_quat=quat(0.0),
                   goal_pos=(1.52, 1.0, 0.0), termination_config={"max_steps": 1})
    env.reset(seed=0)
    _, _, terminated, truncated, info = env.step(FORWARD)
    assert (terminated, truncated) == (True, True)
    assert info["success"] is True


def test_falling_ends_an_episode_that_drives_into_void(backend):
    grid = room(20, 60)
    grid[1:-1, 40:-1] = VOID  # a hole from x = 4.0 on
    env = make_env(backend, grid, initial_pos=(3.025, 1.0, 0.0), initial_quat=quat(0.0),
                   goal_pos=(1.0, 1.0, 0.0), reward_type="geodesic")
    env.reset(seed=0)
    for k in range(1, 20):  # x = 3.025 + 0.05 k stays below 4.0 up to k = 19
        _, reward, terminated, _, info = env.step(FORWARD)
        assert not terminated, k
    _, reward, terminated, truncated, info = env.step(FORWARD)  # over the hole
    assert (terminated, truncated) == (True, False)
    assert info["termination_conditions"]["falling"] == {"done": True, "success": False}
    assert info["success"] is False
    assert env.task.get_current_pos(env)[2] < -0.03
    assert math.isfinite(reward)  # no geodesic over void: the potential is held


# ------------------------------------------------------------------------------ metrics


def test_one_step_success_gets_spl_of_its_efficiency(backend):
    # OmniGibson reported SPL = 0 here: it never counted the final step.
    env = make_env(backend, room(), initial_pos=(1.0, 1.0, 0.0), initial_quat=quat(0.0),
                   goal_pos=(1.6, 1.0, 0.0), goal_tolerance=0.58)
    _, info = env.reset(seed=0)
    d0 = info["geodesic_dist"]
    assert d0 == pytest.approx(0.6, abs=1e-12)
    _, _, terminated, _, info = env.step(FORWARD)
    assert terminated and info["success"]
    assert info["path_length"] == pytest.approx(STEP, abs=1e-12)
    assert info["spl"] == d0 / max(d0, info["path_length"]) == 1.0


def test_spl_counts_the_final_step_in_the_path_length(backend):
    # Start 1 cm from the goal and drive 5 cm: L > d0, so SPL = d0 / L.
    env = make_env(backend, room(), initial_pos=(1.0, 1.0, 0.0), initial_quat=quat(math.pi),
                   goal_pos=(1.01, 1.0, 0.0), goal_tolerance=0.5)
    _, info = env.reset(seed=0)
    _, _, _, _, info = env.step(FORWARD)
    assert info["success"]
    assert info["path_length"] == pytest.approx(0.05, abs=1e-12)
    assert info["spl"] == pytest.approx(0.01 / 0.05, abs=1e-9)


# ------------------------------------------------------------------------------ observations


@pytest.mark.parametrize("polar", [False, True])
def test_goal_observation_of_a_rotated_robot_matches_hand_values(polar, backend):
    # Facing +y, a goal 2 m along +x and 0.5 m along +y is 0.5 m ahead and 2 m to the right.
    env = make_env(backend, room(40, 60), initial_pos=(1.0, 1.0, 0.0), initial_quat=quat(math.pi / 2),
                   goal_pos=(3.0, 1.5, 0.0), goal_in_polar=polar)
    obs, _ = env.reset(seed=0)
    expected = [math.hypot(0.5, 2.0), math.atan2(-2.0, 0.5)] if polar else [0.5, -2.0]
    assert obs["xy_pos_to_goal"].dtype == np.float32
    np.testing.assert_allclose(obs["xy_pos_to_goal"], expected, atol=1e-6)
    # One step ahead (+y in the world): 0.05 m nearer along the robot's x, still facing +y.
    obs, *_ = env.step(FORWARD)
    expected = [math.hypot(0.45, 2.0), math.atan2(-2.0, 0.45)] if polar else [0.45, -2.0]
    np.testing.assert_allclose(obs["xy_pos_to_goal"], expected, atol=1e-6)
    # World velocity (0, 0.5, 0) is straight ahead in the robot frame.
    np.testing.assert_allclose(obs["robot_lin_vel"], [0.5, 0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(obs["robot_ang_vel"], [0.0, 0.0, 0.0], atol=1e-6)


def test_angular_velocity_observation_is_the_yaw_rate(backend):
    env = make_env(backend, room(40, 60), initial_pos=(2.0, 2.0, 0.0), initial_quat=quat(1.0),
                   goal_pos=(5.0, 2.0, 0.0))
    env.reset(seed=0)
    obs, *_ = env.step(np.array([0.0, -0.5], np.float32))  # turn right at 0.75 rad/s
    np.testing.assert_allclose(obs["robot_ang_vel"], [0.0, 0.0, -0.75], atol=1e-6)
    np.testing.assert_allclose(obs["robot_lin_vel"], [0.0, 0.0, 0.0], atol=1e-6)


def test_observations_are_fresh_arrays_on_every_call(backend):
    env = make_env(backend, room(), initial_pos=(1.0, 1.0, 0.0), goal_pos=(3.0, 1.0, 0.0))
    first, _ = env.reset(seed=0)
    second = env.task.get_obs(env)
    for key in first:
        assert not np.shares_memory(first[key], second[key])
    first["xy_pos_to_goal"][:] = 99.0
    assert env.task.get_obs(env)["xy_pos_to_goal"][0] != 99.0


# ------------------------------------------------------------------------------ sampling and floors


def test_sampled_episodes_respect_path_range_and_reachability(backend):
    env = make_env(backend, wall_with_gap(), path_range=(3.0, 4.5), goal_tolerance=0.3)
    for seed in range(5):
        _, info = env.reset(seed=seed)
        task = env.task
        assert 3.0 < info["geodesic_dist"] < 4.5
        start, goal = task.get_start_pos(), task.get_goal_pos()
        _, length = env.scene.get_shortest_path(0, start, goal, entire_path=True, robot=ROBOT)
        assert length == pytest.approx(info["geodesic_dist"], abs=1e-9)
        assert math.hypot(*(goal[:2] - start[:2])) >= 0.3
        assert env.backend.is_valid_pose(0, start)


def test_fixed_start_with_sampled_goal_and_fixed_goal_with_sampled_start(backend):
    env = make_env(backend, room(), initial_pos=(1.0, 1.0, 0.0), goal_tolerance=0.2)
    env.reset(seed=1)
    assert env.task.get_start_pos()[:2].tolist() == [1.0, 1.0]
    assert math.isfinite(env.task.geodesic_dist)
    env = make_env(backend, room(), goal_pos=(4.0, 1.0, 0.0), goal_tolerance=0.2)
    env.reset(seed=1)
    assert env.task.get_goal_pos()[:2].tolist() == [4.0, 1.0]
    assert math.isfinite(env.task.geodesic_dist)


def test_a_start_sampled_for_a_fixed_goal_never_lands_within_its_tolerance(backend):
    # A 1.4 m square room whose usable cells lie mostly within 0.5 m of its centre: a start
    # drawn there would win the episode at reset.
    goal = (0.7, 0.7, 0.0)
    # No path_range: the default one starts at 1 m, more than this room offers.
    env = make_env(backend, room(14, 14), goal_pos=goal, goal_tolerance=0.5, path_range=None)
    for seed in range(30):
        _, info = env.reset(seed=seed)
        start = env.task.get_start_pos()
        assert math.hypot(start[0] - goal[0], start[1] - goal[1]) >= 0.5


def test_task_on_an_upper_floor_lands_the_robot_at_that_floor_height(backend):
    env = make_env(backend, [room(), room()], floor=1, initial_pos=(1.0, 1.0, 0.0), goal_pos=(3.0, 1.0, 0.0))
    _, info = env.reset(seed=0)
    assert env.task.get_current_pos(env)[2] == 3.0
    assert env.task.get_goal_pos()[2] == 3.0
    _, _, terminated, _, info = env.step(FORWARD)
    assert not terminated  # standing on floor 1 is not a fall
    env = make_env(backend, [room(), room()], floor=1)  # and sampled
    env.reset(seed=0)
    assert env.task.get_current_pos(env)[2] == 3.0


def test_same_seed_same_episode_and_different_seeds_differ(backend):
    env = make_env(backend, wall_with_gap())
    starts = []
    for seed in (5, 5, 6):
        env.reset(seed=seed)
        starts.append((*env.task.get_start_pos(), *env.task.get_goal_pos()))
    assert starts[0] == starts[1]
    assert starts[0] != starts[2]


def episodes_on_every_backend(scene: Scene, seeds) -> dict[str, list]:
    """Per backend, each seed's episode: (geodesic, start position, goal, start yaw)."""
    out = {}
    for name in available_backends():
        env = PointNavEnv(scene=scene, backend=name)
        episodes = []
        for seed in seeds:
            _, info = env.reset(seed=seed)
            position, orientation = env.backend.get_pose(0)
            episodes.append((
                info["geodesic_dist"],
                position.tolist(),
                env.task.get_goal_pos().tolist(),
                float(quat2yaw(orientation)),
            ))
        out[name] = episodes
    return out


@pytest.mark.parametrize(
    "make_scene",
    [
        pytest.param(lambda: Scene.from_array(wall_with_gap(), RES), id="grid"),
        pytest.param(lambda: scenes.rooms(seed=1), id="rooms-polygons"),
    ],
)
def test_same_seed_gives_the_same_start_and_goal_on_every_backend(make_scene):
    # Sampling lives in the core; a backend only lands the robot and checks its pose. On a
    # scene built from polygons the map has two shapes for each obstacle, its polygons and
    # its OBSTACLE cells, and a backend may collide with either.
    seeds = range(40)
    episodes = episodes_on_every_backend(make_scene(), seeds)
    first_name, first = next(iter(episodes.items()))
    for name, other in episodes.items():
        differ = [
            seed
            for seed, a, b in zip(seeds, first, other)
            if a[:3] != b[:3] or abs(math.remainder(a[3] - b[3], 2.0 * math.pi)) > 1e-12
        ]
        assert not differ, f"{name} and {first_name} differ for seeds {differ}"


# ------------------------------------------------------------------------------ lifecycle


def test_lifecycle_follows_the_transition_table(backend):
    env = make_env(backend, room(), initial_pos=(1.0, 1.0, 0.0), goal_pos=(5.0, 1.0, 0.0),
                   termination_config={"max_steps": 2})
    task = env.task
    assert task.state is TaskState.IDLE
    env.reset(seed=0)
    assert task.state is TaskState.RUNNING
    env.step(STOP)
    assert task.state is TaskState.RUNNING
    env.step(STOP)
    assert task.state is TaskState.DONE
    env.reset()
    assert task.state is TaskState.RUNNING


def test_step_after_the_episode_ended_raises_and_changes_nothing(backend):
    env = make_env(backend, room(), initial_pos=(1.0, 1.0, 0.0), initial_quat=quat(0.0),
                   goal_pos=(5.0, 1.0, 0.0), termination_config={"max_steps": 1})
    env.reset(seed=0)
    env.step(FORWARD)
    pose = env.backend.get_pose(0)
    length = env.task.episode_length
    with pytest.raises(TaskStateError, match="call reset"):
        env.step(FORWARD)
    with pytest.raises(TaskStateError):
        env.task.step(env, FORWARD)
    assert env.task.state is TaskState.DONE
    assert env.task.episode_length == length
    np.testing.assert_array_equal(env.backend.get_pose(0)[0], pose[0])


def test_default_configs_are_read_only_and_tasks_do_not_share_them():
    with pytest.raises(TypeError):
        PointNavigationTask.default_termination_config["max_steps"] = 3  # type: ignore[index]
    with pytest.raises(TypeError):
        PointNavigationTask.default_reward_config["r_pointgoal"] = 0.0  # type: ignore[index]
    a = PointNavigationTask(termination_config={"max_steps": 7})
    b = PointNavigationTask()
    assert a.termination_config["max_steps"] == 7
    assert b.termination_config["max_steps"] == 500
    assert PointNavigationTask.default_termination_config["max_steps"] == 500


def test_visualization_parameters_are_kept():
    task = PointNavigationTask(visualize_goal=True, visualize_path=True, goal_height=0.2,
                               waypoint_height=0.1, waypoint_width=0.05, n_vis_waypoints=4)
    assert (task.visualize_goal, task.visualize_path) == (True, True)
    assert (task.goal_height, task.waypoint_height, task.waypoint_width) == (0.2, 0.1, 0.05)
    assert task.n_vis_waypoints == 4


# ------------------------------------------------------------------------------ composition


class _StopAfterTwoContacts(TerminationCondition):
    name = "two_contacts"

    def reset(self, task, env):
        super().reset(task, env)
        self.seen = 0

    def terminate(self, task, env, action):
        self.seen += task.in_contact
        return self.seen >= 2


class _TaskWithExtraCondition(PointNavigationTask):
    def _create_termination_conditions(self):
        conditions = super()._create_termination_conditions()
        conditions["two_contacts"] = _StopAfterTwoContacts()
        return conditions


def test_a_subclass_can_add_a_termination_condition(backend):
    task = _TaskWithExtraCondition(initial_pos=(5.025, 1.0, 0.0), initial_quat=quat(0.0),
                                   goal_pos=(1.0, 1.0, 0.0))
    env = PointNavEnv(scene=Scene.from_array(room(), RES), robot=ROBOT, task=task, backend=backend)
    env.reset(seed=0)
    for _ in range(16):
        _, _, terminated, _, info = env.step(FORWARD)
        assert not terminated
    _, _, terminated, _, info = env.step(FORWARD)  # the second contact
    assert terminated
    assert info["termination_conditions"]["two_contacts"] == {"done": True, "success": False}


class _TaskWithoutGoal(PointNavigationTask):
    def _create_termination_conditions(self):
        conditions = super()._create_termination_conditions()
        del conditions["pointgoal"]
        return conditions


def test_goal_reward_without_a_goal_condition_fails_at_reset(backend):
    task = _TaskWithoutGoal(initial_pos=(1.0, 1.0, 0.0), goal_pos=(3.0, 1.0, 0.0))
    env = PointNavEnv(scene=Scene.from_array(room(), RES), robot=ROBOT, task=task, backend=backend)
    with pytest.raises(ValueError, match="pointgoal"):
        env.reset(seed=0)
    assert task.state is TaskState.ERROR
    assert isinstance(task.reward_functions["pointgoal"], PointGoalReward)


def test_omnigibson_accessors(backend):
    env = make_env(backend, room(), initial_pos=(1.0, 1.0, 0.0), initial_quat=quat(0.0),
                   goal_pos=(3.0, 1.0, 0.0))
    task = env.task
    assert task.get_goal_pos().tolist() == [3.0, 1.0, 0.0]
    env.reset(seed=0)
    assert task.get_current_pos(env).tolist() == [1.0, 1.0, 0.0]
    assert task.get_potential(env) == pytest.approx(2.0)
    path, length = task.get_shortest_path_to_goal(env, entire_path=True)
    assert length == pytest.approx(2.0, abs=1e-9)
    np.testing.assert_allclose(path[[0, -1]], [[1.0, 1.0], [3.0, 1.0]], atol=1e-9)
    waypoints, _ = task.get_shortest_path_to_goal(env, start_xy_pos=(2.0, 1.0))
    assert waypoints.shape == (env.scene.num_waypoints, 2)


# ------------------------------------------------------------------------------ fast paths


def obstacle_course() -> np.ndarray:
    """A room with a pillar and a trench: random driving meets walls, falls and goals."""
    grid = room(30, 40)
    grid[12:18, 15:18] = OBSTACLE
    grid[4:26, 26:32] = VOID
    return grid


def drive_randomly(env: PointNavEnv, steps: int, seed: int):
    """Yield each step's result for ``steps`` random actions (mostly forward, so that the
    robot reaches walls and holes), resetting as episodes end."""
    rng = np.random.default_rng(seed)
    env.reset(seed=seed)
    for _ in range(steps):
        result = env.step(rng.uniform((-0.2, -1.0), (1.0, 1.0)).astype(np.float32))
        yield result
        if result[2] or result[3]:
            env.reset()


def test_float_twins_give_exactly_the_numbers_of_get_pose_and_get_velocity(backend):
    # The task reads get_pose_floats / get_velocity_floats on every step when a backend
    # has them: they must be get_pose / get_velocity without the arrays, bit for bit.
    env = make_env(backend, obstacle_course(), termination_config={"max_steps": 30})
    b = env.backend
    for _ in drive_randomly(env, 200, seed=1):  # with contacts and falls
        position, orientation = b.get_pose(0)
        linear, angular = b.get_velocity(0)
        pose, velocity = b.get_pose_floats(0), b.get_velocity_floats(0)
        assert pose == (*position.tolist(), *orientation.tolist())
        assert velocity == (*linear.tolist(), *angular.tolist())
        assert all(type(v) is float for v in pose + velocity)


def arrays_only(backend: str) -> type:
    """The backend class, read only through the protocol's get_pose and get_velocity."""
    base = get_backend(backend)

    class ArraysOnly(base):
        def get_pose(self, idn):
            return super().get_pose(idn)

        def get_velocity(self, idn):
            return super().get_velocity(idn)

    return ArraysOnly


@pytest.mark.parametrize(("reward_type", "polar"), [("geodesic", False), ("l2", True)])
def test_the_float_twins_and_the_protocol_methods_give_the_same_episodes(
    backend, reward_type, polar
):
    # Overriding get_pose and get_velocity turns the twins off (the task must not bypass an
    # override), so the second env runs the protocol path: everything must be identical.
    # Seed 1 drives into the trench, seed 2 reaches goals; both touch walls.
    runs = []
    for backend_cls in (get_backend(backend), arrays_only(backend)):
        env = PointNavEnv(scene=Scene.from_array(obstacle_course(), RES), robot=ROBOT,
                          task={"reward_type": reward_type, "goal_in_polar": polar,
                                "goal_tolerance": 0.6, "termination_config": {"max_steps": 30}},
                          backend=backend_cls)
        steps = []
        for seed in (1, 2):
            for obs, reward, terminated, truncated, info in drive_randomly(env, 200, seed):
                obs_bytes = {key: (value.dtype, value.tobytes()) for key, value in obs.items()}
                steps.append((obs_bytes, reward, terminated, truncated, info))
        runs.append(steps)
    fast, protocol = runs
    ended = [name for *_, info in fast for name, c in info["termination_conditions"].items()
             if c["done"]]
    assert {"falling", "pointgoal", "timeout"} <= set(ended)
    assert fast == protocol


def test_a_backend_subclass_that_changes_get_velocity_is_read_through_it(backend):
    class Boastful(get_backend(backend)):
        def get_velocity(self, idn):
            linear, angular = super().get_velocity(idn)
            return linear * 2.0, angular * 2.0

    observed = []
    for backend_cls in (get_backend(backend), Boastful):
        env = PointNavEnv(scene=Scene.from_array(room(), RES), robot=ROBOT, backend=backend_cls,
                          task={"initial_pos": (1.0, 1.0, 0.0), "initial_quat": quat(0.0),
                                "goal_pos": (3.0, 1.0, 0.0)})
        env.reset(seed=0)
        obs, *_ = env.step(np.array([0.5, 0.5], np.float32))
        observed.append(obs)
    plain, boastful = observed
    assert plain["robot_lin_vel"][0] > 0.2 and plain["robot_ang_vel"][2] > 0.7
    np.testing.assert_array_equal(boastful["robot_lin_vel"], 2.0 * plain["robot_lin_vel"])
    np.testing.assert_array_equal(boastful["robot_ang_vel"], 2.0 * plain["robot_ang_vel"])


def test_a_get_pose_patched_on_the_backend_instance_is_read_from_the_next_episode(backend):
    env = make_env(backend, room(), initial_pos=(1.0, 1.0, 0.0), initial_quat=quat(0.0),
                   goal_pos=(3.0, 1.0, 0.0))
    env.reset(seed=0)
    env.step(STOP)
    real = env.backend.get_pose

    def shifted(idn):
        position, orientation = real(idn)
        return position + np.array([1.0, 0.0, 0.0]), orientation

    env.backend.get_pose = shifted
    env.reset(seed=0)
    _, _, _, _, info = env.step(STOP)
    assert env.task.robot_xyz[0] == pytest.approx(2.0, abs=1e-12)  # the patched position
    assert info["distance_to_goal"] == pytest.approx(1.0, abs=1e-9)


def test_info_distances_and_metrics_are_python_floats(backend):
    env = make_env(backend, wall_with_gap(), initial_pos=(1.0, 1.0, 0.0), goal_pos=(3.0, 1.0, 0.0), reward_type="geodesic")
    _, info = env.reset(seed=0)
    for _ in range(3):
        _, reward, _, _, info = env.step(FORWARD)
        assert type(reward) is float
        for key in ("distance_to_goal", "geodesic_dist", "spl", "soft_spl", "path_length"):
            assert type(info[key]) is float, key
