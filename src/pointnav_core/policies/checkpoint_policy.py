"""A checkpoint as an evaluation policy: ``pointnav eval --policy CHECKPOINT.pt``.

:class:`CheckpointPolicy` is the policy factory :func:`pointnav_core.evaluation.run.evaluate`
plays a checkpoint with: its env config is the checkpoint's own (unless the caller gives
one), and it acts as the checkpoint says (``actions``, which a training run's
``eval_actions`` sets, or as the caller asks): ``"greedy"``, deterministically (the most
likely discrete action, or the Gaussian's mean), or ``"sampled"``, an action drawn from the
policy's distribution by a generator seeded with the episode's seed (the env's
``np_random_seed``, which :func:`~pointnav_core.evaluation.run.evaluate` sets from the
episode's ids), so that a sampled episode plays the same in any order, process or worker
count. A deterministic policy can stall for good where one step of another action would
free it (docs/decisions.md, "Sampled actions"). A recurrent network starts each episode
with a zero state and carries it from step to step. The file is read once per process;
the factory itself pickles as its path, so worker processes load it themselves.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np

from pointnav_core.envs.config import EnvConfig
from pointnav_core.errors import ArgumentError

__all__ = ["ACTIONS", "CheckpointPolicy", "check_actions"]

#: How a checkpoint acts when played (see the module notes).
ACTIONS = ("greedy", "sampled")


def check_actions(name: str, actions: object) -> str:
    """``actions`` if it is one of :data:`ACTIONS`; ValueError naming ``name`` otherwise."""
    if not isinstance(actions, str) or actions not in ACTIONS:
        raise ArgumentError(f"{name} must be one of {list(ACTIONS)}, got {actions!r}")
    return actions


class CheckpointPolicy:
    """A picklable factory ``env -> (observation -> action)`` for a checkpoint file.

    Parameters
    ----------
    path : str
        A checkpoint written by :func:`~pointnav_core.policies.checkpoint.save_checkpoint`.
    actions : {"greedy", "sampled"}, optional
        How to act (:data:`ACTIONS`); default: as the checkpoint says.

    Raises
    ------
    ValueError
        (When first used) for a file that is not a checkpoint, naming it.
    """

    #: The checkpoint's networks read the flat observation.
    flat = True

    def __init__(self, path: str, actions: str | None = None) -> None:
        self.path = path
        self.actions = None if actions is None else check_actions("actions", actions)
        self._checkpoint: Any = None

    def __getstate__(self) -> dict[str, Any]:
        return {"path": self.path, "actions": self.actions, "_checkpoint": None}

    @property
    def checkpoint(self) -> Any:
        """The loaded :class:`~pointnav_core.policies.checkpoint.Checkpoint`."""
        if self._checkpoint is None:
            from pointnav_core.policies.checkpoint import load_checkpoint

            self._checkpoint = load_checkpoint(self.path)
        return self._checkpoint

    @property
    def env_config(self) -> EnvConfig:
        """The env config the checkpoint was trained with."""
        return self.checkpoint.env_config

    def spaces(self) -> Any:
        """The observation and action spaces the network was built for (their shapes)."""
        from gymnasium import spaces

        net = self.checkpoint.network
        obs = spaces.Box(-np.inf, np.inf, (net["n_obs"],), np.float32)
        if net["continuous"]:
            action: Any = spaces.Box(-1.0, 1.0, (net["n_actions"],), np.float32)
        else:
            action = spaces.Discrete(net["n_actions"])
        return SimpleNamespace(observation_space=obs, action_space=action)

    def check_env(self, env: Any) -> None:
        """ValueError unless ``env``'s spaces have the shapes the network was built for."""
        from pointnav_core.policies.spaces import check_spaces

        own = self.env_config.to_dict()
        check_spaces(
            f"checkpoint {self.path!r}", self.spaces(), env,
            advice=f"play it with the env config it carries (sensors {own['sensors']}, action_space "
            f"{own['action_space']!r}): leave out --env-config (evaluate(env_config=None))",
        )

    def __call__(self, env: Any) -> Any:
        import torch

        ckpt = self.checkpoint
        agent, norm, continuous = ckpt.agent, ckpt.obs_norm, ckpt.network["continuous"]
        generator = None
        if (self.actions or ckpt.actions) == "sampled":
            seed = getattr(getattr(env, "unwrapped", env), "np_random_seed", None)
            if not isinstance(seed, int) or seed < 0:
                raise ArgumentError(
                    f"checkpoint {self.path!r} with sampled actions needs an env reset with an integer "
                    f"seed (its np_random_seed seeds the draws), got {seed!r}"
                )
            generator = torch.Generator().manual_seed(seed)
        # A recurrent network's memory of this episode (a factory call is one episode).
        memory = None
        if "memory" in ckpt.network:
            memory = {"state": agent.initial_state(1), "first": torch.ones(1, dtype=torch.bool)}

        def act(obs: Any) -> Any:
            x = norm.normalize(torch.as_tensor(np.asarray(obs, dtype=np.float32)).reshape(1, -1))
            with torch.no_grad():
                if memory is None:
                    action = agent.greedy(x)[0] if generator is None else agent.sample(x, generator)[0]
                else:
                    step = (x, memory["state"], memory["first"])
                    out, memory["state"] = agent.greedy(*step) if generator is None else agent.sample(*step, generator)
                    action, memory["first"] = out[0], torch.zeros(1, dtype=torch.bool)
            return action.numpy().astype(np.float32) if continuous else int(action)

        return act
