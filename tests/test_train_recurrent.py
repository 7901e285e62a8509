"""The recurrent policy (``ppo: {memory: M}``): its sequences, its checkpoint, train then eval.

The LSTM is checked against its equations written out here (PyTorch's gate order i, f, g,
o), with the state zeroed at each episode's first observation: the rollout's one step at a
time and the update's replay of whole sequences must both give the hand computation's
log-probabilities and values, or PPO's ratios would start away from 1.
"""

from __future__ import annotations

import os

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from test_train import SCAN, _same_as_trainer, _train_config, _write, room  # noqa: F401  (room: a fixture)

from pointnav_core.cli import main
from pointnav_core.envs.config import EnvConfig
from pointnav_core.policies.checkpoint import load_checkpoint, save_checkpoint
from pointnav_core.policies.checkpoint_policy import CheckpointPolicy
from pointnav_core.policies.network import RunningNorm
from pointnav_core.policies.recurrent import RecurrentActorCritic
from pointnav_core.training.ppo import PPOSettings


def _net(n_obs: int = 7, n_actions: int = 3, continuous: bool = False) -> RecurrentActorCritic:
    torch.manual_seed(5)
    net = RecurrentActorCritic(n_obs, n_actions, 6, continuous, memory=4)
    with torch.no_grad():  # far from the initialisation, so that every weight matters
        for p in net.parameters():
            p.add_(0.5 * torch.randn_like(p))
    return net


