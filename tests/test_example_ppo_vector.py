"""The batched engine's PPO example runs a few updates on every observation layout."""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.vector import VectorPointNavEnv

_PATH = Path(__file__).resolve().parents[1] / "examples" / "ppo_vector.py"


def _example():
    spec = importlib.util.spec_from_file_location("ppo_vector", _PATH)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclass looks its module up while it is built
    spec.loader.exec_module(module)
    return module


def _room() -> Scene:
    grid = np.zeros((20, 30), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[:12, 15] = OBSTACLE
    return Scene.from_array(grid, 0.1)


@pytest.mark.parametrize(("sensors", "device"), [(None, "numpy"), ({"scan": {"n_rays": 8}}, "numpy"), ({"scan": {"n_rays": 8}}, "cpu")])
def test_a_few_updates_run_and_change_the_policy(sensors, device) -> None:
    ppo = _example()
    env = VectorPointNavEnv(
        8, scene=_room(), device=device, seed=0, pool_size=2, sensors=sensors, max_episode_steps=20,
        task={"goal_in_polar": True, "reward_type": "geodesic", "path_range": (0.3, 2.0)},
        action_space="discrete", discrete_actions={"stop": False},
    )
    cfg = ppo.Config(total_steps=8 * 16 * 3, num_steps=16, minibatch=32, width=16, epochs=2)
    seen: list[dict[str, float]] = []
    first: dict[str, torch.Tensor] = {}

    def log(stats, agent, _norm) -> bool:
        if not first:  # the weights after one update, to compare with the last
            first.update({k: v.detach().clone() for k, v in agent.state_dict().items()})
        seen.append(stats)
        return True

    agent, _ = ppo.train(env, cfg, log)
    assert [s["steps"] for s in seen] == [128.0, 256.0, 384.0]
    assert all(math.isfinite(v) for s in seen for v in s.values())
    changed = [not torch.equal(first[k], v) for k, v in agent.state_dict().items()]
    assert any(changed), "two more updates should move the weights"
    obs, _ = env.reset(seed=1)
    actions = agent.greedy(torch.as_tensor(np.asarray(env.arrays.numpy(obs)), dtype=torch.float32))
    assert actions.shape == (8,) and int(actions.min()) >= 0 and int(actions.max()) < env.single_action_space.n
