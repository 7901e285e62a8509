"""A checkpoint's sampled actions (``actions="sampled"``, ``pointnav eval --actions``).

Each draw is held to the distribution written out by hand in numpy (the softmax of the
actor's logits; the Gaussian's mean and standard deviation), and the draws of an episode to
its seed alone: the same seed gives the same actions whatever else plays in between.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from pointnav_core.envs.config import EnvConfig
from pointnav_core.policies.checkpoint import load_checkpoint, save_checkpoint
from pointnav_core.policies.checkpoint_policy import CheckpointPolicy
from pointnav_core.policies.network import ActorCritic, RunningNorm
from pointnav_core.policies.recurrent import RecurrentActorCritic

N_OBS = 6


def _checkpoint(tmp_path, continuous: bool = False, memory: int = 0, actions: str = "sampled") -> str:
    """A small trained-like checkpoint (weights moved off their initial values)."""
    torch.manual_seed(5)
    agent = RecurrentActorCritic(N_OBS, 2 if continuous else 3, 8, continuous, memory) if memory else \
        ActorCritic(N_OBS, 2 if continuous else 3, 8, continuous)
    with torch.no_grad():
        for p in agent.parameters():
            p.add_(0.5 * torch.randn_like(p))
        last = [m for m in agent.actor if isinstance(m, torch.nn.Linear)][-1]
        last.weight.mul_(0.2)  # logits and means near 0: every action likely, draws inside [-1, 1]
        last.bias.zero_()
        if continuous:
            agent.log_std.fill_(-1.6)  # 0.2: draws stay well inside [-1, 1] for the moments below
    norm = RunningNorm((N_OBS,))
    norm.update(torch.randn(40, N_OBS, dtype=torch.float64) * 2 + 1)
    path = tmp_path / "p.pt"
    save_checkpoint(path, agent, norm, EnvConfig(action_space="discrete" if not continuous else "continuous"),
                    step=1, actions=actions)
    return str(path)


def _hand_output(path: str, obs: np.ndarray) -> np.ndarray:
    """The feed-forward actor's output, with numpy: standardise and clip, two tanh layers, a linear head."""
    ckpt = load_checkpoint(path)
    norm, w = ckpt.obs_norm, [m for m in ckpt.agent.actor if isinstance(m, torch.nn.Linear)]
    z = np.clip((obs - norm.mean.numpy()) / np.sqrt(norm.var.numpy() + 1e-8), -10, 10)
    for layer in w[:-1]:
        z = np.tanh(z @ layer.weight.detach().numpy().T.astype(np.float64) + layer.bias.detach().numpy())
    return z @ w[-1].weight.detach().numpy().T + w[-1].bias.detach().numpy()


def _env(seed) -> SimpleNamespace:
    """What the policy reads of an env: the seed of its last reset."""
    return SimpleNamespace(np_random_seed=seed)


def test_discrete_draws_follow_the_softmax_of_the_logits(tmp_path) -> None:
    path = _checkpoint(tmp_path)
    obs = np.array([0.3, -1.0, 2.0, 0.5, 1.5, -0.2], np.float32)
    logits = _hand_output(path, obs.astype(np.float64))
    probs = np.exp(logits - logits.max()) / np.exp(logits - logits.max()).sum()
    assert probs.min() > 0.05  # every action is drawn often enough to check
    act = CheckpointPolicy(path)(_env(123))
    n = 6000
    counts = np.bincount([act(obs) for _ in range(n)], minlength=3)
    # Each count within 4.5 binomial standard deviations of n * p.
    assert np.all(np.abs(counts - n * probs) <= 4.5 * np.sqrt(n * probs * (1 - probs))), (counts, n * probs)


def test_continuous_draws_have_the_gaussians_mean_and_spread(tmp_path) -> None:
    path = _checkpoint(tmp_path, continuous=True)
    obs = np.array([0.1, 0.4, -0.3, 1.0, 0.2, 0.0], np.float32)
    mean = _hand_output(path, obs.astype(np.float64))
    assert np.all(np.abs(mean) < 0.3), mean
    act = CheckpointPolicy(path)(_env(7))
    draws = np.array([act(obs) for _ in range(4000)])
    assert draws.dtype == np.float32 and draws.shape == (4000, 2)
    np.testing.assert_allclose(draws.mean(0), mean, atol=4.5 * 0.2 / np.sqrt(4000))
    np.testing.assert_allclose(draws.std(0), np.exp(-1.6), rtol=0.06)


@pytest.mark.parametrize("memory", [0, 4])
def test_an_episodes_draws_depend_on_its_seed_alone(tmp_path, memory) -> None:
    """Two episodes played step by step in turn draw what each draws alone; another seed
    draws otherwise; ``actions="greedy"`` overrides the checkpoint's own setting."""
    path = _checkpoint(tmp_path, memory=memory)
    obs = np.random.default_rng(0).normal(0, 2, (60, N_OBS)).astype(np.float32)
    factory = CheckpointPolicy(path)

    def alone(seed: int) -> list[int]:
        act = factory(_env(seed))
        return [act(o) for o in obs]

    a, b = factory(_env(11)), factory(_env(12))
    together = [(a(o), b(o)) for o in obs]
    assert [x for x, _ in together] == alone(11) and [y for _, y in together] == alone(12)
    assert alone(11) != alone(13)
    greedy = CheckpointPolicy(path, actions="greedy")
    assert greedy(_env(11)) is not None
    plays = {tuple(greedy(_env(seed))(o) for o in obs) for seed in (11, 12)}
    assert len(plays) == 1  # the greedy policy ignores the seed


def test_bad_actions_and_unseeded_envs_are_refused(tmp_path) -> None:
    path = _checkpoint(tmp_path)
    with pytest.raises(ValueError, match=r"actions must be one of \['greedy', 'sampled'\], got 'random'"):
        CheckpointPolicy(path, actions="random")
    with pytest.raises(ValueError, match="needs an env reset with an integer seed"):
        CheckpointPolicy(path)(_env(None))
    with pytest.raises(ValueError, match=r"actions must be one of"):
        save_checkpoint(tmp_path / "q.pt", ActorCritic(N_OBS, 3, 8), RunningNorm((N_OBS,)), EnvConfig(), 1,
                        actions="argmax")
    assert load_checkpoint(path).actions == "sampled"
