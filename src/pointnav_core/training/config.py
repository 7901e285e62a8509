"""``pointnav train``'s config file: what to train, on what, and where to write it.

A YAML or JSON file (:meth:`TrainConfig.load`) with these sections, every field but
``eval_dataset`` optional:

``env``
    The :class:`~pointnav_core.envs.config.EnvConfig` the policy is trained with (and that
    its checkpoints carry): sensors, actions, robot, task settings, ``max_steps``.
``scenes``, ``split``, ``max_scenes``
    The scene set (``houses``, ``mazes``, ``clutter`` or a folder of scene files) and the
    split whose scenes it trains on (default ``houses``, ``train``, all of them).
``path_range``
    ``[min, max]`` start-goal geodesic distance (m) of the training episodes (the task's
    ``path_range``; default the task's own).
``eval_dataset``, ``eval_every``, ``eval_limit``, ``eval_stride``, ``eval_workers``, ``scenes_dir``
    The held-out episode dataset played every ``eval_every`` env steps and at the end,
    through :func:`pointnav_core.evaluation.run.evaluate` (``pointnav eval``'s code), its subset
    (as ``--limit`` and ``--stride``), worker processes, and the folder its scene paths are
    read from (default the current one, as ``pointnav eval --scenes-dir``).
``eval_actions``
    How the checkpoints act when played, in the held-out evaluation and by ``pointnav
    eval`` (which reads it from the checkpoint): ``"greedy"`` (default) or ``"sampled"``
    (:mod:`pointnav_core.policies.checkpoint_policy`).
``out``
    The output folder (default ``runs/pointnav``).
``ppo``
    :class:`~pointnav_core.training.ppo.PPOSettings`'s fields.
``engine``
    :class:`EngineSettings`'s fields: the batched engine's worlds and episode pools.

Relative paths are read from the current folder.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Mapping
from typing import Any

from pointnav_core.envs.config import EnvConfig, read_config_file
from pointnav_core.errors import ArgumentError
from pointnav_core.policies.checkpoint_policy import check_actions
from pointnav_core.training.ppo import PPOSettings
from pointnav_core.utils import validation

__all__ = ["EngineSettings", "TrainConfig"]


@dataclasses.dataclass(frozen=True)
class EngineSettings:
    """The batched engine's settings for training.

    Attributes
    ----------
    num_envs : int
        Worlds stepped together (default 256).
    device : str
        ``"numpy"`` (default), ``"cpu"`` or ``"cuda"`` (the engine's; the learner is on CPU).
    pool_size : int
        Goals prepared per scene, each with its settled goal field (default 1).
    starts_per_goal : int
        Episodes per pool goal (default 32).
    refresh_every : int
        Refresh the episode pools (fresh goals, in the background) every this many env
        steps, skipping a tick while the last refresh still builds (the learner never
        waits for a pool); 0 never (default).
    workers : int or None
        Processes that build the pools (default: the engine's choice).
    torch_threads : int
        torch's CPU threads for the learner (default 1).
    """

    num_envs: int = 256
    device: str = "numpy"
    pool_size: int = 1
    starts_per_goal: int = 32
    refresh_every: int = 0
    workers: int | None = None
    torch_threads: int = 1

    def __post_init__(self) -> None:
        for name in ("num_envs", "pool_size", "starts_per_goal", "torch_threads"):
            validation.integer(name, getattr(self, name), minimum=1)
        validation.integer("refresh_every", self.refresh_every, minimum=0)
        if self.workers is not None:
            validation.integer("workers", self.workers, minimum=1)
        if not isinstance(self.device, str):
            raise ArgumentError(f"device must be 'numpy', 'cpu' or 'cuda[:n]', got {self.device!r}")


def _section(cls: Any, name: str, data: Any) -> Any:
    """``cls(**data)``, with an unknown key or a bad value named under ``name``."""
    if isinstance(data, cls):
        return data
    if not isinstance(data, Mapping):
        raise ArgumentError(f"{name} must be a mapping of its fields, got {data!r}")
    validation.known_keys(name, data, [f.name for f in dataclasses.fields(cls)])
    try:
        return cls(**data)
    except ValueError as err:
        raise ArgumentError(f"{name}: {err}") from None


@dataclasses.dataclass(frozen=True, kw_only=True)
class TrainConfig:
    """A training run's settings (see the module notes for each field)."""

    eval_dataset: str
    env: EnvConfig = dataclasses.field(default_factory=EnvConfig)
    scenes: str = "houses"
    split: str = "train"
    max_scenes: int | None = None
    path_range: tuple[float, float] | None = None
    eval_every: int = 100_000
    eval_limit: int | None = None
    eval_stride: int = 1
    eval_workers: int = 1
    eval_actions: str = "greedy"
    scenes_dir: str = "."
    out: str = "runs/pointnav"
    ppo: PPOSettings = dataclasses.field(default_factory=PPOSettings)
    engine: EngineSettings = dataclasses.field(default_factory=EngineSettings)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        if not isinstance(self.env, EnvConfig):
            set_(self, "env", EnvConfig.from_dict(self.env, name="env"))
        set_(self, "ppo", _section(PPOSettings, "ppo", self.ppo))
        set_(self, "engine", _section(EngineSettings, "engine", self.engine))
        for name in ("eval_dataset", "scenes", "split", "scenes_dir", "out"):
            if not isinstance(getattr(self, name), str) or not getattr(self, name):
                raise ArgumentError(f"{name} must be a non-empty string, got {getattr(self, name)!r}")
        for name in ("eval_every", "eval_stride", "eval_workers"):
            validation.integer(name, getattr(self, name), minimum=1)
        check_actions("eval_actions", self.eval_actions)
        for name in ("max_scenes", "eval_limit"):
            if getattr(self, name) is not None:
                validation.integer(name, getattr(self, name), minimum=1)
        if self.path_range is not None:
            pr = self.path_range
            if isinstance(pr, (str, bytes)) or not hasattr(pr, "__len__") or len(pr) != 2:
                raise ArgumentError(f"path_range must be [min, max] in metres, got {pr!r}")
            lo = validation.real("path_range[0]", pr[0], minimum=0.0)
            hi = validation.real("path_range[1]", pr[1], minimum=lo, strict=True)
            set_(self, "path_range", (lo, hi))
        if self.env.backend != "kinematic" or not self.env.flatten_obs:
            raise ArgumentError("env: training runs on the batched engine: backend 'kinematic' and flatten_obs True")

    def policy_config(self) -> EnvConfig:
        """The env config the policy is trained with and its checkpoints carry: ``env``,
        with ``path_range`` in its task when given."""
        if self.path_range is None:
            return self.env
        return dataclasses.replace(self.env, task={**self.env.task, "path_range": list(self.path_range)})

    def to_dict(self) -> dict[str, Any]:
        """The config as plain data (:meth:`from_dict` gives it back)."""
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        out.update(env=self.env.to_dict(), ppo=dataclasses.asdict(self.ppo), engine=dataclasses.asdict(self.engine))
        if self.path_range is not None:
            out["path_range"] = list(self.path_range)
        return out

    @classmethod
    def from_dict(cls, data: Any, name: str = "train config") -> TrainConfig:
        """The config of a mapping; ValueError naming an unknown key, a missing
        ``eval_dataset`` or a bad value."""
        if not isinstance(data, Mapping):
            raise ArgumentError(f"{name} must be a mapping of its fields, got {data!r}")
        validation.known_keys(name, data, [f.name for f in dataclasses.fields(cls)])
        if "eval_dataset" not in data:
            raise ArgumentError(f"{name} needs eval_dataset: the held-out episode dataset (.json.gz) to evaluate on")
        return cls(**data)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> TrainConfig:
        """Read a ``.yaml``/``.yml`` or ``.json`` file; ValueError naming the file and the
        field for a bad one."""
        path = os.fspath(path)
        data = read_config_file(path, "train config")
        try:
            return cls.from_dict(data)
        except ValueError as err:
            raise ArgumentError(f"train config {path!r}: {err}") from None
