"""A training run: PPO on the batched engine, checkpoints, held-out evaluation, curve, resume.

:func:`run_training` (``pointnav train --config FILE``) trains on the config's split of
its scene set (each scene's floor as grid cells: the batched scan sees cells only, and
the benchmark trains so), and every ``eval_every`` env steps and at the end it

1. saves ``latest.pt`` (the network, the observation statistics, the env config and the
   optimiser: :mod:`pointnav_core.policies.checkpoint`);
2. plays the held-out episodes with that file through
   :func:`pointnav_core.evaluation.run.evaluate` and a
   :class:`~pointnav_core.policies.checkpoint_policy.CheckpointPolicy`, the code and policy
   ``pointnav eval --policy latest.pt`` uses, so that its numbers are eval's to the
   episode; the per-episode results go to ``heldout/step_<N>.jsonl`` (eval's results file);
3. copies the checkpoint to ``best.pt`` (without the optimiser: the file to share) when its
   held-out success is the best so far (SPL breaks ties);
4. appends a row to ``curve.csv`` and redraws ``curve.png``
   (:mod:`pointnav_core.training.curve`).

``resume=True`` continues from ``latest.pt``: the weights, statistics, optimiser and step
count, the curve so far and its best. The env is reseeded with ``seed + step``, so the
resumed part draws new episodes (it does not replay the interrupted run's exact
trajectory). Ctrl-C saves ``latest.pt`` at the end of the current update before stopping.
"""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Callable
from typing import Any

from pointnav_core.errors import ArgumentError
from pointnav_core.policies.checkpoint import load_checkpoint, save_checkpoint
from pointnav_core.training.config import TrainConfig
from pointnav_core.training.curve import plot_curve, read_curve, write_curve
from pointnav_core.training.ppo import PPO

__all__ = ["OUTPUTS", "heldout_episodes", "run_training", "training_scenes"]

#: The files a run writes in its output folder.
OUTPUTS = {"latest": "latest.pt", "best": "best.pt", "curve": "curve.csv", "plot": "curve.png",
           "config": "train_config.yaml", "heldout": "heldout"}


def training_scenes(config: TrainConfig) -> list[Any]:
    """The training split's scenes (the first ``max_scenes``), each the trained floor as a
    one-floor scene of grid cells."""
    from pointnav_core.datasets.scene_sets import load_scene, scene_set
    from pointnav_core.vector.arguments import grid_scene

    ids = scene_set(config.scenes, seed=config.ppo.seed).scene_ids(config.split)[: config.max_scenes]
    if not ids:
        raise ArgumentError(f"split {config.split!r} of scene set {config.scenes!r} has no scenes to train on")
    floor = int(config.env.task.get("floor", 0))
    return [grid_scene(load_scene(scene_id), floor) for scene_id in ids]


def heldout_episodes(config: TrainConfig) -> list[Any]:
    """The held-out episodes (``eval_limit`` and ``eval_stride`` applied), checked before
    any training: their scenes exist, and their robot radius is the config's."""
    from pointnav_core.datasets import EpisodeDataset
    from pointnav_core.evaluation.config import check_robot_radius
    from pointnav_core.evaluation.run import check_scene_ids, select_episodes

    episodes = select_episodes(EpisodeDataset.load(config.eval_dataset), config.eval_limit, config.eval_stride)
    check_robot_radius(config.policy_config(), episodes)
    check_scene_ids(episodes, config.scenes_dir)
    return episodes


def _engine(config: TrainConfig, scenes: list[Any]) -> Any:
    """The batched env the policy trains in (the trained floor is floor 0 of each grid)."""
    from pointnav_core.vector import VectorPointNavEnv

    env_config = config.policy_config()
    if "floor" in env_config.task:
        env_config = dataclasses.replace(env_config, task={**env_config.task, "floor": 0})
    e = config.engine
    return VectorPointNavEnv(
        e.num_envs, scene=scenes, config=env_config, device=e.device, seed=config.ppo.seed,
        pool_size=e.pool_size, starts_per_goal=e.starts_per_goal, workers=e.workers, progress=False,
    )


