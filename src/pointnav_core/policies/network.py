"""The actor-critic that ``pointnav train`` trains, and its running observation statistics.

:class:`ActorCritic` is SB3's ``MlpPolicy`` shape: separate actor and critic MLPs of two
tanh layers of ``width`` units, orthogonal initialisation. With discrete actions the actor
gives the logits of a categorical distribution; with continuous ones the mean of a
diagonal Gaussian whose log standard deviation is a learned vector that does not depend on
the observation (CleanRL's and SB3's choice). It is feed-forward, without memory; the
recurrent one is :class:`~pointnav_core.policies.recurrent.RecurrentActorCritic` (see
``docs/decisions.md``, "Issue 32: training").

:class:`RunningNorm` keeps the running mean and variance of observations (and of the
discounted return, for the reward scale), as SB3's ``VecNormalize`` does.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch
from torch import nn

from pointnav_core.errors import ArgumentError

__all__ = ["ActorCritic", "RunningNorm", "action_distribution", "as_tensor", "greedy_action", "layer", "sampled_action"]


class RunningNorm:
    """Running mean and variance of a stream of batches (Chan's parallel update).

    Parameters
    ----------
    shape : tuple of int
        The shape of one sample (``()`` for scalars).
    """

    def __init__(self, shape: tuple[int, ...]) -> None:
        self.mean = torch.zeros(shape, dtype=torch.float64)
        self.var = torch.ones(shape, dtype=torch.float64)
        self.count = 1e-4

    def update(self, x: torch.Tensor) -> None:
        """Fold the batch ``x`` (samples along the first axis) into the statistics."""
        x = x.double()
        mean, var, n = x.mean(0), x.var(0, unbiased=False), x.shape[0]
        delta, total = mean - self.mean, self.count + n
        self.mean = self.mean + delta * n / total
        self.var = (self.var * self.count + var * n + delta**2 * self.count * n / total) / total
        self.count = total

    def normalize(self, x: torch.Tensor, clip: float = 10.0) -> torch.Tensor:
        """``x`` standardised and clipped to ``[-clip, clip]``, as float32."""
        z = (x.double() - self.mean) / torch.sqrt(self.var + 1e-8)
        return z.clamp(-clip, clip).float()

    def state_dict(self) -> dict[str, Any]:
        """The statistics as plain tensors and a float (what a checkpoint stores)."""
        return {"mean": self.mean.clone(), "var": self.var.clone(), "count": float(self.count)}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Take the statistics of :meth:`state_dict`; ValueError for another shape."""
        mean, var = state["mean"], state["var"]
        if tuple(mean.shape) != tuple(self.mean.shape) or tuple(var.shape) != tuple(self.var.shape):
            raise ArgumentError(
                f"observation statistics of shape {tuple(mean.shape)}, expected {tuple(self.mean.shape)}"
            )
        self.mean, self.var = mean.double().clone(), var.double().clone()
        self.count = float(state["count"])


def layer(n_in: int, n_out: int, std: float = 2**0.5) -> nn.Linear:
    """A linear layer with orthogonal weights of gain ``std`` and zero bias."""
    lin = nn.Linear(n_in, n_out)
    nn.init.orthogonal_(lin.weight, std)
    nn.init.zeros_(lin.bias)
    return lin


class ActorCritic(nn.Module):
    """Separate actor and critic MLPs (two tanh layers of ``width``), as SB3's MlpPolicy.

    Parameters
    ----------
    n_obs : int
        Length of the flat observation.
    n_actions : int
        Number of discrete actions, or the length of a continuous action.
    width : int
        Units per hidden layer.
    continuous : bool
        A diagonal Gaussian over ``n_actions`` real numbers instead of a categorical.
    """

    def __init__(self, n_obs: int, n_actions: int, width: int, continuous: bool = False) -> None:
        super().__init__()
        self.shape = {"n_obs": int(n_obs), "n_actions": int(n_actions), "width": int(width),
                      "continuous": bool(continuous)}
        self.critic = nn.Sequential(layer(n_obs, width), nn.Tanh(), layer(width, width), nn.Tanh(), layer(width, 1, 1.0))
        self.actor = nn.Sequential(layer(n_obs, width), nn.Tanh(), layer(width, width), nn.Tanh(), layer(width, n_actions, 0.01))
        self.continuous = bool(continuous)
        if self.continuous:  # std 1 at first: actions in [-1, 1] are explored widely
            self.log_std = nn.Parameter(torch.zeros(n_actions))

    def value(self, obs: torch.Tensor) -> torch.Tensor:
        """The critic's value of each (normalised) observation."""
        return self.critic(obs).squeeze(-1)

    def distribution(self, obs: torch.Tensor) -> torch.distributions.Distribution:
        """The policy's action distribution at each (normalised) observation."""
        return action_distribution(self.actor(obs), self.log_std if self.continuous else None)

    def act(self, obs: torch.Tensor, action: torch.Tensor | None = None) -> tuple[torch.Tensor, ...]:
        """A sampled (or the given) action, its log-probability, the entropy and the value."""
        dist = self.distribution(obs)
        if action is None:
            action = dist.sample()
        return action, dist.log_prob(action), dist.entropy(), self.value(obs)

    def greedy(self, obs: torch.Tensor) -> torch.Tensor:
        """The deterministic action: the most likely one (discrete), or the Gaussian's mean
        clipped to the action bounds ``[-1, 1]`` (continuous)."""
        return greedy_action(self.actor(obs), self.continuous)

    def sample(self, obs: torch.Tensor, generator: torch.Generator) -> torch.Tensor:
        """An action drawn from the policy's distribution with ``generator`` (see
        :func:`sampled_action`)."""
        return sampled_action(self.actor(obs), self.log_std if self.continuous else None, generator)


def action_distribution(out: torch.Tensor, log_std: torch.Tensor | None) -> torch.distributions.Distribution:
    """The actor's output ``out`` as a distribution: a diagonal Gaussian of mean ``out`` and
    log standard deviation ``log_std`` (continuous actions), or a categorical over the
    logits ``out`` (``log_std`` None)."""
    if log_std is not None:
        normal = torch.distributions.Normal(out, log_std.exp().expand_as(out))
        return torch.distributions.Independent(normal, 1)
    return torch.distributions.Categorical(logits=out)


def greedy_action(out: torch.Tensor, continuous: bool) -> torch.Tensor:
    """The deterministic action of the actor's output: the mean clipped to ``[-1, 1]``
    (continuous), or the most likely action."""
    return out.clamp(-1.0, 1.0) if continuous else out.argmax(-1)


def sampled_action(out: torch.Tensor, log_std: torch.Tensor | None, generator: torch.Generator) -> torch.Tensor:
    """An action of :func:`action_distribution` ``(out, log_std)`` drawn with ``generator``
    (``Distribution.sample`` takes none): a category with the softmax's probabilities, or
    the Gaussian's draw clipped to ``[-1, 1]`` as the env clips it."""
    if log_std is None:
        return torch.multinomial(torch.softmax(out, -1), 1, generator=generator).squeeze(-1)
    noise = torch.randn(out.shape, generator=generator, dtype=out.dtype)
    return (out + log_std.exp() * noise).clamp(-1.0, 1.0)


def as_tensor(x: Any) -> torch.Tensor:
    """``x`` (a numpy array, a number or a tensor) as a CPU torch tensor."""
    if isinstance(x, torch.Tensor):
        return x.cpu()
    return torch.from_numpy(np.asarray(x))
