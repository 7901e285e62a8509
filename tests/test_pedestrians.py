"""Pedestrians in ``PointNavEnv`` (``pedestrians={...}``, :mod:`pointnav_core.crowds`).

Every check is against a reference written here: distances to wall cells by brute force over
the grid's squares, a ray's hand-computed range to a disc, contacts by centre distances.
"""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
from crowd_reference import RES, env_in, room, spawn_is_clear, wall_clearance

from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.errors import SamplingError
from pointnav_core.sensors import LOCAL_PEDESTRIAN


# ---------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("pedestrians", "names"),
    [
        ({"density": -0.1}, "pedestrians['density']"),
        ({"count": -1}, "pedestrians['count']"),
        ({"count": True}, "pedestrians['count']"),
        ({"count": 2.0}, "pedestrians['count']"),
        ({"count": 3, "density": 0.1}, "exactly one of 'count'"),
        ({}, "exactly one of 'count'"),
        ({"count": 3, "behaviour": "flock"}, "pedestrians['behaviour']"),
        ({"count": 3, "behavior": "orca"}, "unknown key 'behavior'"),
        ({"count": 3, "radius": (0.3, 0.2)}, "pedestrians['radius']"),
        ({"count": 3, "radius": 0.0}, "pedestrians['radius']"),
        ({"count": 3, "radius": "0.3"}, "pedestrians['radius']"),
        ({"count": 3, "speed": (0.5, math.nan)}, "pedestrians['speed'][1]"),
        ({"count": 3, "sees_robots": 1}, "pedestrians['sees_robots']"),
        ({"count": 3, "orca": {"time_horizon": 0}}, "pedestrians['orca']['time_horizon']"),
        ({"count": 3, "orca": {"horizon": 2.0}}, "unknown key 'horizon'"),
        ("orca", "pedestrians must be None or a dict"),
    ],
)
def test_bad_pedestrians_are_refused_naming_the_key(pedestrians: object, names: str) -> None:
    with pytest.raises(ValueError, match=re_escape(names)):
        PointNavEnv(pedestrians=pedestrians)


def re_escape(text: str) -> str:
    import re

    return re.escape(text)


def test_more_pedestrians_than_fit_is_a_sampling_error_naming_the_count() -> None:
    env = env_in(room(20, 20, boxes=0), pedestrians={"count": 200, "radius": 0.3})
    with pytest.raises(SamplingError, match=r"count=200"):
        env.reset(seed=0)


def test_density_gives_the_count_from_the_free_area() -> None:
    grid = room(60, 40, boxes=0)
    free_area = grid.sum() * RES**2  # 58 x 38 cells of 0.01 m²: 22.04 m²
    env = env_in(grid, pedestrians={"density": 1 / 8})
    env.reset(seed=0)
    assert env.crowd.n == math.floor(free_area / 8 + 0.5) == 3


# ---------------------------------------------------------------------- placement
@pytest.mark.parametrize("seed", range(6))
def test_no_pedestrian_starts_overlapping_a_wall_a_robot_or_another(seed: int) -> None:
    grid = room(seed=seed)
    env = env_in(grid, pedestrians={"count": 12, "radius": (0.15, 0.3)})
    env.reset(seed=seed)
    assert env.crowd.n == 12
    spawn_is_clear(grid, env)


@pytest.mark.parametrize("behaviour", ["orca", "social_force"])
def test_pedestrians_walk_and_never_enter_a_wall(behaviour: str) -> None:
    grid = room(seed=1)
    env = env_in(grid, pedestrians={"count": 8, "behaviour": behaviour}, task={"termination_config": {"max_steps": 400}})
    env.reset(seed=1)
    start = env.crowd.positions.copy()
    goals = {tuple(g) for g in env.crowd.goals.tolist()}
    for _ in range(300):
        env.step(np.zeros(2))
        assert (wall_clearance(grid, env.crowd.positions) >= env.crowd.config.radius[1] - 1e-9).all()
        goals |= {tuple(g) for g in env.crowd.goals.tolist()}
    moved = np.hypot(*(env.crowd.positions - start).T)
    assert np.median(moved) > 0.5  # they walk: 30 s at 0.5-1.0 m/s
    assert len(goals) > 8  # and draw new goals when they arrive