class _Run:
    """One run's state between updates: the learner, the curve and the output paths."""

    def __init__(self, config: TrainConfig, ppo: PPO, episodes: list[Any]) -> None:
        self.config, self.ppo, self.episodes = config, ppo, episodes
        self.paths = {k: os.path.join(config.out, name) for k, name in OUTPUTS.items()}
        self.rows: list[dict[str, Any]] = []
        self.wall0 = 0.0  # wall seconds of the earlier parts of a resumed run
        self.acc = {"n": 0.0, "return": 0.0, "success": 0.0, "spl": 0.0}

    def resume(self, ckpt: Any) -> None:
        """Take the weights, statistics, optimiser and step of ``ckpt`` (``latest.pt``,
        checked by :func:`_resumable`), and the curve up to its step."""
        if ckpt.network != self.ppo.agent.shape or ckpt.training is None:
            raise ArgumentError(f"--resume: {self.paths['latest']!r} holds another network or no training state")
        self.ppo.agent.load_state_dict(ckpt.agent.state_dict())
        self.ppo.obs_norm.load_state_dict(ckpt.obs_norm.state_dict())
        self.ppo.load_training_state(ckpt.training)
        import torch

        torch.manual_seed(self.config.ppo.seed + self.ppo.steps)  # fresh draws, not the start's again
        if os.path.exists(self.paths["curve"]):
            self.rows = [r for r in read_curve(self.paths["curve"]) if r["step"] <= ckpt.step]
            self.wall0 = self.rows[-1]["wall_s"] if self.rows else 0.0

    def record(self, stats: dict[str, float]) -> None:
        """Add one update's training episodes to the next row's training figures."""
        n = stats["episodes"]
        self.acc["n"] += n
        for key in ("return", "success", "spl"):
            self.acc[key] += stats[key] * n

    def save_latest(self) -> None:
        p = self.ppo
        save_checkpoint(self.paths["latest"], p.agent, p.obs_norm, self.config.policy_config(), p.steps,
                        training=p.training_state(), actions=self.config.eval_actions)

    def evaluate(self, wall: float) -> dict[str, Any]:
        """Save ``latest.pt``, play the held-out episodes with it, keep the row and the best."""
        from pointnav_core.evaluation.report import summary_record, write_results
        from pointnav_core.evaluation.run import evaluate
        from pointnav_core.policies.checkpoint_policy import CheckpointPolicy

        self.save_latest()
        step = self.ppo.steps
        results = evaluate(self.episodes, CheckpointPolicy(self.paths["latest"]),
                           scenes_root=self.config.scenes_dir, workers=self.config.eval_workers)
        summary = summary_record(results)
        run = {"policy": self.paths["latest"], "step": step, "dataset": os.path.abspath(self.config.eval_dataset),
               "env_config": self.config.policy_config().to_dict()}
        os.makedirs(self.paths["heldout"], exist_ok=True)
        write_results(results, os.path.join(self.paths["heldout"], f"step_{step:09d}.jsonl"), run=run, summary=summary)
        n = max(self.acc["n"], 1.0)
        row = {"step": step, "wall_s": wall, "train_episodes": int(self.acc["n"]),
               "train_return": self.acc["return"] / n, "train_success": self.acc["success"] / n,
               "train_spl": self.acc["spl"] / n, "heldout_episodes": len(results),
               "heldout_success": summary["success"], "heldout_spl": summary["spl"],
               "heldout_soft_spl": summary["soft_spl"]}
        score = (row["heldout_success"], row["heldout_spl"])
        if all(score > (r["heldout_success"], r["heldout_spl"]) for r in self.rows):
            metrics = {k: row[k] for k in ("heldout_success", "heldout_spl", "heldout_soft_spl")}
            p = self.ppo
            save_checkpoint(self.paths["best"], p.agent, p.obs_norm, self.config.policy_config(), step,
                            metrics=metrics, actions=self.config.eval_actions)
        self.rows.append(row)
        self.acc = dict.fromkeys(self.acc, 0.0)
        write_curve(self.rows, self.paths["curve"])
        plot_curve(self.rows, self.paths["plot"])
        return row


def _resumable(config: TrainConfig) -> Any:
    """``latest.pt`` of the run in ``config.out``; ValueError unless it was trained with
    the config's env (checked before the engine's pools are built)."""
    path = os.path.join(config.out, OUTPUTS["latest"])
    ckpt = load_checkpoint(path)
    if ckpt.env_config != config.policy_config():
        raise ArgumentError(
            f"--resume: {path!r} was trained with another env config than the config file's env "
            f"(and path_range); resume with the config it was started with"
        )
    return ckpt


