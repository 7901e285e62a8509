"""PPO on the batched engine (:class:`~pointnav_core.vector.VectorPointNavEnv`), in torch.

A short PPO in CleanRL's style. One rollout of ``num_steps`` steps of every world gives
``num_envs * num_steps`` samples without a Python loop over worlds. Observations and
rewards are normalised by running statistics (as SB3's ``VecNormalize`` does), and the
engine's next-step autoreset is respected: the step that resets a world carries no
transition, so it is left out of the losses, and a truncated episode bootstraps from the
value of its final observation. Discrete actions (Habitat's) are a categorical; continuous
ones (velocity commands, clipped to ``[-1, 1]`` by the env) a diagonal Gaussian.

With ``memory`` > 0 the policy is recurrent
(:class:`~pointnav_core.policies.recurrent.RecurrentActorCritic`, DD-PPO's LSTM core), as in
CleanRL's ``ppo_atari_lstm``: the rollout carries each world's LSTM state and marks each
episode's first observation (the one the engine's autoreset step returns), and the update
replays whole worlds' sequences from the state they started the rollout with, so that
minibatches are sets of worlds rather than of samples.

:class:`PPO` keeps what training needs between rollouts (the network, the optimiser, the
statistics, the step count) so that ``pointnav train`` can save it and resume;
:func:`train` runs it to a step budget (``examples/ppo_vector.py`` calls it).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from typing import Any

import torch
from torch import nn

from pointnav_core.errors import ArgumentError
from pointnav_core.policies.network import ActorCritic, RunningNorm, as_tensor
from pointnav_core.policies.recurrent import RecurrentActorCritic
from pointnav_core.utils import validation

__all__ = ["PPO", "PPOSettings", "train"]


@dataclasses.dataclass
class PPOSettings:
    """PPO's settings (SB3's defaults where the benchmark does not change them).

    Attributes
    ----------
    total_steps : int
        Env steps (all worlds together) to train for.
    num_steps : int
        Steps per world per rollout.
    lr : float
        Adam's learning rate.
    gamma, gae_lambda : float
        Discount and GAE's lambda.
    epochs, minibatch : int
        Passes over each rollout, and samples per gradient step.
    clip : float
        PPO's ratio clip.
    ent_coef, vf_coef : float
        Weights of the entropy bonus and of the value loss.
    max_grad_norm : float
        Gradient norm clip.
    width : int
        Units per hidden layer of the actor and of the critic.
    memory : int
        Units of the recurrent policy's LSTM; 0 (the default): the feed-forward MLP. A
        recurrent update's minibatches are ``max(1, minibatch // num_steps)`` worlds.
    seed : int
        Seeds the network, the sampling and the env.
    """

    total_steps: int = 500_000
    num_steps: int = 32
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
    memory: int = 0
    seed: int = 0

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.type == "int":
                minimum = 0 if f.name in ("seed", "memory") else 1
                setattr(self, f.name, validation.integer(f.name, value, minimum=minimum))
            else:
                strict = f.name in ("lr", "clip", "max_grad_norm")
                setattr(self, f.name, validation.real(f.name, value, minimum=0.0, strict=strict, unit=""))
        for name in ("gamma", "gae_lambda"):
            if getattr(self, name) > 1.0:
                raise ArgumentError(f"{name} must be in [0, 1], got {getattr(self, name)!r}")


class PPO:
    """A PPO learner for one batched env's spaces.

    Parameters
    ----------
    env : VectorPointNavEnv
        Its flat observation's length and its action space (``Discrete`` or ``Box``) shape
        the network.
    settings : PPOSettings
    """

    def __init__(self, env: Any, settings: PPOSettings) -> None:
        torch.manual_seed(settings.seed)
        self.settings = settings
        n_obs = int(env.single_observation_space.shape[0])
        space = env.single_action_space
        continuous = not hasattr(space, "n")
        n_actions = int(space.shape[0]) if continuous else int(space.n)
        self.recurrent = settings.memory > 0
        self.agent: Any = (
            RecurrentActorCritic(n_obs, n_actions, settings.width, continuous, settings.memory)
            if self.recurrent else ActorCritic(n_obs, n_actions, settings.width, continuous)
        )
        self.opt = torch.optim.Adam(self.agent.parameters(), lr=settings.lr, eps=1e-5)
        self.obs_norm, self.ret_norm = RunningNorm((n_obs,)), RunningNorm(())
        self.steps = 0

    # ------------------------------------------------------------------ state
    def training_state(self) -> dict[str, Any]:
        """What resuming needs beyond the network and the observation statistics."""
        return {"optimizer": self.opt.state_dict(), "return_norm": self.ret_norm.state_dict(),
                "steps": int(self.steps)}

    def load_training_state(self, state: dict[str, Any]) -> None:
        """Take :meth:`training_state`'s values (the network and statistics are set apart)."""
        self.opt.load_state_dict(state["optimizer"])
        self.ret_norm.load_state_dict(state["return_norm"])
        self.steps = int(state["steps"])

    # ------------------------------------------------------------------ one update
    def rollout(self, env: Any, obs: torch.Tensor) -> tuple[torch.Tensor, dict[str, Any], dict[str, float]]:
        """Step every world ``num_steps`` times from ``obs``: the next observation, the
        rollout's buffers and the sums over the episodes that ended in it."""
        cfg, agent, n = self.settings, self.agent, env.num_envs
        t_len, n_obs = cfg.num_steps, obs.shape[1]
        buf = {k: torch.zeros((t_len, n)) for k in ("logp", "value", "reward", "term", "done", "valid")}
        buf["obs"] = torch.zeros((t_len, n, n_obs))
        ended = {"n": 0.0, "success": 0.0, "spl": 0.0, "return": 0.0}
        if self.recurrent:  # the state each world starts the rollout with, to replay it from
            buf["first"], buf["state"] = torch.zeros((t_len, n)), tuple(x.clone() for x in self.state)
        for t in range(t_len):
            self.obs_norm.update(obs)
            buf["obs"][t] = obs
            with torch.no_grad():
                if self.recurrent:
                    buf["first"][t] = self.first.float()
                    action, logp, _, value, self.state = agent.act(self.obs_norm.normalize(obs), self.state, self.first)
                else:
                    action, logp, _, value = agent.act(self.obs_norm.normalize(obs))
            if t == 0:
                buf["action"] = torch.zeros((t_len, *action.shape), dtype=action.dtype)
            sent = action.to(env.arrays.device) if env.arrays.is_torch else action.numpy()
            obs, reward, term, trunc, info = env.step(sent)
            obs = as_tensor(obs).float()
            reward, term, trunc = as_tensor(reward).double(), as_tensor(term), as_tensor(trunc)
            done = term | trunc
            valid_now = ~as_tensor(info["autoreset"])
            self.first = ~valid_now  # an autoreset step returns the next episode's first observation
            self.ret = torch.where(valid_now, self.ret * cfg.gamma + reward, self.ret)
            self.ep_ret = torch.where(valid_now, self.ep_ret + reward, self.ep_ret)
            self.ret_norm.update(self.ret[valid_now] if valid_now.any() else self.ret)
            buf["action"][t], buf["logp"][t], buf["value"][t] = action, logp, value
            buf["reward"][t] = (reward / torch.sqrt(self.ret_norm.var + 1e-8)).clamp(-10, 10).float()
            buf["term"][t], buf["done"][t], buf["valid"][t] = term.float(), done.float(), valid_now.float()
            if done.any():
                ended["n"] += float(done.sum())
                ended["success"] += float(as_tensor(info["success"])[done].double().sum())
                ended["spl"] += float(as_tensor(info["spl"])[done].double().sum())
                ended["return"] += float(self.ep_ret[done].sum())
            self.ret = torch.where(done, torch.zeros_like(self.ret), self.ret)
            self.ep_ret = torch.where(done, torch.zeros_like(self.ep_ret), self.ep_ret)
        return obs, buf, ended

    def advantages(self, buf: dict[str, Any], obs: torch.Tensor) -> tuple[torch.Tensor, ...]:
        """GAE: the normalised observations, the advantages and the returns of a rollout.
        V(next) is the value of the observation the step returned (a final one when the
        episode ended: truncation bootstraps from it, termination does not)."""
        cfg = self.settings
        t_len, n, n_obs = buf["obs"].shape
        with torch.no_grad():
            norm_all = self.obs_norm.normalize(buf["obs"].reshape(-1, n_obs)).reshape(t_len, n, n_obs)
            if self.recurrent:
                _, _, values, state = self.agent.evaluate(norm_all, buf["state"], buf["first"], buf["action"])
                next_value = self.agent.value(self.obs_norm.normalize(obs), state, self.first)
            else:
                values = self.agent.value(norm_all)
                next_value = self.agent.value(self.obs_norm.normalize(obs))
        adv = torch.zeros((t_len, n))
        gae = torch.zeros(n)
        for t in reversed(range(t_len)):
            nv = next_value if t == t_len - 1 else values[t + 1]
            delta = buf["reward"][t] + cfg.gamma * nv * (1 - buf["term"][t]) - values[t]
            gae = delta + cfg.gamma * cfg.gae_lambda * (1 - buf["done"][t]) * gae
            adv[t] = gae
        return norm_all, adv, adv + values

    def learn(self, buf: dict[str, Any], norm_all: torch.Tensor, adv: torch.Tensor, returns: torch.Tensor) -> None:
        """PPO's clipped-objective epochs over the rollout's valid transitions."""
        if self.recurrent:
            self._learn_sequences(buf, norm_all, adv, returns)
            return
        cfg, agent = self.settings, self.agent
        n_obs = norm_all.shape[-1]
        keep = buf["valid"].reshape(-1) > 0  # a reset step carries no transition
        b_act = buf["action"].reshape(-1, *buf["action"].shape[2:])[keep]
        b_obs = norm_all.reshape(-1, n_obs)[keep]
        b_logp, b_adv, b_ret = buf["logp"].reshape(-1)[keep], adv.reshape(-1)[keep], returns.reshape(-1)[keep]
        size = b_obs.shape[0]
        for _ in range(cfg.epochs):
            perm = torch.randperm(size)
            for i in range(0, size, cfg.minibatch):
                mb = perm[i : i + cfg.minibatch]
                _, logp, entropy, value = agent.act(b_obs[mb], b_act[mb])
                self._gradient_step(logp, entropy, value, b_logp[mb], b_adv[mb], b_ret[mb])

    def _learn_sequences(self, buf: dict[str, Any], norm_all: torch.Tensor, adv: torch.Tensor,
                         returns: torch.Tensor) -> None:
        """:meth:`learn` for the recurrent policy: minibatches of whole worlds, each replayed
        from its rollout's first state, the losses over its valid transitions."""
        cfg, n = self.settings, norm_all.shape[1]
        worlds = max(1, cfg.minibatch // cfg.num_steps)
        h0, c0 = buf["state"]
        for _ in range(cfg.epochs):
            perm = torch.randperm(n)
            for i in range(0, n, worlds):
                mb = perm[i : i + worlds]
                keep = buf["valid"][:, mb] > 0
                if not keep.any():
                    continue
                logp, entropy, value, _ = self.agent.evaluate(
                    norm_all[:, mb], (h0[:, mb], c0[:, mb]), buf["first"][:, mb], buf["action"][:, mb]
                )
                self._gradient_step(logp[keep], entropy[keep], value[keep], buf["logp"][:, mb][keep],
                                    adv[:, mb][keep], returns[:, mb][keep])

    def _gradient_step(self, logp: torch.Tensor, entropy: torch.Tensor, value: torch.Tensor, old_logp: torch.Tensor,
                       adv: torch.Tensor, ret: torch.Tensor) -> None:
        """One Adam step on PPO's loss over a minibatch (the advantages standardised in it)."""
        cfg = self.settings
        ratio = torch.exp(logp - old_logp)
        a = (adv - adv.mean()) / (adv.std() + 1e-8)
        pg = torch.max(-a * ratio, -a * ratio.clamp(1 - cfg.clip, 1 + cfg.clip)).mean()
        v_loss = 0.5 * ((value - ret) ** 2).mean()
        loss = pg + cfg.vf_coef * v_loss - cfg.ent_coef * entropy.mean()
        self.opt.zero_grad()
        loss.backward()
        nn.utils.clip_grad_norm_(self.agent.parameters(), cfg.max_grad_norm)
        self.opt.step()

    def start(self, env: Any, seed: int | None = None) -> torch.Tensor:
        """Reset ``env`` (seeded with ``seed``, default the settings' seed) and the
        per-world returns: the first observation to :meth:`update` from."""
        obs, _ = env.reset(seed=self.settings.seed if seed is None else seed)
        self.ret = torch.zeros(env.num_envs, dtype=torch.float64)  # discounted, for the reward scale
        self.ep_ret = torch.zeros(env.num_envs, dtype=torch.float64)  # undiscounted, reported
        self.first = torch.ones(env.num_envs, dtype=torch.bool)  # each world's observation begins an episode
        if self.recurrent:
            self.state = self.agent.initial_state(env.num_envs)
        return as_tensor(obs).float()

    def update(self, env: Any, obs: torch.Tensor) -> tuple[torch.Tensor, dict[str, float]]:
        """One rollout and one PPO update: the next observation, and the rollout's
        ``steps`` (the total so far), ``episodes`` (that ended in it), and the ``success``,
        ``spl`` and ``return`` (undiscounted, raw rewards) of those episodes (0 if none)."""
        obs, buf, ended = self.rollout(env, obs)
        self.steps += env.num_envs * self.settings.num_steps
        self.learn(buf, *self.advantages(buf, obs))
        count = max(ended["n"], 1.0)
        return obs, {"steps": float(self.steps), "episodes": ended["n"], "success": ended["success"] / count,
                     "spl": ended["spl"] / count, "return": ended["return"] / count}


def train(
    env: Any, cfg: PPOSettings, log: Callable[[dict[str, float], Any, RunningNorm], bool] | None = None
) -> tuple[Any, RunningNorm]:
    """Train a PPO agent on a ``VectorPointNavEnv`` for ``cfg.total_steps`` steps.

    Parameters
    ----------
    env : VectorPointNavEnv
        Any device; its arrays are moved to CPU torch tensors for the learner.
    cfg : PPOSettings
    log : callable, optional
        Called after every update with :meth:`PPO.update`'s figures plus ``wall_s``, and
        with the agent and the observation statistics; training stops when it returns False.

    Returns
    -------
    agent, obs_norm
        The policy (an ``ActorCritic``, or a ``RecurrentActorCritic`` with ``cfg.memory``)
        and the observation statistics it was trained with.
    """
    ppo = PPO(env, cfg)
    obs = ppo.start(env)
    start, updates = time.perf_counter(), cfg.total_steps // (env.num_envs * cfg.num_steps)
    for _ in range(max(updates, 1)):
        obs, stats = ppo.update(env, obs)
        stats["wall_s"] = time.perf_counter() - start
        if log is not None and log(stats, ppo.agent, ppo.obs_norm) is False:
            break
    return ppo.agent, ppo.obs_norm