@pytest.mark.parametrize("behaviour", ["orca", "static_velocity"])
def test_a_waypoint_nearer_than_a_step_is_landed_on_not_overshot_into_a_wall(behaviour: str) -> None:
    """Beside the east wall (free for a 0.2 m disc up to x = 5.7 m), a pedestrian 0.05 m from
    its next waypoint, whose following one it cannot see, walks at 1 m/s: its preferred
    velocity would carry it 0.1 m, into the wall. It lands on the waypoint instead (half its
    speed for the step), keeping its path, rather than standing still to plan again."""
    chosen = "orca" if behaviour == "orca" else (lambda view: view.preferred)
    env = env_in(room(60, 40, boxes=0), pedestrians={"count": 1, "speed": 1.0, "radius": 0.2, "behaviour": chosen,
                                                      "sees_robots": False},
                 task={"initial_pos": [1.0, 2.0], "initial_quat": [0.0, 0.0, 0.0, 1.0], "goal_pos": [3.0, 2.0]})
    env.reset(seed=0)
    crowd_of_one(env, (5.64, 2.0), 0.2)
    crowd = env.crowd
    crowd.speed = np.array([1.0])
    waypoint, hidden = (5.69, 2.0), (5.95, 2.0)  # the one after it lies in the wall: never in sight
    crowd.set_route(0, [(5.64, 2.0), waypoint, hidden])
    env.step(np.zeros(2))
    np.testing.assert_allclose(crowd.positions[0], waypoint, atol=1e-12)
    np.testing.assert_allclose(crowd.velocities[0], [0.5, 0.0], atol=1e-12)
    assert tuple(crowd.goals[0]) == hidden  # no new plan, no new goal


# ---------------------------------------------------------------------- the robot's side
def crowd_of_one(env: PointNavEnv, xy: tuple[float, float], radius: float) -> None:
    """Make the env's crowd one standing pedestrian at ``xy``."""
    crowd = env.crowd
    crowd.positions = np.array([xy], dtype=float)
    crowd.velocities = np.zeros((1, 2))
    crowd.radius = np.array([radius])
    crowd.speed = np.array([0.0])
    crowd.headings = np.zeros(1)


def fixed_robot_env(**kwargs: object) -> PointNavEnv:
    task = {"initial_pos": [1.0, 2.0], "initial_quat": [0.0, 0.0, 0.0, 1.0], "goal_pos": [5.0, 2.0]}
    kwargs.setdefault("pedestrians", {"count": 1, "behaviour": "static"})
    return env_in(room(60, 40, boxes=0), task=task, **kwargs)


def test_the_scan_sees_a_pedestrian_at_its_hand_computed_range() -> None:
    env = fixed_robot_env(sensors={"scan": {"n_rays": 4}})
    env.reset(seed=0)
    crowd_of_one(env, (3.0, 2.0), 0.25)  # 2 m straight ahead of the robot at (1, 2), facing +x
    obs, *_ = env.step(np.zeros(2))
    # The ray ahead (0 rad) meets the disc at 3.0 - 0.25 - 1.0 = 1.75 m. The others meet the
    # room's walls, whose border cells end 0.1 m inside a 6 x 4 m room: 0.9 m behind, 1.9 m
    # to either side of (1, 2).
    want = {0.0: 1.75, 90.0: 1.9, -90.0: 1.9, 180.0: 0.9, -180.0: 0.9}
    angles = np.degrees(env.task.observation_terms["scan"].angles).round(6)
    np.testing.assert_allclose(obs["scan"], [want[float(a)] for a in angles], atol=1e-6)


