"""The ``pointnav train`` command: PPO on the batched engine, from a config file.

``pointnav train --config FILE`` trains as the config says
(:mod:`pointnav_core.training.config`: the env config, the scene set and split, the episode
distribution, the held-out dataset, PPO's settings, the output folder) and writes
``latest.pt`` and ``best.pt`` checkpoints, ``curve.csv``, ``curve.png`` and each held-out
evaluation's results (:mod:`pointnav_core.training.trainer`), with a progress bar.
``--resume`` continues the run in the output folder from its ``latest.pt``. Then
``pointnav eval --policy OUT/best.pt --dataset FILE`` plays the policy with nothing else
to say. Bad input is one line on stderr and exit status 2; Ctrl-C saves ``latest.pt`` and
exits with status 130.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any

from pointnav_core.errors import ArgumentError

__all__ = ["add_command"]


def _train(args: argparse.Namespace) -> int:
    try:
        import torch  # noqa: F401
    except ImportError:
        raise ArgumentError("pointnav train needs torch (pip install 'pointnav-core[vector]')") from None
    from tqdm import tqdm

    from pointnav_core.training.config import TrainConfig
    from pointnav_core.training.trainer import OUTPUTS, run_training

    config = TrainConfig.load(args.config)
    echo = None if args.quiet else tqdm.write  # lines above the progress bar
    rows = run_training(config, resume=args.resume, progress=not args.quiet, echo=echo)
    last = rows[-1] if rows else None
    if last is not None:
        print(f"trained {last['step']} steps: held-out success {last['heldout_success']:.3f}, SPL "
              f"{last['heldout_spl']:.3f} ({last['heldout_episodes']} episodes of {config.eval_dataset})")
    print(f"wrote {config.out}/: {', '.join(OUTPUTS[k] for k in ('latest', 'best', 'curve', 'plot'))} and "
          f"{OUTPUTS['heldout']}/ (evaluate with pointnav eval --policy {config.out}/{OUTPUTS['best']} --dataset FILE)")
    return 0


def add_command(sub: Any, reporting: Callable[..., Any]) -> None:
    """Add ``train`` to the ``pointnav`` sub-command parser."""
    train = sub.add_parser("train", help="train a policy with PPO on the batched engine, from a config file")
    train.add_argument("--config", required=True, metavar="FILE",
                       help="the training config (.yaml or .json): env, scenes, split, path_range, eval_dataset, "
                       "out, ppo, engine")
    train.add_argument("--resume", action="store_true", help="continue the run in the config's out folder")
    train.add_argument("--quiet", action="store_true", help="no progress bar or evaluation lines")
    train.set_defaults(func=reporting("train", _train))
