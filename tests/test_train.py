"""Training and checkpoints: ``pointnav train`` then ``pointnav eval --policy CHECKPOINT``.

The checkpoint tests hold a saved network to a hand computation of its actions (the
running statistics' standardisation, then the MLP) and refuse what is not a checkpoint
without running it. The training tests run ``pointnav train`` on a tiny budget in a small
room, and check that the trainer's held-out results are ``pointnav eval``'s, episode by
episode.
"""

from __future__ import annotations

import os
import pickle

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from pointnav_core.cli import main
from pointnav_core.env_config import EnvConfig
from pointnav_core.evaluation import evaluate, make_policy, read_results
from pointnav_core.training.agent import ActorCritic, RunningNorm
from pointnav_core.training.checkpoint import load_checkpoint, save_checkpoint

# 6 x 4 m at 0.5 m per character: one room with a pillar.
MAP = """type octile
height 8
width 12
map
@@@@@@@@@@@@
@..........@
@..........@
@....@@....@
@....@@....@
@..........@
@..........@
@@@@@@@@@@@@
"""
SCAN = EnvConfig(sensors={"scan": {"n_rays": 8}}, action_space="discrete", discrete_actions={"stop": False},
                 task={"goal_in_polar": True, "reward_type": "geodesic"}, max_steps=30)


def _trained_like(n_obs: int, n_actions: int, continuous: bool) -> tuple[ActorCritic, RunningNorm]:
    """A network and statistics far from their initial values (as after training)."""
    torch.manual_seed(3)
    agent = ActorCritic(n_obs, n_actions, 8, continuous)
    with torch.no_grad():
        for p in agent.parameters():
            p.add_(torch.randn_like(p))
    norm = RunningNorm((n_obs,))
    norm.update(torch.randn(50, n_obs, dtype=torch.float64) * 3 + 1)
    return agent, norm


def _by_hand(agent: ActorCritic, norm: RunningNorm, obs: np.ndarray, continuous: bool) -> np.ndarray:
    """The deterministic action, from the weights with numpy: standardise and clip to
    [-10, 10], two tanh layers, then the argmax (discrete) or the mean clipped to [-1, 1]."""
    z = np.clip((obs - norm.mean.numpy()) / np.sqrt(norm.var.numpy() + 1e-8), -10, 10).astype(np.float32)
    w = [m for m in agent.actor if isinstance(m, torch.nn.Linear)]
    h = np.tanh(z @ w[0].weight.detach().numpy().T + w[0].bias.detach().numpy())
    h = np.tanh(h @ w[1].weight.detach().numpy().T + w[1].bias.detach().numpy())
    out = h @ w[2].weight.detach().numpy().T + w[2].bias.detach().numpy()
    return np.clip(out, -1, 1) if continuous else out.argmax(-1)


@pytest.mark.parametrize("continuous", [False, True])
def test_checkpoint_round_trip_gives_the_same_actions(tmp_path, continuous) -> None:
    config = SCAN if not continuous else EnvConfig(sensors={"scan": {"n_rays": 8}}, max_steps=30)
    agent, norm = _trained_like(16, 2 if continuous else 3, continuous)
    path = tmp_path / "p.pt"
    save_checkpoint(path, agent, norm, config, step=1234, metrics={"success": 0.5})
    ckpt = load_checkpoint(path)
    assert (ckpt.step, ckpt.env_config, ckpt.metrics) == (1234, config, {"success": 0.5})
    assert ckpt.network == {"n_obs": 16, "n_actions": 2 if continuous else 3, "width": 8, "continuous": continuous}
    obs = np.random.default_rng(0).normal(0, 4, (64, 16)).astype(np.float32)
    want = _by_hand(agent, norm, obs, continuous)
    policy = make_policy(str(path))(None)  # the evaluation's policy: one observation at a time
    got = np.array([policy(o) for o in obs])
    if continuous:
        np.testing.assert_allclose(got, want, atol=1e-5)
        assert got.dtype == np.float32 and got.shape == (64, 2)
    else:
        assert got.tolist() == want.tolist() and len(set(got.tolist())) > 1


class _Marker:
    """Unpickling this runs code: it creates a file (a checkpoint must never do that)."""

    def __init__(self, path: str) -> None:
        self.path = path

    def __reduce__(self):
        return (open, (self.path, "w"))


def test_what_is_not_a_checkpoint_is_refused_naming_the_file(tmp_path) -> None:
    agent, norm = _trained_like(16, 3, False)
    good = tmp_path / "good.pt"
    save_checkpoint(good, agent, norm, SCAN, step=1)
    data = good.read_bytes()
    marker = tmp_path / "ran"
    cases = {
        "truncated.pt": data[: len(data) // 2],
        "empty.pt": b"",
        "text.pt": b"not a checkpoint\n",
        "pickle.pt": pickle.dumps(_Marker(str(marker))),
    }
    for name, content in cases.items():
        (tmp_path / name).write_bytes(content)
    torch.save({"weights": torch.zeros(3)}, tmp_path / "foreign.pt")
    torch.save({"x": _Marker(str(marker))}, tmp_path / "code.pt")
    for name in [*cases, "foreign.pt", "code.pt"]:
        path = str(tmp_path / name)
        with pytest.raises(ValueError, match=f"checkpoint {path!r}"):
            load_checkpoint(path)
    assert not marker.exists(), "loading a checkpoint ran code"
    with pytest.raises(ValueError, match="no such checkpoint file"):
        make_policy(str(tmp_path / "missing.pt"))