def _check_out(config: TrainConfig, resume: bool) -> None:
    """Refuse to overwrite a run, or to resume none."""
    latest = os.path.join(config.out, OUTPUTS["latest"])
    if resume and not os.path.isfile(latest):
        raise ArgumentError(f"--resume: {config.out!r} holds no {OUTPUTS['latest']} to resume from")
    if not resume and os.path.exists(latest):
        raise ArgumentError(
            f"out {config.out!r} already holds a run ({OUTPUTS['latest']}): pass --resume to continue "
            f"it, or choose another out folder"
        )
    if os.path.exists(config.out) and not os.path.isdir(config.out):
        raise ArgumentError(f"out {config.out!r} is not a folder")


def run_training(
    config: TrainConfig,
    resume: bool = False,
    progress: bool = True,
    echo: Callable[[str], None] | None = None,
) -> list[dict[str, Any]]:
    """Train as ``config`` says (see the module notes); the curve's rows.

    Parameters
    ----------
    config : TrainConfig
    resume : bool
        Continue the run in ``config.out`` from its ``latest.pt``.
    progress : bool
        A tqdm bar over the env steps (on stderr).
    echo : callable, optional
        Called with one line per held-out evaluation.

    Raises
    ------
    ValueError
        For a bad config, dataset or output folder (before any training), naming it.
    """
    import torch
    from tqdm import tqdm

    _check_out(config, resume)
    ckpt = _resumable(config) if resume else None
    episodes = heldout_episodes(config)
    torch.set_num_threads(config.engine.torch_threads)
    env = _engine(config, training_scenes(config))
    try:
        os.makedirs(config.out, exist_ok=True)
        run = _Run(config, PPO(env, config.ppo), episodes)
        if ckpt is not None:
            run.resume(ckpt)
        else:
            import yaml

            from pointnav_core.utils.outputs import atomic_writer

            with atomic_writer(run.paths["config"], "w", encoding="utf-8") as fh:
                yaml.safe_dump(config.to_dict(), fh, sort_keys=False)
        _loop(run, env, tqdm(total=config.ppo.total_steps, initial=min(run.ppo.steps, config.ppo.total_steps),
                             disable=not progress, unit="step", desc="train"), echo)
    finally:
        env.close()
    return run.rows


def _loop(run: _Run, env: Any, bar: Any, echo: Callable[[str], None] | None) -> None:
    """Update until the step budget, evaluating every ``eval_every`` steps and at the end."""
    config, ppo = run.config, run.ppo
    every, refresh = config.eval_every, config.engine.refresh_every
    start = time.perf_counter()
    obs = ppo.start(env, seed=config.ppo.seed + ppo.steps)
    evaluated = ppo.steps if run.rows and run.rows[-1]["step"] == ppo.steps else -1
    try:
        while ppo.steps < config.ppo.total_steps:
            before = ppo.steps
            obs, stats = ppo.update(env, obs)
            run.record(stats)
            bar.update(ppo.steps - before)
            n = max(run.acc["n"], 1.0)  # the training episodes since the last evaluation
            bar.set_postfix(train_success=f"{run.acc['success'] / n:.2f}", refresh=False)
            # A refresh still building is left to finish: refresh_pool() would wait for it,
            # and the learner never waits for a pool (the next tick starts the next one).
            if refresh and ppo.steps // refresh > before // refresh and not env.refresh_pending:
                env.refresh_pool()
            if ppo.steps // every > before // every or ppo.steps >= config.ppo.total_steps:
                row = run.evaluate(run.wall0 + time.perf_counter() - start)
                evaluated = ppo.steps
                if echo is not None:
                    echo(f"step {row['step']}: held-out success {row['heldout_success']:.3f}, SPL "
                         f"{row['heldout_spl']:.3f} ({row['heldout_episodes']} episodes); training success "
                         f"{row['train_success']:.3f} ({row['train_episodes']} episodes)")
        if evaluated != ppo.steps:  # resumed at the budget's end without its evaluation
            run.evaluate(run.wall0 + time.perf_counter() - start)
    except KeyboardInterrupt:
        run.save_latest()  # the last finished update, for --resume
        raise
    finally:
        bar.close()
