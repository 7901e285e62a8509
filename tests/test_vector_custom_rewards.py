"""A custom reward term with a batched method runs in the batched engine as in the single env.

The term below reads the geodesic distance, the contact flag and the step count from the
task's snapshot (``task.distance_to_goal``, ``task.in_contact``, ``task.episode_length``)
in ``compute`` and from their arrays in ``batched``. Played on the same fixed episodes and
actions, ``VectorPointNavEnv`` and one ``PointNavEnv`` per world give the same rewards,
flags and info step for step (``vector_reference.compare``), on numpy and torch.
"""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest
from vector_reference import compare, random_episodes

from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.task.rewards import PotentialReward, RewardFunction
from pointnav_core.vector import VectorPointNavEnv

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])


class Shaped(RewardFunction):
    """-c * distance to the goal, -k more on a contact, after 5 steps."""

    name = "shaped"

    def __init__(self, c: float = 0.01, k: float = 0.5) -> None:
        super().__init__()
        self.c, self.k = c, k

    def compute(self, task, env, action) -> float:
        if task.episode_length <= 5:
            return 0.0
        return -self.c * min(task.distance_to_goal, 50.0) - (self.k if task.in_contact else 0.0)

    def batched(self, task):
        xp, zero, d = task.xp, task.zero, task.distance_to_goal
        value = -self.c * xp.where(d < 50.0, d, zero + 50.0) - xp.where(task.in_contact, zero + self.k, zero)
        return xp.where(task.episode_length <= 5, zero, value)


def _scene() -> Scene:
    grid = np.zeros((30, 40), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = OBSTACLE
    grid[8:22, 18:21] = OBSTACLE
    return Scene.from_array(grid, 0.1)


@pytest.mark.parametrize("device", DEVICES)
def test_a_custom_reward_gives_equal_rewards_in_both_engines(device: str) -> None:
    scene = _scene()
    rng = np.random.default_rng(3)
    actions = rng.uniform(-1.0, 1.0, (80, 5, 2)).astype(np.float32)
    actions[..., 0] = np.abs(actions[..., 0])  # mostly forward: contacts and goals happen
    task = {"reward_type": "geodesic", "reward_functions": [Shaped()],
            "termination_config": {"max_steps": 40, "max_collisions": 30}}
    stats = compare(scene, random_episodes(scene, 5, rng), actions, task=task, device=device)
    assert stats["contacts"] > 0 and stats["autoresets"] > 0


@pytest.mark.parametrize("device", DEVICES)
def test_the_slack_term_gives_equal_rewards_in_both_engines(device: str) -> None:
    scene = _scene()
    rng = np.random.default_rng(4)
    actions = rng.uniform(-1.0, 1.0, (60, 4, 2)).astype(np.float32)
    actions[..., 0] = np.abs(actions[..., 0])
    task = {"reward_type": "geodesic", "reward_config": {"r_slack": 0.03}, "reward_functions": [Shaped()],
            "termination_config": {"max_steps": 30, "max_collisions": 30}}
    stats = compare(scene, random_episodes(scene, 4, rng), actions, task=task, device=device)
    assert stats["autoresets"] > 0


def test_the_fleet_reports_each_robots_slack() -> None:
    task = [{"reward_config": {"r_slack": 0.5}}, {}]  # one robot pays for time, one does not
    env = VectorPointNavEnv(2, n_robots=2, scene=_scene(), seed=0, task=task)
    env.reset(seed=0)
    _, reward, _, _, info = env.step(np.tile([[1.0, 0.0]], (2, 2, 1)).astype(np.float32))
    np.testing.assert_array_equal(info["reward_slack"], [[-0.5, 0.0], [-0.5, 0.0]])
    parts = info["reward_potential"] + info["reward_collision"] + info["reward_pointgoal"] + info["reward_slack"]
    np.testing.assert_allclose(reward, parts, rtol=0, atol=1e-12)


def test_the_engine_reports_each_custom_term_and_adds_it_last() -> None:
    env = VectorPointNavEnv(3, scene=_scene(), seed=0, task={"reward_functions": [Shaped(c=0.02)]})
    env.reset(seed=0)
    for _ in range(8):
        _, reward, _, _, info = env.step(np.tile([[1.0, 0.0]], (3, 1)).astype(np.float32))
    parts = info["reward_potential"] + info["reward_collision"] + info["reward_pointgoal"] + info["reward_shaped"]
    np.testing.assert_allclose(reward, parts, rtol=0, atol=1e-12)
    assert (info["reward_shaped"] < 0).all()


@pytest.mark.parametrize(
    ("term", "message"),
    [
        (type("NoBatch", (RewardFunction,), {"name": "nobatch", "compute": lambda self, t, e, a: 0.0})(),
         "has no batched\\(task\\) method"),
        (PotentialReward(2.0), "cannot replace the built-in 'potential' term"),
    ],
)
def test_terms_the_engine_cannot_run_are_refused_by_name(term, message) -> None:
    with pytest.raises(ValueError, match=message):
        VectorPointNavEnv(2, scene=_scene(), task={"reward_functions": [term]})