def test_the_local_map_marks_a_pedestrian() -> None:
    env = fixed_robot_env(sensors={"local_map": {"size": 2.0, "cells": 20}})
    env.reset(seed=0)
    crowd_of_one(env, (1.6, 2.0), 0.2)  # 0.6 m ahead: rows above the centre, middle columns
    obs, *_ = env.step(np.zeros(2))
    grid = obs["local_map"]
    assert env.observation_space["local_map"].high.max() == LOCAL_PEDESTRIAN
    # Cell (row, col) centre: 0.1 m cells, heading up; 0.6 m ahead is rows 2-5 from the
    # top edge at 1.0 m ahead: cell row 4 has its centre 0.55 m ahead, inside the disc.
    assert grid[4, 9] == grid[4, 10] == LOCAL_PEDESTRIAN
    assert (grid == LOCAL_PEDESTRIAN).sum() == sum(
        (0.95 - r * 0.1 - 0.6) ** 2 + (0.95 - c * 0.1) ** 2 <= 0.04 for r in range(20) for c in range(20)
    )


@pytest.mark.parametrize("end", [False, True])
def test_touching_a_pedestrian_is_counted_apart_and_ends_the_episode_if_asked(end: bool) -> None:
    env = env_in(room(60, 40, boxes=0), pedestrians={"count": 1, "behaviour": "static", "end_on_collision": end},
                 task={"initial_pos": [1.0, 2.0], "initial_quat": [0.0, 0.0, 0.0, 1.0], "goal_pos": [5.0, 2.0]})
    _, info = env.reset(seed=0)
    assert info["pedestrian_collisions"] == 0
    crowd_of_one(env, (1.6, 2.0), 0.2)  # 0.6 m ahead; touching below 0.2 + robot radius
    touch = 0.2 + env.robot.radius
    while True:
        _, _, terminated, _, info = env.step(np.array([1.0, 0.0]))
        x = env.backend.get_pose(0)[0][0]
        if abs(1.6 - x) < touch:
            break
        assert info["pedestrian_collisions"] == 0 and not terminated
    assert info["pedestrian_collisions"] == 1
    assert info["collisions"] == 0  # not a collision with the floor
    assert terminated is end
    if end:
        assert info["termination_conditions"]["pedestrian_collision"]["done"]
        assert not info["success"]


# ---------------------------------------------------------------------- reproducibility
def rollout(env: PointNavEnv, steps: int) -> np.ndarray:
    out = []
    for i in range(steps):
        _, _, terminated, truncated, _ = env.step(np.array([0.6, math.sin(i / 7)]))
        out.append(env.crowd.positions.copy())
        if terminated or truncated:
            env.reset()
    return np.array(out)


def test_same_seed_same_crowd_and_a_pickled_copy_walks_the_same() -> None:
    a, b = (PointNavEnv(pedestrians={"count": 6}) for _ in range(2))
    a.reset(seed=7)
    b.reset(seed=7)
    np.testing.assert_array_equal(a.crowd.positions, b.crowd.positions)
    np.testing.assert_array_equal(rollout(a, 40), rollout(b, 40))
    copy = pickle.loads(pickle.dumps(a))
    np.testing.assert_array_equal(rollout(a, 100), rollout(copy, 100))
    c = PointNavEnv(pedestrians={"count": 6})
    c.reset(seed=8)
    assert not np.array_equal(c.crowd.positions, b.crowd.positions)


def test_a_callable_behaviour_sets_the_velocities_clipped_to_the_speed() -> None:
    seen = []

    def east(view: object) -> np.ndarray:
        seen.append(view)
        return np.tile([5.0, 0.0], (len(view.positions), 1))  # type: ignore[attr-defined]

    env = env_in(room(60, 40, boxes=0), pedestrians={"count": 3, "speed": 0.5, "behaviour": east})
    env.reset(seed=2)
    before = env.crowd.positions.copy()
    env.step(np.zeros(2))
    moved = env.crowd.positions - before
    walking = moved[:, 0] > 0  # those a wall did not stop: 0.5 m/s for 0.1 s east
    assert walking.any()
    np.testing.assert_allclose(moved[walking], [[0.05, 0.0]] * int(walking.sum()), atol=1e-12)
    assert seen[0].robots.shape == (1, 3) and seen[0].dt == pytest.approx(0.1)

    env = env_in(room(60, 40, boxes=0), pedestrians={"count": 3, "behaviour": lambda view: [1.0, 2.0]})
    env.reset(seed=2)
    with pytest.raises(ValueError, match=re_escape("pedestrians['behaviour'] must return an array of shape (3, 2)")):
        env.step(np.zeros(2))


