"""Holonomic robots in the batched engines: hand-computed steps, spaces and argument checks.

The step-for-step agreement with the single and multi-robot envs is in
``property_tests/test_vector_props.py`` and ``test_vector_fleet_props.py``; here each
expected pose is worked out by hand from ``(vx, vy, w)`` in the robot frame.
"""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest

from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.scenes import Scene
from pointnav_core.vector import VectorPointNavEnv

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])
HOLO = {"drive": "holonomic"}  # 0.5 m/s, 1.5 rad/s, radius 0.18 m; 10 Hz: dt = 0.1 s
FAR_GOAL = (0.3, 0.3)


def room() -> Scene:
    """A walled 2 x 2 m room of 0.1 m cells: free from 0.1 to 1.9 m on both axes."""
    grid = np.zeros((20, 20), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = 1
    return Scene.from_array(grid, 0.1)


def one_step(device: str, start: tuple[float, float], yaw: float, action: list[float], n_robots: int = 1) -> tuple:
    """Pose, observation and contact of robot 0 after one step from ``start`` heading ``yaw``
    (the other robots, if any, stand still in the far corner)."""
    episode = [(start, yaw, FAR_GOAL)] + [((0.3 + 0.4 * k, 1.7), 0.0, (1.7, 0.3 + 0.4 * k)) for k in range(n_robots - 1)]
    env = VectorPointNavEnv(1, n_robots=n_robots, scene=room(), robot=HOLO, device=device, pool_size=1)
    env.reset(options={"episodes": [episode if n_robots > 1 else episode[0]]})
    act = np.zeros((1, n_robots, 3))
    act[0, 0] = action
    obs, _, _, _, info = env.step(act if n_robots > 1 else act[:, 0])
    to_np = env.arrays.numpy
    pose = [float(to_np(getattr(env.state, k)).reshape(-1)[0]) for k in ("x", "y", "yaw")]
    return pose, to_np(obs).reshape(-1, obs.shape[-1])[0], bool(to_np(info["in_contact"]).reshape(-1)[0])


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("n_robots", [1, 2])
def test_a_robot_at_yaw_90_deg_moving_ahead_moves_plus_y(device: str, n_robots: int) -> None:
    (x, y, yaw), obs, contact = one_step(device, (1.0, 1.0), math.pi / 2, [1.0, 0.0, 0.0], n_robots)
    assert x == pytest.approx(1.0, abs=1e-12) and y == pytest.approx(1.0 + 0.5 * 0.1, abs=1e-12)
    assert yaw == math.pi / 2 and not contact
    # low_dim: goal (2), linear velocity in the robot frame (3), angular velocity (3).
    np.testing.assert_allclose(obs[2:8], [0.5, 0.0, 0.0, 0.0, 0.0, 0.0], atol=1e-6)


@pytest.mark.parametrize("device", DEVICES)
def test_a_sideways_command_moves_to_the_left_of_the_heading(device: str) -> None:
    (x, y, _), obs, _ = one_step(device, (1.0, 1.0), 0.0, [0.0, 1.0, 0.0])
    assert (x, y) == pytest.approx((1.0, 1.05), abs=1e-12)
    (x, y, _), _, _ = one_step(device, (1.0, 1.0), math.pi / 2, [0.0, -0.5, 0.0])  # right of +y is +x
    assert (x, y) == pytest.approx((1.025, 1.0), abs=1e-12)
    np.testing.assert_allclose(obs[2:4], [0.0, 0.5], atol=1e-6)


@pytest.mark.parametrize("device", DEVICES)
def test_a_diagonal_step_travels_sqrt2_times_the_top_speed(device: str) -> None:
    # Beyond [-1, 1] is clipped per component: (1, 1) at 0.5 m/s each, 0.0707 m in 0.1 s.
    (x, y, _), obs, contact = one_step(device, (1.0, 1.0), 0.0, [3.0, 1.0, 0.0])
    assert (x, y) == pytest.approx((1.05, 1.05), abs=1e-12) and not contact
    np.testing.assert_allclose(obs[2:4], [0.5, 0.5], atol=1e-6)  # within the bound sqrt(2) * 0.5


@pytest.mark.parametrize("device", DEVICES)
def test_turning_while_translating_follows_the_exact_arc(device: str) -> None:
    # R(w t) (vx, 0) integrated over [0, dt]: vx / w * (sin(w dt), 1 - cos(w dt)).
    vx, w, dt = 0.5, 1.5, 0.1
    (x, y, yaw), _, _ = one_step(device, (1.0, 1.0), 0.0, [1.0, 0.0, 1.0])
    assert x == pytest.approx(1.0 + vx / w * math.sin(w * dt), abs=1e-12)
    assert y == pytest.approx(1.0 + vx / w * (1.0 - math.cos(w * dt)), abs=1e-12)
    assert yaw == pytest.approx(w * dt, abs=1e-15)


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("n_robots", [1, 2])
def test_a_diagonal_step_into_a_wall_slides_along_it(device: str, n_robots: int) -> None:
    # The wall's face is at x = 1.9; the disc (radius 0.18) starts 0.01 m from touching it.
    # Of the chord (0.05, 0.05), x is cut at the wall and y keeps all of it (the backend
    # takes it in two sub-steps of (0.025, 0.025), each cut and slid alike).
    (x, y, _), obs, contact = one_step(device, (1.71, 1.0), 0.0, [1.0, 1.0, 0.0], n_robots)
    assert x == pytest.approx(1.72, abs=1e-8) and y == pytest.approx(1.05, abs=1e-12) and contact
    np.testing.assert_allclose(obs[2:4], [0.1, 0.5], atol=1e-6)  # what was moved, over dt


@pytest.mark.parametrize("device", DEVICES)
def test_discrete_forward_moves_a_holonomic_robot_ahead(device: str) -> None:
    # MOVE_FORWARD: 0.25 m held as (1, 0, 0) for 5 control steps of 0.05 m; TURN_LEFT turns in place.
    env = VectorPointNavEnv(1, scene=room(), robot=HOLO, device=device, pool_size=1, action_space="discrete")
    env.reset(options={"episodes": [((1.0, 0.6), math.pi / 2, FAR_GOAL)]})
    env.step(np.array([0]))
    to_np = env.arrays.numpy
    assert float(to_np(env.state.x)[0]) == pytest.approx(1.0, abs=1e-12)
    assert float(to_np(env.state.y)[0]) == pytest.approx(0.85, abs=1e-12)
    env.step(np.array([1]))
    assert float(to_np(env.state.yaw)[0]) == pytest.approx(math.pi / 2 + math.radians(10.0), abs=1e-12)
    assert float(to_np(env.state.y)[0]) == pytest.approx(0.85, abs=1e-12)


def test_spaces_equal_the_single_envs() -> None:
    single = PointNavEnv(scene=room(), robot=HOLO, flatten_obs=True)
    env = VectorPointNavEnv(4, scene=room(), robot=HOLO, pool_size=1)
    assert env.single_action_space == single.action_space and env.single_action_space.shape == (3,)
    assert env.action_space.shape == (4, 3)
    np.testing.assert_array_equal(env.single_observation_space.low, single.observation_space.low)
    np.testing.assert_array_equal(env.single_observation_space.high, single.observation_space.high)
    fleet = VectorPointNavEnv(2, n_robots=3, scene=room(), robot=HOLO, pool_size=1)
    assert fleet.action_space.shape == (2, 3, 3)


@pytest.mark.parametrize(("n_robots", "bad", "words"), [
    (1, (2, 2), r"^actions must have shape \(2, 3\) or \(2, 1, 3\) for a holonomic drive, got \(2, 2\)"),
    (1, (2, 1, 2), r"^actions must have shape \(2, 3\) or \(2, 1, 3\) for a holonomic drive"),
    (3, (2, 3, 2), r"^actions must have shape \(2, 3, 3\) for a holonomic drive, got \(2, 3, 2\)"),
])
def test_actions_of_the_wrong_shape_are_named(n_robots: int, bad: tuple, words: str) -> None:
    env = VectorPointNavEnv(2, n_robots=n_robots, scene=room(), robot=HOLO, pool_size=1, seed=0,
                            task={"path_range": (0.5, 1.5)})
    env.reset()
    before = env.arrays.numpy(env.state.x)
    with pytest.raises(ValueError, match=words):
        env.step(np.zeros(bad))
    np.testing.assert_array_equal(env.arrays.numpy(env.state.x), before)


def test_a_differential_engine_names_its_own_shape() -> None:
    env = VectorPointNavEnv(2, scene=room(), pool_size=1, seed=0, task={"path_range": (0.5, 1.5)})
    env.reset()
    with pytest.raises(ValueError, match=r"^actions must have shape \(2, 2\) or \(2, 1, 2\) for a differential drive"):
        env.step(np.zeros((2, 3)))


@pytest.mark.parametrize("robot", [[{}, HOLO], [HOLO, {"drive": "differential"}]])
def test_robots_of_mixed_drives_are_refused(robot: list) -> None:
    with pytest.raises(ValueError, match=r"^robot: every robot must have the same drive .*\['differential', 'holonomic'\]"):
        VectorPointNavEnv(1, n_robots=2, scene=room(), robot=robot, pool_size=1)
