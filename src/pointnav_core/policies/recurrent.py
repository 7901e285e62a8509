"""The recurrent actor-critic of ``pointnav train`` (``ppo: {memory: M}``): DD-PPO's shape.

An observation goes through an encoder (one tanh layer of ``width`` units), then an LSTM of
``memory`` units, whose output feeds an actor and a critic of one tanh layer each (Habitat's
DD-PPO: a visual encoder, an LSTM core, linear heads; here the encoder reads the flat
observation). The LSTM's state is the policy's memory of the episode: it starts at zero
at each episode's first observation.

Every method takes the state to start from and ``first``, whether each observation is the
first of its episode (the state is zeroed there before the observation is read), so one
definition serves the rollout (one step of every world), the update (a rollout's sequences,
episode boundaries inside them) and evaluation (one world).
"""

from __future__ import annotations

import torch
from torch import nn

from pointnav_core.policies.network import action_distribution, greedy_action, layer, sampled_action

__all__ = ["RecurrentActorCritic", "State"]

#: The LSTM's hidden and cell states, each ``(1, B, memory)``.
State = tuple[torch.Tensor, torch.Tensor]


class RecurrentActorCritic(nn.Module):
    """Encoder, LSTM and two heads (see the module notes).

    Parameters
    ----------
    n_obs : int
        Length of the flat observation.
    n_actions : int
        Number of discrete actions, or the length of a continuous action.
    width : int
        Units of the encoder's layer and of each head's hidden layer.
    continuous : bool
        A diagonal Gaussian over ``n_actions`` real numbers instead of a categorical.
    memory : int
        Units of the LSTM, >= 1.
    """

    def __init__(self, n_obs: int, n_actions: int, width: int, continuous: bool = False, memory: int = 128) -> None:
        super().__init__()
        self.shape = {"n_obs": int(n_obs), "n_actions": int(n_actions), "width": int(width),
                      "continuous": bool(continuous), "memory": int(memory)}
        self.encoder = nn.Sequential(layer(n_obs, width), nn.Tanh())
        self.core = nn.LSTM(width, memory)
        for name, param in self.core.named_parameters():  # CleanRL's LSTM initialisation
            if "bias" in name:
                nn.init.zeros_(param)
            else:
                nn.init.orthogonal_(param, 1.0)
        self.actor = nn.Sequential(layer(memory, width), nn.Tanh(), layer(width, n_actions, 0.01))
        self.critic = nn.Sequential(layer(memory, width), nn.Tanh(), layer(width, 1, 1.0))
        self.continuous = bool(continuous)
        if self.continuous:
            self.log_std = nn.Parameter(torch.zeros(n_actions))

    def initial_state(self, batch: int) -> State:
        """The zero state of ``batch`` worlds."""
        zeros = torch.zeros((1, batch, self.core.hidden_size))
        return zeros, zeros.clone()

    def features(self, obs: torch.Tensor, state: State, first: torch.Tensor) -> tuple[torch.Tensor, State]:
        """The LSTM's outputs ``(T, B, memory)`` over observations ``(T, B, n_obs)`` from
        ``state``, zeroed before each observation where ``first`` ``(T, B)`` is true, and
        the state after the last."""
        x = self.encoder(obs)
        h, c = state
        outs = []
        for t in range(obs.shape[0]):  # one call per step: a state may be zeroed between steps
            keep = (~first[t].bool()).float().view(1, -1, 1)
            out, (h, c) = self.core(x[t : t + 1], (h * keep, c * keep))
            outs.append(out)
        return torch.cat(outs), (h, c)

    def act(
        self, obs: torch.Tensor, state: State, first: torch.Tensor, action: torch.Tensor | None = None
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor, State]:
        """One step of ``B`` worlds (``obs`` ``(B, n_obs)``, ``first`` ``(B,)``): a sampled (or
        the given) action, its log-probability, the entropy, the value and the new state."""
        out, state = self.features(obs[None], state, first[None])
        logp, entropy, value, action = self._heads(out[0], action)
        return action, logp, entropy, value, state

    def evaluate(
        self, obs: torch.Tensor, state: State, first: torch.Tensor, action: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, State]:
        """Sequences (``(T, B, ...)``, from ``state``): each taken action's log-probability,
        the entropies and the values, each ``(T, B)``, and the state after the last step."""
        out, state = self.features(obs, state, first)
        logp, entropy, value, _ = self._heads(out, action)
        return logp, entropy, value, state

    def value(self, obs: torch.Tensor, state: State, first: torch.Tensor) -> torch.Tensor:
        """The critic's value of one step's observations ``(B, n_obs)``."""
        out, _ = self.features(obs[None], state, first[None])
        return self.critic(out[0]).squeeze(-1)

    def greedy(self, obs: torch.Tensor, state: State, first: torch.Tensor) -> tuple[torch.Tensor, State]:
        """The deterministic action of one step (see :func:`~pointnav_core.policies.network.greedy_action`)
        and the new state."""
        out, state = self.features(obs[None], state, first[None])
        return greedy_action(self.actor(out[0]), self.continuous), state

    def sample(
        self, obs: torch.Tensor, state: State, first: torch.Tensor, generator: torch.Generator
    ) -> tuple[torch.Tensor, State]:
        """An action of one step drawn with ``generator`` (see
        :func:`~pointnav_core.policies.network.sampled_action`) and the new state."""
        out, state = self.features(obs[None], state, first[None])
        return sampled_action(self.actor(out[0]), self.log_std if self.continuous else None, generator), state

    def _heads(
        self, out: torch.Tensor, action: torch.Tensor | None
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
        dist = action_distribution(self.actor(out), self.log_std if self.continuous else None)
        if action is None:
            action = dist.sample()
        return dist.log_prob(action), dist.entropy(), self.critic(out).squeeze(-1), action