def test_orca_pedestrians_keep_apart_from_a_robot_they_see() -> None:
    """A pedestrian walking at a standing robot goes round it when it sees it, and walks
    through it when it does not."""
    for sees, touches in ((True, False), (False, True)):
        env = fixed_robot_env(pedestrians={"count": 1, "speed": 0.8, "sees_robots": sees})
        env.reset(seed=0)
        crowd_of_one(env, (4.0, 2.05), 0.25)
        env.crowd.speed = np.array([0.8])
        env.crowd.set_route(0, [[4.0, 2.05], [0.4, 1.95]])  # straight through the robot
        closest = math.inf
        for _ in range(60):
            env.step(np.zeros(2))
            closest = min(closest, math.dist(env.crowd.positions[0], (1.0, 2.0)))
        assert (closest < 0.25 + env.robot.radius) is touches, (sees, closest)


def test_the_episode_end_carries_its_social_metrics_measured_on_its_own_positions() -> None:
    """The minimum centre distance and the personal-space time, recomputed here from the
    positions the test reads after every step, equal the env's ``info["social"]``."""
    env = PointNavEnv(pedestrians={"count": 8}, task={"termination_config": {"max_steps": 120}})
    env.reset(seed=4)
    robot, walkers = [env.backend.get_pose(0)[0][:2]], [env.crowd.positions.copy()]
    while True:
        _, _, terminated, truncated, info = env.step(np.array([0.8, 0.3]))
        robot.append(env.backend.get_pose(0)[0][:2])
        walkers.append(env.crowd.positions.copy())
        if terminated or truncated:
            break
        assert "social" not in info
    robot_xy, peds = np.array(robot), np.array(walkers)
    gaps = [math.dist(r, p) for r, step in zip(robot_xy, peds) for p in step]
    social = info["social"]
    assert social["min_ped_distance"] == pytest.approx(min(gaps), abs=1e-12)
    inside = sum(any(math.dist(r, p) < 0.5 for p in step) for r, step in zip(robot_xy[1:], peds[1:]))
    assert social["personal_space_time"] == pytest.approx(inside * 0.1)
    assert social["psc"] == pytest.approx(1 - inside / (len(robot_xy) - 1))


def test_an_env_config_carries_the_crowd() -> None:
    """``EnvConfig(pedestrians=...)`` round-trips, builds the crowd, names a bad key, and the
    batched engine walks an ORCA crowd from it and refuses the social force by name."""
    from pointnav_core.envs.config import EnvConfig
    from pointnav_core.vector import VectorPointNavEnv

    config = EnvConfig(pedestrians={"count": 4, "radius": [0.2, 0.25], "behaviour": "social_force"})
    assert EnvConfig.from_dict(config.to_dict()) == config
    env = PointNavEnv(config=config)
    env.reset(seed=0)
    assert env.crowd.n == 4 and env.crowd.config.behaviour == "social_force"
    assert EnvConfig().to_dict()["pedestrians"] is None
    with pytest.raises(ValueError, match=re_escape("pedestrians['density']")):
        EnvConfig(pedestrians={"density": -1.0})
    with pytest.raises(ValueError, match="pedestrians"):
        EnvConfig(pedestrians={"count": 2, "behaviour": print})  # a callable cannot be saved
    with pytest.raises(ValueError, match=re_escape("pedestrians['behaviour']")):
        VectorPointNavEnv(num_envs=2, config=config)
    orca = EnvConfig(pedestrians={"count": 3}, flatten_obs=True)
    venv = VectorPointNavEnv(num_envs=2, config=orca)
    venv.reset(seed=0)
    assert venv.crowd.count.tolist() == [3, 3]
    fleet = VectorPointNavEnv(num_envs=2, n_robots=2, config=orca)
    fleet.reset(seed=0)
    assert fleet.crowd.count.tolist() == [3, 3] and fleet.crowd.collisions.shape == (2, 2)
