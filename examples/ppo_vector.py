"""PPO on the batched engine: a short, single-file PPO in torch (CleanRL style).

``VectorPointNavEnv`` steps thousands of worlds as arrays, so one rollout of ``--num-steps``
steps gives ``num_envs * num_steps`` samples (16,384 with the defaults) without a Python
loop over worlds. The policy acts with Habitat's discrete actions (MOVE_FORWARD 0.25 m,
TURN_LEFT/RIGHT 10 deg; STOP with ``--stop``). Observations and rewards are normalised by
running statistics (as SB3's ``VecNormalize`` does), and the engine's next-step autoreset
is respected: the step that resets a world carries no transition, so it is left out of the
losses, and a truncated episode bootstraps from the value of its final observation.

Run (one torch thread; the default scene is the default house as a grid)::

    python examples/ppo_vector.py --total-steps 200000
    python examples/ppo_vector.py --num-envs 1024 --device cpu   # the engine on torch too

:func:`train` is reused by ``benchmarks/bench_learning_vector.py``.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch
from torch import nn


@dataclass
class Config:
    """PPO's settings (SB3's defaults where the benchmark does not change them)."""

    total_steps: int = 500_000
    num_steps: int = 32  # steps per world per rollout
    lr: float = 3e-4
    gamma: float = 0.99
    gae_lambda: float = 0.95
    epochs: int = 4
    minibatch: int = 1024
    clip: float = 0.2
    ent_coef: float = 0.01
    vf_coef: float = 0.5
    max_grad_norm: float = 0.5
    width: int = 256
    seed: int = 0


class RunningNorm:
    """Running mean and variance of a stream of batches (Chan's parallel update)."""

    def __init__(self, shape: tuple[int, ...]) -> None:
        self.mean = torch.zeros(shape, dtype=torch.float64)
        self.var = torch.ones(shape, dtype=torch.float64)
        self.count = 1e-4

    def update(self, x: torch.Tensor) -> None:
        x = x.double()
        mean, var, n = x.mean(0), x.var(0, unbiased=False), x.shape[0]
        delta, total = mean - self.mean, self.count + n
        self.mean = self.mean + delta * n / total
        self.var = (self.var * self.count + var * n + delta**2 * self.count * n / total) / total
        self.count = total

    def normalize(self, x: torch.Tensor, clip: float = 10.0) -> torch.Tensor:
        """``x`` standardised and clipped, as float32."""
        z = (x.double() - self.mean) / torch.sqrt(self.var + 1e-8)
        return z.clamp(-clip, clip).float()


def layer(n_in: int, n_out: int, std: float = 2**0.5) -> nn.Linear:
    lin = nn.Linear(n_in, n_out)
    nn.init.orthogonal_(lin.weight, std)
    nn.init.zeros_(lin.bias)
    return lin


class Agent(nn.Module):
    """Separate actor and critic MLPs (two tanh layers of ``width``), as SB3's MlpPolicy."""

    def __init__(self, n_obs: int, n_actions: int, width: int) -> None:
        super().__init__()
        self.critic = nn.Sequential(layer(n_obs, width), nn.Tanh(), layer(width, width), nn.Tanh(), layer(width, 1, 1.0))
        self.actor = nn.Sequential(layer(n_obs, width), nn.Tanh(), layer(width, width), nn.Tanh(), layer(width, n_actions, 0.01))

    def value(self, obs: torch.Tensor) -> torch.Tensor:
        return self.critic(obs).squeeze(-1)

    def act(self, obs: torch.Tensor, action: torch.Tensor | None = None) -> tuple[torch.Tensor, ...]:
        """A sampled (or the given) action, its log-probability, the entropy and the value."""
        dist = torch.distributions.Categorical(logits=self.actor(obs))
        if action is None:
            action = dist.sample()
        return action, dist.log_prob(action), dist.entropy(), self.value(obs)

    def greedy(self, obs: torch.Tensor) -> torch.Tensor:
        """The most likely action (for evaluation)."""
        return self.actor(obs).argmax(-1)


def as_tensor(x: Any) -> torch.Tensor:
    return x if isinstance(x, torch.Tensor) else torch.from_numpy(np.asarray(x))


def train(
    env: Any, cfg: Config, log: Callable[[dict[str, float], Agent, RunningNorm], bool] | None = None
) -> tuple[Agent, RunningNorm]:
    """Train a PPO agent on a ``VectorPointNavEnv`` with discrete actions.

    Parameters
    ----------
    env : VectorPointNavEnv
        Any device; its arrays are moved to CPU torch tensors for the learner.
    cfg : Config
    log : callable, optional
        Called after every update with ``steps``, ``episodes``, ``success``, ``spl`` (of the
        episodes that ended in that rollout) and ``wall_s``, and with the agent and the
        observation statistics; training stops when it returns False.

    Returns
    -------
    agent, obs_norm
        The policy and the observation statistics it was trained with (frozen).
    """
    torch.manual_seed(cfg.seed)
    n, t_len = env.num_envs, cfg.num_steps
    n_obs = env.single_observation_space.shape[0]
    agent = Agent(n_obs, int(env.single_action_space.n), cfg.width)
    opt = torch.optim.Adam(agent.parameters(), lr=cfg.lr, eps=1e-5)
    obs_norm, ret_norm = RunningNorm((n_obs,)), RunningNorm(())
    ret = torch.zeros(n, dtype=torch.float64)  # discounted return, for the reward scale
    buf = {k: torch.zeros((t_len, n)) for k in ("logp", "value", "reward", "term", "done", "valid")}
    raw_obs = torch.zeros((t_len, n, n_obs))
    actions = torch.zeros((t_len, n), dtype=torch.long)
    obs, _ = env.reset(seed=cfg.seed)
    obs = as_tensor(obs).float()
    steps, start, updates = 0, time.perf_counter(), cfg.total_steps // (n * t_len)
    for _ in range(max(updates, 1)):
        ended = {"n": 0.0, "success": 0.0, "spl": 0.0}
        for t in range(t_len):
            obs_norm.update(obs)
            raw_obs[t] = obs
            with torch.no_grad():
                action, logp, _, value = agent.act(obs_norm.normalize(obs))
            obs, reward, term, trunc, info = env.step(action.to(env.arrays.device) if env.arrays.is_torch else action.numpy())
            obs = as_tensor(obs).float()
            reward, term, trunc = as_tensor(reward).double(), as_tensor(term), as_tensor(trunc)
            done = term | trunc
            valid_now = ~as_tensor(info["autoreset"])
            ret = torch.where(valid_now, ret * cfg.gamma + reward, ret)
            ret_norm.update(ret[valid_now] if valid_now.any() else ret)
            actions[t], buf["logp"][t], buf["value"][t] = action, logp, value
            buf["reward"][t] = (reward / torch.sqrt(ret_norm.var + 1e-8)).clamp(-10, 10).float()
            buf["term"][t], buf["done"][t], buf["valid"][t] = term.float(), done.float(), valid_now.float()
            ret = torch.where(done, torch.zeros_like(ret), ret)
            if done.any():
                ended["n"] += float(done.sum())
                ended["success"] += float(as_tensor(info["success"])[done].double().sum())
                ended["spl"] += float(as_tensor(info["spl"])[done].double().sum())
        steps += n * t_len
        # GAE: V(next) is the value of the observation the step returned (a final one when the
        # episode ended: truncation bootstraps from it, termination does not).
        with torch.no_grad():
            norm_all = obs_norm.normalize(raw_obs.reshape(-1, n_obs)).reshape(t_len, n, n_obs)
            values = agent.value(norm_all)
            next_value = agent.value(obs_norm.normalize(obs))
        adv = torch.zeros((t_len, n))
        gae = torch.zeros(n)
        for t in reversed(range(t_len)):
            nv = next_value if t == t_len - 1 else values[t + 1]
            delta = buf["reward"][t] + cfg.gamma * nv * (1 - buf["term"][t]) - values[t]
            gae = delta + cfg.gamma * cfg.gae_lambda * (1 - buf["done"][t]) * gae
            adv[t] = gae
        returns = adv + values
        keep = buf["valid"].reshape(-1) > 0  # a reset step carries no transition
        b_obs, b_act = norm_all.reshape(-1, n_obs)[keep], actions.reshape(-1)[keep]
        b_logp, b_adv, b_ret = buf["logp"].reshape(-1)[keep], adv.reshape(-1)[keep], returns.reshape(-1)[keep]
        size = b_obs.shape[0]
        for _ in range(cfg.epochs):
            perm = torch.randperm(size)
            for i in range(0, size, cfg.minibatch):
                mb = perm[i : i + cfg.minibatch]
                _, logp, entropy, value = agent.act(b_obs[mb], b_act[mb])
                ratio = torch.exp(logp - b_logp[mb])
                a = b_adv[mb]
                a = (a - a.mean()) / (a.std() + 1e-8)
                pg = torch.max(-a * ratio, -a * ratio.clamp(1 - cfg.clip, 1 + cfg.clip)).mean()
                v_loss = 0.5 * ((value - b_ret[mb]) ** 2).mean()
                loss = pg + cfg.vf_coef * v_loss - cfg.ent_coef * entropy.mean()
                opt.zero_grad()
                loss.backward()
                nn.utils.clip_grad_norm_(agent.parameters(), cfg.max_grad_norm)
                opt.step()
        stats = {"steps": float(steps), "episodes": ended["n"], "wall_s": time.perf_counter() - start,
                 "success": ended["success"] / max(ended["n"], 1.0), "spl": ended["spl"] / max(ended["n"], 1.0)}
        if log is not None and log(stats, agent, obs_norm) is False:
            break
    return agent, obs_norm


def main() -> None:
    from pointnav_core.vector import VectorPointNavEnv

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--num-envs", type=int, default=512)
    p.add_argument("--device", default="numpy", help="the engine's: numpy, cpu or cuda")
    p.add_argument("--total-steps", type=int, default=Config.total_steps)
    p.add_argument("--num-steps", type=int, default=Config.num_steps)
    p.add_argument("--max-steps", type=int, default=150, help="actions per episode")
    p.add_argument("--stop", action="store_true", help="STOP is an action (success needs it)")
    p.add_argument("--seed", type=int, default=0)
    args = p.parse_args()
    torch.set_num_threads(1)
    env = VectorPointNavEnv(
        args.num_envs, device=args.device, seed=args.seed, max_episode_steps=args.max_steps,
        task={"goal_in_polar": True, "reward_type": "geodesic"},
        action_space="discrete", discrete_actions={"stop": args.stop}, pool_size=4, starts_per_goal=32,
    )
    cfg = Config(total_steps=args.total_steps, num_steps=args.num_steps, seed=args.seed)

    def log(s: dict[str, float], *_: Any) -> bool:
        print(f"{s['steps']:>9.0f} steps  {s['steps'] / s['wall_s']:>7.0f} steps/s  "
              f"success {s['success']:.3f}  SPL {s['spl']:.3f}  ({s['episodes']:.0f} episodes)", flush=True)
        return True

    train(env, cfg, log)


if __name__ == "__main__":
    main()