def _by_hand(net: RecurrentActorCritic, obs: np.ndarray, first: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Actor outputs and values ``(T, B, ...)`` from the weights with numpy: encoder, the
    LSTM's equations step by step (the state zeroed where ``first``), the two heads."""
    w = {k: v.detach().double().numpy() for k, v in net.state_dict().items()}
    sig = lambda x: 1.0 / (1.0 + np.exp(-x))  # noqa: E731
    x = np.tanh(obs @ w["encoder.0.weight"].T + w["encoder.0.bias"])
    t_len, b = obs.shape[:2]
    m = w["core.weight_hh_l0"].shape[1]
    h, c = np.zeros((b, m)), np.zeros((b, m))
    outs = []
    for t in range(t_len):
        h, c = np.where(first[t][:, None], 0.0, h), np.where(first[t][:, None], 0.0, c)
        z = x[t] @ w["core.weight_ih_l0"].T + w["core.bias_ih_l0"] + h @ w["core.weight_hh_l0"].T + w["core.bias_hh_l0"]
        i, f, g, o = np.split(z, 4, axis=1)
        c = sig(f) * c + sig(i) * np.tanh(g)
        h = sig(o) * np.tanh(c)
        outs.append(h)
    out = np.stack(outs)
    head = lambda name: np.tanh(out @ w[f"{name}.0.weight"].T + w[f"{name}.0.bias"]) @ w[f"{name}.2.weight"].T + w[f"{name}.2.bias"]  # noqa: E731
    return head("actor"), head("critic")[..., 0]


def test_steps_and_sequences_follow_the_lstm_equations():
    net = _net()
    rng = np.random.default_rng(0)
    t_len, b = 9, 5
    obs = rng.normal(size=(t_len, b, 7))
    first = rng.random((t_len, b)) < 0.25
    first[0] = True
    actions = rng.integers(0, 3, (t_len, b))
    logits, values = _by_hand(net, obs, first)
    logp = logits - np.log(np.exp(logits).sum(-1, keepdims=True))
    want_logp = np.take_along_axis(logp, actions[..., None], -1)[..., 0]
    o, f, a = torch.as_tensor(obs, dtype=torch.float32), torch.as_tensor(first), torch.as_tensor(actions)
    with torch.no_grad():
        got_logp, _, got_values, _ = net.evaluate(o, net.initial_state(b), f, a)
        state, step_logp, step_values = net.initial_state(b), [], []
        for t in range(t_len):  # the rollout's path: one step of every world at a time
            _, lp, _, v, state = net.act(o[t], state, f[t], a[t])
            step_logp.append(lp)
            step_values.append(v)
    for got in (got_logp, torch.stack(step_logp)):
        np.testing.assert_allclose(got.numpy(), want_logp, atol=1e-5)
    for got in (got_values, torch.stack(step_values)):
        np.testing.assert_allclose(got.numpy(), values, atol=1e-5)


def test_a_sequence_split_in_two_continues_from_its_state():
    net = _net(continuous=True)
    obs = torch.randn(8, 3, 7)
    first = torch.zeros(8, 3, dtype=torch.bool)
    first[0] = True
    act = torch.randn(8, 3, 3)
    with torch.no_grad():
        whole = net.evaluate(obs, net.initial_state(3), first, act)
        head = net.evaluate(obs[:5], net.initial_state(3), first[:5], act[:5])
        tail = net.evaluate(obs[5:], head[3], first[5:], act[5:])
    torch.testing.assert_close(torch.cat([head[0], tail[0]]), whole[0])
    torch.testing.assert_close(torch.cat([head[2], tail[2]]), whole[2])


def test_a_recurrent_checkpoint_plays_each_episode_from_a_zero_state(tmp_path):
    config = EnvConfig(sensors={"scan": {"n_rays": 8}}, max_steps=30)  # continuous: the means are compared
    net, norm = _net(n_obs=SCAN_OBS, n_actions=2, continuous=True), RunningNorm((SCAN_OBS,))
    with torch.no_grad():
        net.actor[2].weight.mul_(0.1)  # means inside [-1, 1], where the clip does not hide them
    norm.update(torch.randn(40, SCAN_OBS, dtype=torch.float64) * 2 + 1)
    save_checkpoint(tmp_path / "r.pt", net, norm, config, step=7)
    ckpt = load_checkpoint(tmp_path / "r.pt")
    assert ckpt.network["memory"] == 4 and isinstance(ckpt.agent, RecurrentActorCritic)
    obs = np.random.default_rng(1).normal(size=(6, SCAN_OBS)).astype(np.float32)
    z = np.clip((obs - norm.mean.numpy()) / np.sqrt(norm.var.numpy() + 1e-8), -10, 10)
    means, _ = _by_hand(net, z[:, None, :], np.eye(6, 1, dtype=bool))
    want = means[:, 0]
    assert np.abs(want).max() < 1.0
    factory = CheckpointPolicy(str(tmp_path / "r.pt"))
    for _ in range(2):  # a second episode starts again from zero
        policy = factory(None)
        np.testing.assert_allclose([policy(o) for o in obs], want, atol=1e-5)


SCAN_OBS = 10  # the scan config's flat observation: the goal (2: SCAN's polar goal, or x, y) and 8 ranges


@pytest.mark.parametrize("bad", [-1, True, 2.5, "8"])
def test_memory_must_be_a_count(bad):
    with pytest.raises(ValueError, match="memory"):
        PPOSettings(memory=bad)


def test_train_then_eval_a_recurrent_policy(room, monkeypatch):  # noqa: F811
    monkeypatch.chdir(room)
    config = _train_config("lstm_run", SCAN)
    config["ppo"]["memory"] = 8
    assert main(["train", "--config", _write(room / "lstm.yaml", config), "--quiet"]) == 0
    assert load_checkpoint(room / "lstm_run" / "best.pt").network["memory"] == 8
    assert main(["eval", "--policy", "lstm_run/best.pt", "--dataset", "val.json.gz", "--results", "lstm.jsonl",
                 "--quiet"]) == 0
    _same_as_trainer(room / "lstm_run", room / "lstm.jsonl")
    assert os.path.exists(room / "lstm_run" / "curve.png")


def test_a_rollout_replays_to_its_own_log_probabilities():
    """The rollout's first flags and starting state are what the update replays from: with
    the statistics held still, the replay gives every step's log-probability and value, across
    the engine's autoresets and into the next rollout."""
    from test_example_ppo_vector import _room

    from pointnav_core.training.ppo import PPO
    from pointnav_core.vector import VectorPointNavEnv

    env = VectorPointNavEnv(
        6, scene=_room(), seed=0, pool_size=2, sensors={"scan": {"n_rays": 8}}, max_episode_steps=7,
        task={"goal_in_polar": True, "reward_type": "geodesic", "path_range": (0.3, 1.5)},
        action_space="discrete", discrete_actions={"stop": False},
    )
    ppo = PPO(env, PPOSettings(num_steps=12, width=8, memory=4, seed=2))
    obs = ppo.start(env)
    ppo.obs_norm.update(torch.randn(20, obs.shape[1]))
    ppo.obs_norm.update = lambda x: None  # statistics held still
    for _ in range(2):
        obs, buf, _ = ppo.rollout(env, obs)
        resets = buf["valid"] == 0
        assert resets.any(), "episodes of 7 steps end inside 12 steps"
        # An episode's first observation is the one right after its autoreset step.
        assert torch.equal(buf["first"][1:].bool(), resets[:-1])
        norm = ppo.obs_norm.normalize(buf["obs"])
        with torch.no_grad():
            logp, _, value, _ = ppo.agent.evaluate(norm, buf["state"], buf["first"], buf["action"])
        torch.testing.assert_close(logp, buf["logp"], atol=1e-5, rtol=0)
        torch.testing.assert_close(value, buf["value"], atol=1e-5, rtol=0)
