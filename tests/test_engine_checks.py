"""Every engine checks the same things (issue 29, point 6).

The single env (and so Gymnasium's), the parallel env, the batched engine and its fleet
refuse, with a ``ValueError`` naming what is wrong: a dataset episode of another scene, a
goal tolerance of 0 m (no episode could succeed), a fixed episode's non-finite yaw, and
actions that are not real numbers. Scenes are a walled 3 x 2 m room: the references are
straight-line geometry.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import math

import numpy as np
import pytest

from pointnav_core import scenes
from pointnav_core.datasets import EpisodeDataset, GeneratorConfig, load_scene
from pointnav_core.datasets.format import PointNavEpisode
from pointnav_core.envs.multi_pointnav import parallel_env
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.task.terminations import PointGoal
from pointnav_core.vector import VectorPointNavEnv

TORCH = importlib.util.find_spec("torch") is not None


def room(scene_id: str | None = "box") -> scenes.Scene:
    grid = np.zeros((20, 30), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = OBSTACLE
    scene = scenes.Scene.from_array(grid, 0.1)
    scene.scene_id = scene_id  # as Scene.from_array(..., scene_id=...) names it
    return scene


def episode(scene_id: str, start=(0.6, 0.6), goal=(2.2, 1.2), yaw: float = 0.5) -> PointNavEpisode:
    return PointNavEpisode(
        episode_id="e", scene_id=scene_id, floor=0, start_position=(*start, 0.0),
        start_rotation=(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)), goal_position=(*goal, 0.0),
        goal_radius=0.3, geodesic_distance=math.dist(start, goal), robot_radius=0.18,
    )


def engines(scene: scenes.Scene, task: dict | None = None) -> dict:
    return {
        "single": lambda: PointNavEnv(scene=scene, task=task),
        "parallel": lambda: parallel_env(scene=scene, n_robots=2, task=task),
        "vector": lambda: VectorPointNavEnv(1, scene=scene, pool_size=1, seed=0, task=task),
        "fleet": lambda: VectorPointNavEnv(1, n_robots=2, scene=scene, pool_size=1, seed=0, task=task),
    }


def play(kind: str, env, ep: PointNavEpisode, other: PointNavEpisode):
    """Reset ``env`` into ``ep`` (with ``other`` for a second robot); the start it took."""
    if kind == "single":
        env.reset(options={"episode": ep})
        return tuple(env.backend.get_pose(0)[0][:2])
    if kind == "parallel":
        env.reset(options={"episodes": [ep, other]})
        return tuple(env.backend.get_pose(0)[0][:2])
    episodes = [ep] if kind == "vector" else [[ep, other]]
    _, info = env.reset(options={"episodes": episodes})
    d0 = np.asarray(info["geodesic_dist"]).reshape(-1)[0]
    assert d0 == pytest.approx(math.dist(ep.start_xy, ep.goal_xy), abs=1e-6)  # open floor: a straight line
    return float(env.arrays.numpy(env.state.x).reshape(-1)[0]), float(env.arrays.numpy(env.state.y).reshape(-1)[0])


@pytest.mark.parametrize("kind", ["single", "parallel", "vector", "fleet"])
def test_an_episode_of_another_scene_is_refused_by_every_engine(kind: str) -> None:
    scene = room("box")
    env = engines(scene)[kind]()
    other = episode("box", start=(2.4, 0.5), goal=(0.5, 1.5))
    assert play(kind, env, episode("box"), other) == pytest.approx((0.6, 0.6))
    with pytest.raises(ValueError, match=r"episode 'e' \(scene 'house_b'\): field 'scene_id' is 'house_b', but the env's scene is 'box'"):
        play(kind, env, episode("house_b"), other)
    # A scene built without a name checks nothing (it has no name to check against).
    env = engines(room(None))[kind]()
    assert play(kind, env, episode("anything"), other) == pytest.approx((0.6, 0.6))


def test_scenes_carry_the_names_datasets_give_them() -> None:
    assert scenes.rooms(seed=3).scene_id == "rooms:3" and load_scene("maze:2").scene_id == "maze:2"
    # Not the scene "rooms:3" names: another resolution, no seed.
    assert scenes.rooms(seed=3, resolution=0.2).scene_id is None and scenes.clutter().scene_id is None
    assert scenes.Scene.from_array(np.ones((5, 5), bool), 0.1, scene_id="box").scene_id == "box"
    with pytest.raises(ValueError, match="scene_id must be None or a non-empty string"):
        scenes.Scene.from_array(np.ones((5, 5), bool), 0.1, scene_id="")


@pytest.mark.parametrize("kind", ["single", "parallel", "vector", "fleet"])
def test_a_goal_tolerance_of_zero_is_refused_by_every_engine(kind: str) -> None:
    with pytest.raises(ValueError, match=r"goal_tolerance must be a finite number > 0 \(m\), got 0"):
        engines(room(), {"goal_tolerance": 0})[kind]()
    engines(room(), {"goal_tolerance": 1e-6})[kind]()  # any radius above 0 is a radius


def test_a_goal_radius_of_zero_is_refused_where_episodes_are_made_and_read() -> None:
    with pytest.raises(ValueError, match=r"goal_tolerance must be a finite number > 0"):
        PointGoal(goal_tolerance=0.0)
    with pytest.raises(ValueError, match=r"goal_radius must be a finite number > 0"):
        GeneratorConfig(goal_radius=0)
    raw = EpisodeDataset([episode("box")]).to_json()
    raw["episodes"][0]["goals"][0]["radius"] = 0.0
    with pytest.raises(ValueError, match=r"field 'goals\[0\].radius' must be a finite number > 0 or null, got 0.0"):
        EpisodeDataset.from_json(raw)
    raw["episodes"][0]["goals"][0]["radius"] = None  # the task's tolerance then
    assert EpisodeDataset.from_json(raw)[0].goal_radius is None


@pytest.mark.parametrize("yaw", [math.nan, math.inf, "0.5", True])
def test_a_fixed_episode_needs_a_finite_yaw_in_both_batched_engines(yaw) -> None:
    single = VectorPointNavEnv(1, scene=room(), pool_size=1, seed=0)
    with pytest.raises(ValueError, match=r"options\['episodes'\]\[0\]: yaw must be a finite number \(rad\)"):
        single.reset(options={"episodes": [((0.6, 0.6), yaw, (2.2, 1.2))]})
    fleet = VectorPointNavEnv(1, n_robots=2, scene=room(), pool_size=1, seed=0)
    with pytest.raises(ValueError, match=r"options\['episodes'\]\[0\]\[1\]: yaw must be a finite number \(rad\)"):
        fleet.reset(options={"episodes": [[((0.6, 0.6), 0.0, (2.2, 1.2)), ((2.4, 0.5), yaw, (0.5, 1.5))]]})
    obs, _ = single.reset(options={"episodes": [((0.6, 0.6), 0.5, (2.2, 1.2))]})  # a finite one plays
    assert np.isfinite(obs).all()


@pytest.mark.parametrize("kind", ["single", "parallel", "vector", "fleet"])
@pytest.mark.parametrize(("field", "value", "words"), [
    ("start_rotation", (0.0, 0.0, math.nan, 1.0), r"'start_rotation' must be a finite yaw quaternion"),
    ("start_rotation", (0.0, 0.0, 0.0, 0.0), r"'start_rotation' must be a finite yaw quaternion"),
    ("start_position", (0.6, 0.6, math.nan), r"'start_position' must be 3 finite numbers"),
])
def test_a_dataset_episode_with_a_nan_pose_is_refused_by_every_engine(kind: str, field: str, value, words: str) -> None:
    # A PointNavEpisode made in code is not checked as a file's is (datasets.format).
    env = engines(room())[kind]()
    bad = dataclasses.replace(episode("box"), **{field: value})
    with pytest.raises(ValueError, match=r"episode 'e' \(scene 'box'\): field " + words):
        play(kind, env, bad, episode("box", start=(2.4, 0.5), goal=(0.5, 1.5)))


# The single env's refusals (tests/test_validation.py), as one action per world.
NOT_REAL = {
    "complex": np.array([1 + 1j, 0.0]),
    "bool array": np.array([True, False]),
    "bool item": [True, 0.0],
    "string array": np.array(["1", "0"]),
    "string list": ["1", "0"],
}


@pytest.mark.parametrize("name", list(NOT_REAL))
def test_actions_that_are_not_real_numbers_are_refused_by_every_engine(name: str) -> None:
    action = NOT_REAL[name]
    single = PointNavEnv(scene=room())
    single.reset(seed=0)
    with pytest.raises(ValueError, match=r"^action must be an array of 2 real numbers"):
        single.step(action)
    batched = [
        (VectorPointNavEnv(2, scene=room(), pool_size=1, seed=0), [action, action]),
        (VectorPointNavEnv(1, n_robots=2, scene=room(), pool_size=1, seed=0), [[action, action]]),
    ]
    for env, actions in batched:
        env.reset(seed=0)
        before = env.arrays.numpy(env.state.x).copy()
        # As a list, and as an array (but a list of bools and floats makes a float array).
        for given in (actions, np.array(actions)) if name != "bool item" else (actions,):
            with pytest.raises(ValueError, match=r"^actions must be real numbers in \[-1, 1\]"):
                env.step(given)
        np.testing.assert_array_equal(env.arrays.numpy(env.state.x), before)  # nothing moved
        env.step(np.zeros(np.shape(np.array(actions)), np.int64))  # integers are real numbers


@pytest.mark.skipif(not TORCH, reason="the torch device needs torch")
def test_torch_actions_that_are_not_real_numbers_are_refused() -> None:
    import torch

    env = VectorPointNavEnv(2, scene=room(), pool_size=1, seed=0, device="cpu")
    env.reset(seed=0)
    for bad in (torch.zeros((2, 2), dtype=torch.complex64), torch.zeros((2, 2), dtype=torch.bool)):
        with pytest.raises(ValueError, match=r"^actions must be real numbers"):
            env.step(bad)
    env.step(torch.zeros((2, 2), dtype=torch.int32))
    env.step(np.zeros((2, 2), np.float32))
