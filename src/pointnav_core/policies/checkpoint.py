"""A policy checkpoint: one file that holds everything needed to play (and resume) a policy.

A checkpoint (``.pt``) is a torch file of plain data only: the actor-critic's state dict
(tensors), the observation normalisation statistics (tensors), the network's shape, the
:class:`~pointnav_core.envs.config.EnvConfig` it was trained with (as JSON text), the
training step and the library version; ``latest.pt`` of a training run also holds the
optimiser and the return statistics, to resume. It is read with
``torch.load(..., weights_only=True)``, which rebuilds tensors, dicts, lists, strings and
numbers and refuses anything else: unlike a pickled model (an SB3 ``.zip``), a checkpoint
someone else made cannot run code when it is loaded.

Examples
--------
>>> import tempfile, os
>>> from pointnav_core.envs.config import EnvConfig
>>> from pointnav_core.policies.network import ActorCritic, RunningNorm
>>> agent, norm = ActorCritic(8, 3, 16), RunningNorm((8,))
>>> path = os.path.join(tempfile.mkdtemp(), "policy.pt")
>>> save_checkpoint(path, agent, norm, EnvConfig(action_space="discrete"), step=128)
>>> ckpt = load_checkpoint(path)
>>> ckpt.step, ckpt.network["n_obs"], ckpt.env_config.action_space
(128, 8, 'discrete')
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Mapping
from typing import Any

import torch

from pointnav_core.envs.config import EnvConfig
from pointnav_core.errors import ArgumentError
from pointnav_core.policies.checkpoint_policy import ACTIONS, check_actions
from pointnav_core.policies.network import ActorCritic, RunningNorm
from pointnav_core.policies.recurrent import RecurrentActorCritic

__all__ = ["CHECKPOINT_SUFFIX", "FORMAT", "FORMAT_VERSION", "Checkpoint", "load_checkpoint", "save_checkpoint"]

#: The file suffix of a checkpoint (``pointnav eval --policy FILE.pt`` plays one).
CHECKPOINT_SUFFIX = ".pt"
#: What a checkpoint's ``format`` entry says, and the layout's version.
FORMAT, FORMAT_VERSION = "pointnav_core.checkpoint", 1
_NETWORK_KEYS = ("n_obs", "n_actions", "width", "continuous")
#: A recurrent network's shape adds its LSTM's units (files without it are feed-forward).
_RECURRENT_KEYS = (*_NETWORK_KEYS, "memory")


@dataclasses.dataclass(frozen=True)
class Checkpoint:
    """A loaded checkpoint.

    Attributes
    ----------
    path : str
        The file it was read from.
    agent : ActorCritic or RecurrentActorCritic
        The network, with its weights (evaluation mode).
    obs_norm : RunningNorm
        The observation statistics the network was trained with.
    env_config : EnvConfig
        The env config it was trained with.
    network : dict
        ``n_obs``, ``n_actions``, ``width``, ``continuous``, and a recurrent network's
        ``memory`` (its LSTM's units).
    step : int
        Env steps trained.
    version : str
        The library version that wrote it.
    training : dict or None
        The optimiser and return statistics (``latest.pt`` of a run), for resuming.
    metrics : dict
        Figures recorded with it (the held-out evaluation's success, SPL, ...).
    actions : {"greedy", "sampled"}
        How it acts when played (:data:`~pointnav_core.policies.checkpoint_policy.ACTIONS`;
        "greedy" for files without the entry).
    """

    path: str
    agent: Any
    obs_norm: RunningNorm
    env_config: EnvConfig
    network: dict[str, Any]
    step: int
    version: str
    training: dict[str, Any] | None
    metrics: dict[str, float]
    actions: str = "greedy"


def save_checkpoint(
    path: str | os.PathLike[str],
    agent: Any,
    obs_norm: RunningNorm,
    env_config: EnvConfig,
    step: int,
    training: Mapping[str, Any] | None = None,
    metrics: Mapping[str, float] | None = None,
    actions: str = "greedy",
) -> None:
    """Write a checkpoint to ``path`` atomically (a reader sees the old file or the new).

    Parameters
    ----------
    path : str or os.PathLike
    agent : ActorCritic or RecurrentActorCritic
    obs_norm : RunningNorm
    env_config : EnvConfig
    step : int
        Env steps trained.
    training : dict, optional
        :meth:`~pointnav_core.training.ppo.PPO.training_state`, for resuming.
    metrics : dict, optional
        Figures to keep with it (plain numbers).
    actions : {"greedy", "sampled"}
        How it acts when played (:data:`~pointnav_core.policies.checkpoint_policy.ACTIONS`).
    """
    from pointnav_core import __version__
    from pointnav_core.utils.outputs import atomic_writer

    if not isinstance(env_config, EnvConfig):
        raise ArgumentError(f"env_config must be an EnvConfig, got {env_config!r}")
    check_actions("actions", actions)
    data = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "library_version": __version__,
        "env_config": json.dumps(env_config.to_dict()),
        "network": dict(agent.shape),
        "state_dict": {k: v.detach().clone() for k, v in agent.state_dict().items()},
        "obs_norm": obs_norm.state_dict(),
        "step": int(step),
        "training": None if training is None else dict(training),
        "metrics": {k: float(v) for k, v in (metrics or {}).items()},
        "actions": actions,
    }
    with atomic_writer(path, "wb") as fh:
        torch.save(data, fh)


def _read(path: str) -> Any:
    """The file's data, loaded without running code; ValueError naming the file otherwise."""
    try:
        return torch.load(path, map_location="cpu", weights_only=True)
    except (FileNotFoundError, IsADirectoryError, PermissionError):
        raise
    except Exception as err:  # noqa: BLE001 -- torch says "not a zip archive", "weights only load failed", ...
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise ArgumentError(
            f"checkpoint {path!r} cannot be read as a pointnav-core checkpoint (a corrupt, truncated "
            f"or foreign file, or one that asks to run code): {first}"
        ) from None


def load_checkpoint(path: str | os.PathLike[str]) -> Checkpoint:
    """Read a checkpoint written by :func:`save_checkpoint`.

    Raises
    ------
    ValueError
        For a file that is not such a checkpoint (corrupt, truncated, another program's,
        another layout, missing entries, weights that do not fit the network), naming it.
    FileNotFoundError
        For a file that does not exist.
    """
    path = os.fspath(path)
    data = _read(path)

    def bad(what: str) -> ValueError:
        return ArgumentError(f"checkpoint {path!r} is not a pointnav-core checkpoint: {what}")

    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise bad(f"it has no 'format': {FORMAT!r} entry")
    if data.get("format_version") != FORMAT_VERSION:
        raise bad(f"layout version {data.get('format_version')!r}, this library reads {FORMAT_VERSION}")
    missing = [k for k in ("env_config", "network", "state_dict", "obs_norm", "step") if k not in data]
    if missing:
        raise bad(f"entries {missing} are missing")
    network = data["network"]
    if not isinstance(network, dict) or sorted(network) not in (sorted(_NETWORK_KEYS), sorted(_RECURRENT_KEYS)):
        raise bad(f"'network' must hold {list(_NETWORK_KEYS)} (and 'memory', when recurrent), got {network!r}")
    try:
        config = EnvConfig.from_dict(json.loads(data["env_config"]))
        shape = (network["n_obs"], network["n_actions"], network["width"], network["continuous"])
        agent: Any = RecurrentActorCritic(*shape, network["memory"]) if "memory" in network else ActorCritic(*shape)
        agent.load_state_dict(data["state_dict"])
        obs_norm = RunningNorm((int(network["n_obs"]),))
        obs_norm.load_state_dict(data["obs_norm"])
    except (ValueError, TypeError, KeyError, RuntimeError) as err:
        raise bad(f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}") from None
    if data.get("actions", "greedy") not in ACTIONS:
        raise bad(f"'actions' must be one of {list(ACTIONS)}, got {data.get('actions')!r}")
    agent.eval()
    return Checkpoint(
        path=path, agent=agent, obs_norm=obs_norm, env_config=config, network=dict(network),
        step=int(data["step"]), version=str(data.get("library_version")),
        training=data.get("training"), metrics=dict(data.get("metrics") or {}),
        actions=data.get("actions", "greedy"),
    )
