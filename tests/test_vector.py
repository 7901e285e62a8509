"""Examples of the batched engine: hand-calculated episodes, the reference, bad input."""

from __future__ import annotations

import importlib.util
import math

import gymnasium as gym
import numpy as np
import pytest
from vector_reference import compare, random_episodes

import pointnav_core  # noqa: F401  (registers the ids)
from pointnav_core.floor.maps import OBSTACLE, VOID
from pointnav_core.scenes import Scene
from pointnav_core.vector import VectorPointNavEnv

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])


def room(rows: int = 30, cols: int = 40) -> Scene:
    grid = np.zeros((rows, cols), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return Scene.from_array(grid, 0.1)


@pytest.mark.parametrize("device", DEVICES)
def test_straight_drive_to_the_goal_by_hand(device: str) -> None:
    # Facing the goal 1.02 m ahead; full speed is 0.05 m a step, so the distance first
    # drops below the 0.5 m tolerance after 11 steps (0.47 m left).
    env = VectorPointNavEnv(2, scene=room(), device=device)
    episodes = [((1.0, 1.5), 0.0, (2.02, 1.5)), ((1.0, 1.0), math.pi / 2, (1.0, 2.02))]
    obs, _ = env.reset(options={"episodes": episodes})
    to_np = env.arrays.numpy
    np.testing.assert_allclose(to_np(obs)[:, :2], [[1.02, 0.0], [1.02, 0.0]], atol=1e-6)
    total = np.zeros(2)
    for step in range(1, 12):
        obs, reward, terminated, _, info = env.step(np.tile([1.0, 0.0], (2, 1)))
        total += to_np(reward)
        assert to_np(terminated).tolist() == [step == 11] * 2
    np.testing.assert_allclose(to_np(obs)[:, 2], 0.5, atol=1e-6)  # forward speed, m/s
    np.testing.assert_allclose(total, 0.55 + 10.0, atol=1e-9)
    np.testing.assert_allclose(to_np(info["spl"]), 1.0)
    np.testing.assert_allclose(to_np(info["soft_spl"]), 1 - 0.47 / 1.02, atol=1e-9)
    np.testing.assert_allclose(to_np(info["path_length"]), 0.55, atol=1e-9)
    # Next-step autoreset: the action is ignored, the episode starts again.
    obs, reward, _, _, info = env.step(np.tile([1.0, 1.0], (2, 1)))
    np.testing.assert_allclose(to_np(obs)[:, :2], [[1.02, 0.0], [1.02, 0.0]], atol=1e-6)
    assert to_np(reward).tolist() == [0.0, 0.0] and to_np(info["autoreset"]).all()
    assert to_np(info["episode_length"]).tolist() == [0, 0]


@pytest.mark.parametrize("device", DEVICES)
def test_wall_contact_slides_and_costs(device: str) -> None:
    # Heading 45 degrees into the wall at y = 0.1 m: the robot slides along it in +x.
    env = VectorPointNavEnv(1, scene=room(), device=device, task={"termination_config": {"max_steps": 50}})
    env.reset(options={"episodes": [((1.0, 0.3), -math.pi / 4, (3.5, 2.5))]})
    contacts = 0
    for _ in range(20):
        _, _, _, _, info = env.step(np.array([[1.0, 0.0]]))
        contacts += bool(env.arrays.numpy(info["in_contact"])[0])
    y = float(env.arrays.numpy(env.state.y)[0])
    assert contacts > 0
    assert abs(y - (0.1 + 0.18)) < 1e-6  # resting on the wall
    assert float(env.arrays.numpy(info["collisions"])[0]) == contacts


@pytest.mark.parametrize("device", DEVICES)
def test_matches_single_envs_in_clutter(device: str) -> None:
    rng = np.random.default_rng(7)
    grid = np.zeros((22, 28), np.uint8)
    grid[rng.random(grid.shape) < 0.1] = OBSTACLE
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[10:13, 3:6] = VOID
    scene = Scene.from_array(grid, 0.1)
    actions = rng.uniform(-1.2, 1.2, (250, 6, 2)).astype(np.float32)
    actions[rng.random((250, 6)) < 0.5, 0] = 1.0
    stats = compare(scene, random_episodes(scene, 6, rng), actions,
                    task={"reward_type": "geodesic", "termination_config": {"max_steps": 60, "max_collisions": 20}},
                    device=device)
    assert stats["contacts"] > 0 and stats["autoresets"] > 0  # the case exercised what it claims


def test_pool_episodes_have_exact_geodesics() -> None:
    scene = room()
    env = VectorPointNavEnv(4, scene=scene, seed=3, pool_size=3)
    _, info = env.reset()
    st = env.state
    for i in range(4):
        start, goal = (st.x[i], st.y[i]), (st.goal_x[i], st.goal_y[i])
        # An empty room: the geodesic is the straight line.
        assert info["geodesic_dist"][i] == pytest.approx(math.dist(start, goal), abs=1e-9)
        assert 1.0 < info["geodesic_dist"][i] < 10.0  # the single env's derived path_range


def test_make_vec_builds_the_batched_engine() -> None:
    env = gym.make_vec("pointnav_core/VectorPointNav-v0", num_envs=3, vectorization_mode="vector_entry_point",
                       scene=room(), pool_size=2, max_episode_steps=40)
    assert isinstance(env, VectorPointNavEnv) and env.max_steps == 40
    obs, _ = env.reset(seed=0)
    assert obs.shape == (3, 8) and obs.dtype == np.float32
    obs, reward, terminated, truncated, _ = env.step(env.action_space.sample())
    assert reward.dtype == np.float64 and terminated.dtype == truncated.dtype == np.bool_ and env.observation_space.contains(obs)


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("n_robots", [1, 2])
def test_a_fall_goes_on_over_three_steps_by_hand(device: str, n_robots: int) -> None:
    # VOID from x = 1.1 m (y 0.5 to 2.5 m); robot 0 at x = 0.92 m drives +x at 0.05 m a step,
    # so its centre is over VOID after step 4 (x = 1.12 m). The backend's fall at 10 Hz:
    # step 4 drops 1 m/s x 0.1 s + 9.81 x 0.1^2 / 2 = 0.14905 m (speed then 1.981 m/s),
    # step 5 0.1981 + 0.04905 = 0.24715 m (2.962 m/s), step 6 0.2962 + 0.04905 = 0.34525 m:
    # z = -0.14905, -0.39620, -0.74145 m. With fall_height 0.5 m the episode ends at step 6.
    grid = np.zeros((30, 40), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[5:25, 11:15] = VOID
    task = {"reward_type": "l2", "termination_config": {"fall_height": 0.5}}
    first = ((0.92, 1.5), 0.0, (3.0, 1.5))
    if n_robots == 1:
        env = VectorPointNavEnv(1, scene=Scene.from_array(grid, 0.1), task=task, device=device)
        episodes: list = [first]
    else:  # a second robot that stands still far away
        env = VectorPointNavEnv(1, n_robots=2, scene=Scene.from_array(grid, 0.1), task=task, device=device)
        episodes = [[first, ((3.0, 2.5), 0.0, (3.5, 0.5))]]
    to_np = env.arrays.numpy
    obs, _ = env.reset(options={"episodes": episodes})
    want_z = {4: -0.14905, 5: -0.39620, 6: -0.74145}
    assert float(env.single_observation_space.low[4]) > -1.4905  # so the clip below is seen
    for step in range(1, 7):
        obs, reward, terminated, _, info = env.step(np.array([[[1.0, 0.0]] * n_robots] if n_robots > 1 else [[1.0, 0.0]]))
        z = float(to_np(env.state.z).reshape(-1)[0])
        o, r = to_np(obs).reshape(n_robots, -1)[0], float(to_np(reward).reshape(-1)[0])
        assert z == pytest.approx(want_z.get(step, 0.0), abs=1e-12), f"step {step}"
        assert bool(to_np(terminated).reshape(-1)[0]) == (step == 6), f"step {step}"
        x = float(to_np(env.state.x).reshape(-1)[0])
        assert x == pytest.approx(min(0.92 + 0.05 * step, 1.12), abs=1e-12)
        # Driving at 0.5 m/s until the fall's first step; then no planar motion, no reward.
        assert o[2] == pytest.approx(0.5 if step <= 4 else 0.0, abs=1e-6)
        # vz: the step's drop over 0.1 s, clipped to the observation's bound.
        vz = {4: -1.4905, 5: -2.4715, 6: -3.4525}.get(step, 0.0)
        assert o[4] == pytest.approx(max(vz, float(env.single_observation_space.low[4])), abs=1e-6)
        assert r == pytest.approx(0.05 if step <= 4 else 0.0, abs=1e-9)
    if n_robots == 2:  # the fallen robot leaves; the other goes on
        assert to_np(info["active"]).tolist() == [[False, True]]


@pytest.mark.parametrize("device", ["gpu", "cuda:x", 0, "numpy "])
def test_unknown_device_is_refused(device: object) -> None:
    with pytest.raises(ValueError, match="device"):
        VectorPointNavEnv(1, scene=room(), device=device)  # type: ignore[arg-type]


@pytest.mark.skipif(not importlib.util.find_spec("torch"), reason="needs torch")
def test_cuda_without_cuda_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    import torch

    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    with pytest.raises(ValueError, match="device 'cuda'.*no CUDA"):
        VectorPointNavEnv(1, scene=room(), device="cuda")


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("actions", [np.zeros((2, 3)), np.zeros((3, 2)), np.zeros(4), np.array([[0.0, np.nan], [0.0, 0.0]]),
                                     np.array([[np.inf, 0.0], [0.0, 0.0]])])
def test_bad_actions_are_refused(device: str, actions: np.ndarray) -> None:
    env = VectorPointNavEnv(2, scene=room(), device=device, pool_size=1)
    env.reset(seed=0)
    before = env.arrays.numpy(env.state.x)
    with pytest.raises(ValueError, match="actions"):
        env.step(actions)
    np.testing.assert_array_equal(env.arrays.numpy(env.state.x), before)


@pytest.mark.parametrize(("kwargs", "name"), [({"n_robots": 0}, "n_robots"), ({"sensors": {"lidar": {}}}, "sensors"),
                                             ({"num_envs": 0}, "num_envs"), ({"pool_size": 0}, "pool_size"),
                                             ({"robot": {"drive": "tank"}}, "drive")])
def test_unsupported_arguments_are_named(kwargs: dict, name: str) -> None:
    args = {"num_envs": 1, "scene": room(), **kwargs}
    with pytest.raises(ValueError, match=name):
        VectorPointNavEnv(**args)


def test_floors_with_polygons_are_refused_on_a_gpu_or_without_numba() -> None:
    from pointnav_core import scenes
    from pointnav_core.utils import compiled as _compiled

    with _compiled.numpy_paths(), pytest.raises(ValueError, match="scene 0 has obstacle polygons.*numba"):
        VectorPointNavEnv(1, scene=scenes.rooms(seed=0))


def test_returned_arrays_are_fresh() -> None:
    # reset() writes the engine's state in place: what the last step returned stays.
    env = VectorPointNavEnv(1, scene=room(), task={"termination_config": {"max_steps": 2}})
    env.reset(options={"episodes": [((1.0, 1.5), 0.0, (3.0, 1.5))]})
    env.step(np.array([[1.0, 0.0]]))
    _, _, _, truncated, info = env.step(np.array([[1.0, 0.0]]))
    kept = {key: np.array(value) for key, value in info.items()}
    assert truncated[0] and info["episode_length"][0] == 2
    env.reset(options={"episodes": [((1.0, 1.5), 0.0, (3.0, 1.5))]})
    for key, value in info.items():
        np.testing.assert_array_equal(value, kept[key], err_msg=key)


def test_a_disc_exactly_as_wide_as_a_passage_slides_into_it() -> None:
    # The kinematic backend's case: blocks at x 0.6-0.8, y 0.5-0.7 and x 0.7-0.9, y 1.0-1.2
    # leave a passage 0.3 m wide; a 0.15 m disc touching the lower block, drifting up by
    # 1e-9 m a step, meets the upper block's corner. Its slide along the lower block is clear.
    import shapely
    from shapely.geometry import Point

    from pointnav_core.vector.contacts import advance
    from pointnav_core.vector.floors import FloorTables
    from pointnav_core.vector.xp import make_arrays

    grid = np.zeros((16, 19), dtype=np.uint8)
    grid[5:7, 6:8] = OBSTACLE
    grid[10:12, 7:9] = OBSTACLE
    floors = FloorTables([Scene.from_array(grid, 0.1)], 0, 0.15, make_arrays("numpy"))
    blocks = shapely.union_all([shapely.box(0.6, 0.5, 0.8, 0.7), shapely.box(0.7, 1.0, 0.9, 1.2)])
    x, y = np.array([0.69998013]), np.array([0.85 + 3e-10])
    scene = np.zeros(1, dtype=np.int64)
    for _ in range(2):
        x, y, _ = advance(floors, scene, x, y, np.array([0.05]), np.array([1e-9]), 0.15, max_travel=0.051)
        assert Point(x[0], y[0]).distance(blocks) >= 0.15 - 2e-9
    assert x[0] > 0.79
