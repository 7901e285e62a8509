"""The ``pointnav dataset generate`` and ``pointnav eval`` commands.

``pointnav dataset generate --scenes SET --split val --episodes N --out FILE`` writes an
episode dataset (:mod:`pointnav_core.datasets`); the same arguments give the same bytes.

``pointnav eval --dataset FILE --policy oracle|MODULE:CALLABLE|MODEL.zip`` plays every
episode once (:mod:`pointnav_core.evaluation`), prints success, SPL, SoftSPL, the mean
distance to the goal and collisions, and writes per-episode results (JSON lines, or CSV for
a ``.csv`` path) and a PNG of SPL and success against geodesic distance.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable
from typing import Any

__all__ = ["add_commands", "reporting"]


def _dataset_generate(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from pointnav_core.datasets import GeneratorConfig, generate_split, scene_set

    config = GeneratorConfig(
        geodesic_range=(args.min_geodesic, args.max_geodesic),
        robot_radius=args.robot_radius,
        goal_radius=args.goal_radius,
        ratio_threshold=args.ratio_threshold,
        island_radius_limit=args.island_radius,
    )
    scenes = scene_set(args.scenes, seed=args.seed)
    with tqdm(total=args.episodes, disable=args.quiet, desc="episodes", unit="ep") as bar:
        dataset = generate_split(
            scenes, args.split, args.episodes, seed=args.seed, config=config, progress=bar.update
        )
    dataset.save(args.out, frame="habitat" if args.habitat_frame else "z-up")
    print(
        f"wrote {args.out}: {len(dataset)} episodes on {len(dataset.scene_ids)} scenes of {args.scenes!r} ({args.split})"
    )
    return 0


def _default_output(dataset: str, suffix: str) -> str:
    name = os.path.basename(dataset)
    for ext in (".json.gz", ".json"):
        if name.endswith(ext):
            name = name[: -len(ext)]
    return f"{name}.eval{suffix}"


def _eval(args: argparse.Namespace) -> int:
    from pointnav_core.datasets import EpisodeDataset
    from pointnav_core.evaluation import evaluate, plot_results, summarize, write_results

    dataset = EpisodeDataset.load(args.dataset)
    results = evaluate(
        dataset,
        args.policy,
        backend=args.backend,
        workers=args.workers,
        max_steps=args.max_steps,
        drive=args.drive,
        scenes_root=args.scenes_dir,
        sb3_algo=args.sb3_algo,
        progress=not args.quiet,
    )
    summary = summarize(results)
    results_path = args.results or _default_output(args.dataset, ".jsonl")
    plot_path = args.plot or _default_output(args.dataset, ".png")
    write_results(results, results_path)
    plot_results(results, plot_path)
    rows = [
        ("episodes", f"{int(summary['episodes'])}"),
        ("success", f"{summary['success']:.4f}"),
        ("SPL", f"{summary['spl']:.4f}"),
        ("SoftSPL", f"{summary['soft_spl']:.4f}"),
        ("distance to goal", f"{summary['distance_to_goal']:.3f} m (mean, at the end)"),
        ("collisions", f"{summary['collisions']:.3f} per episode"),
        ("path length", f"{summary['path_length']:.2f} m (mean)"),
    ]
    width = max(len(name) for name, _ in rows)
    print(f"{args.policy} on {args.dataset}, {args.backend} backend")
    for name, value in rows:
        print(f"  {name:<{width}}  {value}")
    print(f"wrote {results_path} and {plot_path}")
    return 0


def reporting(
    command: str, func: Callable[[argparse.Namespace], int]
) -> Callable[[argparse.Namespace], int]:
    """Run ``func``; bad input (a ValueError, a missing file, a sampling failure) is printed
    as one line ``pointnav COMMAND: error: ...`` on stderr, with exit status 2."""
    from pointnav_core.errors import SamplingError

    def run(args: argparse.Namespace) -> int:
        try:
            return func(args)
        except (ValueError, FileNotFoundError, SamplingError) as err:
            print(f"pointnav {command}: error: {err}", file=sys.stderr)
            return 2

    return run


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None


def add_commands(sub: Any, positive_int: Callable[[str], int]) -> None:
    """Add ``dataset generate`` and ``eval`` to the ``pointnav`` sub-command parser."""
    dataset = sub.add_parser("dataset", help="episode datasets")
    dsub = dataset.add_subparsers(dest="dataset_command", required=True)
    gen = dsub.add_parser("generate", help="generate an episode dataset with Habitat's rules")
    gen.add_argument(
        "--scenes",
        required=True,
        metavar="SET",
        help="a named set (houses, mazes, clutter) or a folder of scenes",
    )
    gen.add_argument("--split", default="val", help="train, val or test (default val)")
    gen.add_argument("--episodes", type=positive_int, required=True, metavar="N")
    gen.add_argument("--out", required=True, metavar="FILE", help="output .json.gz")
    gen.add_argument("--seed", type=int, default=0)
    gen.add_argument("--min-geodesic", type=_number, default=1.0, metavar="M")
    gen.add_argument("--max-geodesic", type=_number, default=30.0, metavar="M")
    gen.add_argument("--robot-radius", type=_number, default=0.18, metavar="M")
    gen.add_argument("--goal-radius", type=_number, default=0.5, metavar="M")
    gen.add_argument(
        "--ratio-threshold",
        type=_number,
        default=1.1,
        metavar="R",
        help="pairs with geodesic/euclidean below R are kept with probability 20 (ratio - 0.98)^2",
    )
    gen.add_argument(
        "--island-radius",
        type=_number,
        default=1.5,
        metavar="M",
        help="reject starts on smaller islands",
    )
    gen.add_argument("--habitat-frame", action="store_true", help="write Habitat's y-up frame")
    gen.add_argument("--quiet", action="store_true", help="no progress bar")
    gen.set_defaults(func=reporting("dataset generate", _dataset_generate))

    ev = sub.add_parser("eval", help="evaluate a policy on an episode dataset")
    ev.add_argument("--dataset", required=True, metavar="FILE")
    ev.add_argument(
        "--policy", default="oracle", help="oracle, MODULE:CALLABLE or a Stable-Baselines3 .zip"
    )
    ev.add_argument(
        "--sb3-algo", default="PPO", help="algorithm class of an SB3 .zip (default PPO)"
    )
    ev.add_argument("--backend", default="kinematic")
    ev.add_argument("--drive", choices=("differential", "holonomic"), default="differential")
    ev.add_argument("--workers", type=positive_int, default=1, metavar="N")
    ev.add_argument("--max-steps", type=positive_int, default=1000, metavar="N")
    ev.add_argument(
        "--scenes-dir",
        default=None,
        metavar="DIR",
        help="folder relative scene paths are read from",
    )
    ev.add_argument(
        "--results", default=None, metavar="FILE", help="per-episode results (.jsonl, or .csv)"
    )
    ev.add_argument(
        "--plot",
        default=None,
        metavar="FILE",
        help="PNG of SPL and success against geodesic distance",
    )
    ev.add_argument("--quiet", action="store_true", help="no progress bar")
    ev.set_defaults(func=reporting("eval", _eval))
