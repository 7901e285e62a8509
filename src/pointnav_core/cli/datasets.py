"""The ``pointnav dataset generate`` and ``pointnav eval`` commands.

``pointnav dataset generate --scenes SET --split val --episodes N --out FILE`` writes an
episode dataset (:mod:`pointnav_core.datasets`); the same arguments give the same bytes.
``--pedestrians '{"count": 5}'`` (the envs' ``pedestrians`` dict as JSON) or
``--pedestrians igibson`` (iGibson's density) records a crowd in every episode.

``pointnav eval --dataset FILE --policy oracle|MODULE:CALLABLE|CHECKPOINT.pt|MODEL.zip`` (a
``.zip`` with ``--trust-policy-file``: loading one runs the code pickled in it; a checkpoint
of ``pointnav train`` plays with the env config it carries) plays every
episode once (:mod:`pointnav_core.evaluation.run`), or every ``--stride``-th and then the first
``--limit`` of those; prints success, SPL and SoftSPL with 95 % bootstrap confidence
intervals, the mean distance to the goal and collisions; and writes per-episode results
(JSON lines between a run record and a summary record, or CSV for a ``.csv`` path with
those records beside it: :mod:`pointnav_core.evaluation.report`) and a PNG of SPL and
success against geodesic distance. The run record names the library version, the
dataset's SHA-256 and every setting that decides the results.

Faults (see :mod:`pointnav_core.evaluation.log`): every output path is checked before the
first episode; each finished episode is on disk (``RESULTS.partial``) as it ends; Ctrl-C or
SIGTERM stops the run at once, keeps what is finished and exits with status 130, and
``--resume`` finishes it. Bad input is one line on stderr and exit status 2; a run that
fails (a policy error with ``--on-error stop``, a full disk) exits with status 1.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
from collections.abc import Callable
from typing import Any

from pointnav_core.errors import ArgumentError
from pointnav_core.evaluation.policy_specs import make_policy, policy_file
from pointnav_core.policies.checkpoint_policy import ACTIONS

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
    from pointnav_core.utils.outputs import check_output

    check_output("--out", args.out)
    pedestrians = _pedestrians(args.pedestrians)
    scenes = scene_set(args.scenes, seed=args.seed)
    with tqdm(total=args.episodes, disable=args.quiet, desc="episodes", unit="ep") as bar:
        dataset = generate_split(
            scenes, args.split, args.episodes, seed=args.seed, config=config, progress=bar.update,
            pedestrians=pedestrians,
        )
    dataset.save(args.out, frame="habitat" if args.habitat_frame else "z-up")
    print(
        f"wrote {args.out}: {len(dataset)} episodes on {len(dataset.scene_ids)} scenes of {args.scenes!r} ({args.split})"
    )
    return 0


#: ``--pedestrians`` presets by name.
PEDESTRIAN_PRESETS = ("igibson",)


def _pedestrians(text: str | None) -> dict[str, Any] | None:
    """``--pedestrians``: a preset name or a JSON object of the envs' ``pedestrians`` keys."""
    import json

    from pointnav_core.crowds import make_pedestrians, presets

    if text is None:
        return None
    if text == "igibson":
        return presets.igibson_density()
    try:
        value = json.loads(text)
    except json.JSONDecodeError:
        value = None
    if not isinstance(value, dict):
        raise ArgumentError(
            f"--pedestrians must be a JSON object of the pedestrians keys (e.g. '{{\"count\": 5}}') "
            f"or one of {list(PEDESTRIAN_PRESETS)}, got {text!r}"
        )
    make_pedestrians(value, "--pedestrians")  # a bad key is named before any scene is built
    return value


def _default_output(dataset: str, suffix: str) -> str:
    name = os.path.basename(dataset)
    for ext in (".json.gz", ".json"):
        name = name.removesuffix(ext)
    return f"{name}.eval{suffix}"


def _count(name: str, text: str | None) -> int | None:
    """``--limit``/``--stride``'s text as an integer >= 1 (None stays None)."""
    if text is None:
        return None
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise ArgumentError(f"{name} must be an integer >= 1, got {text!r}")
    return value


def _sha256(path: str) -> str:
    """The SHA-256 of a file's bytes, as ``sha256sum`` prints it."""
    import hashlib

    with open(path, "rb") as fh:
        return hashlib.file_digest(fh, "sha256").hexdigest()


def _run_settings(args: argparse.Namespace, scenes_dir: str) -> dict[str, Any]:
    """What decides a run's results (recorded in its log and its results file); a policy
    file (a checkpoint, an SB3 ``.zip``) is recorded with its SHA-256 too."""
    from pointnav_core import __version__

    settings = {
        "version": __version__,
        "dataset": os.path.abspath(args.dataset), "dataset_sha256": _sha256(args.dataset),
        "policy": args.policy, "actions": args.actions, "sb3_algo": args.sb3_algo, "backend": args.backend,
        "drive": args.drive, "max_steps": args.max_steps, "scenes_dir": os.path.abspath(scenes_dir),
        "limit": args.limit, "stride": args.stride,
        "env_config": None if args.config is None else args.config.to_dict(),
    }
    if (file := policy_file(args.policy)) is not None:
        settings["policy_sha256"] = _sha256(file)
    return settings


#: ``pointnav eval``'s flags that an env config sets, and their defaults without one.
_CONFIG_FLAGS = {"backend": "kinematic", "drive": "differential", "max_steps": 1000}


def _env_config(args: argparse.Namespace, factory: Any) -> None:
    """Read ``--env-config`` (or else the config a checkpoint ``factory`` carries) into
    ``args.config`` (None without either), and settle ``--backend``, ``--drive`` and
    ``--max-steps``: the config's values, or the defaults without one. One of those flags
    beside a config is refused, naming it."""
    from pointnav_core.envs.config import EnvConfig

    source = "--env-config"
    if args.env_config is not None:
        args.config = EnvConfig.load(args.env_config)
    else:
        args.config = getattr(factory, "env_config", None)
        source = f"the checkpoint {args.policy!r}"
    for name, default in _CONFIG_FLAGS.items():
        if args.config is None:
            value = default if getattr(args, name) is None else getattr(args, name)
        elif getattr(args, name) is not None:
            flag = "--" + name.replace("_", "-")
            raise ArgumentError(
                f"{flag} given beside {source}, whose env config sets it: "
                + ("edit the config file instead" if args.env_config is not None else
                   "pass an edited copy of its config with --env-config")
            )
        else:
            value = args.config.robot.drive if name == "drive" else getattr(args.config, name)
        setattr(args, name, value)


#: The social metrics ``pointnav eval`` prints with pedestrians: key, label, unit.
_SOCIAL_ROWS = (
    ("psc", "PSC", ""),
    ("stl", "STL", ""),
    ("min_ped_distance", "min pedestrian dist.", " m"),
    ("personal_space_time", "in personal space", " s"),
    ("min_ttc", "min time-to-collision", " s"),
    ("path_irregularity", "path irregularity", " rad/m"),
    ("jerk_mean", "mean jerk", " m/s³"),
)


def _print_summary(args: argparse.Namespace, summary: dict[str, Any], of: int) -> None:
    """The summary as the table ``pointnav eval`` prints, with 95 % intervals."""
    ci = summary["intervals"]

    def with_ci(key: str) -> str:
        lo, hi = ci[key]
        return f"{summary[key]:.4f}  [{lo:.4f}, {hi:.4f}]"

    rows = [
        ("episodes", f"{summary['episodes']}" + (f" of {of}" if summary["episodes"] != of else "")),
        ("success", with_ci("success")),
        ("SPL", with_ci("spl")),
        ("SoftSPL", with_ci("soft_spl")),
        ("distance to goal", f"{summary['distance_to_goal']:.3f} m (mean, at the end)"),
        ("collisions", f"{summary['collisions']:.3f} per episode"),
        ("path length", f"{summary['path_length']:.2f} m (mean)"),
    ]
    if "pedestrian_collisions" in summary:  # an env config with pedestrians
        rows.append(("pedestrian contacts", f"{summary['pedestrian_collisions']:.3f} steps per episode"))
        for key, label, unit in _SOCIAL_ROWS:
            if f"social_{key}" in summary:
                rows.append((label, f"{summary[f'social_{key}']:.3f}{unit} (mean where defined)"))
    width = max(len(name) for name, _ in rows)
    subset = (f", --stride {args.stride}" if args.stride > 1 else "") + (
        f", --limit {args.limit}" if args.limit is not None else ""
    )
    print(f"{args.policy} on {args.dataset}, {args.backend} backend{subset}")
    for name, value in rows:
        print(f"  {name:<{width}}  {value}")
    print(
        f"  [lo, hi]: {ci['confidence']:.0%} confidence interval "
        f"({ci['method']}, {ci['resamples']} resamples, seed {ci['seed']})"
    )


def _eval(args: argparse.Namespace) -> int:
    from pointnav_core.datasets import EpisodeDataset
    from pointnav_core.errors import PointNavError
    from pointnav_core.evaluation.config import check_robot_radius
    from pointnav_core.evaluation.log import ResultsLog
    from pointnav_core.evaluation.report import plot_results, summary_path
    from pointnav_core.evaluation.run import check_scene_ids, evaluate, select_episodes
    from pointnav_core.utils.outputs import check_output

    if os.getcwd() not in sys.path:  # MODULE:CALLABLE from here, as `python -m` would find it
        sys.path.insert(0, os.getcwd())
    args.limit, args.stride = _count("--limit", args.limit), _count("--stride", args.stride)
    factory = make_policy(args.policy, args.sb3_algo, args.trust_policy_file, args.actions)
    _env_config(args, factory)
    inputs = [args.dataset] + ([file] if (file := policy_file(args.policy)) is not None else [])
    inputs += [args.env_config] if args.env_config is not None else []
    results_path = check_output("--results", args.results or _default_output(args.dataset, ".jsonl"), inputs)
    plot_path = check_output("--plot", args.plot or _default_output(args.dataset, ".png"), [*inputs, results_path])
    if results_path.endswith(".csv"):
        check_output("--results (its summary)", summary_path(results_path), [*inputs, plot_path])
    scenes_dir = args.scenes_dir if args.scenes_dir is not None else "."
    if not os.path.isdir(scenes_dir):
        raise ArgumentError(f"--scenes-dir {scenes_dir!r} is not a folder")
    dataset = EpisodeDataset.load(args.dataset)
    episodes = select_episodes(dataset, args.limit, args.stride)
    check_scene_ids(episodes, scenes_dir)
    if args.config is not None:
        check_robot_radius(args.config, episodes)
    log = ResultsLog(results_path, _run_settings(args, scenes_dir))
    check_output("--results (its log)", log.path, inputs)
    done = log.start(args.resume, episodes)
    failed: list[str] = []
    # With an env config, evaluate takes these from it (args holds the config's values).
    settings = {} if args.config is not None else {k: getattr(args, k) for k in _CONFIG_FLAGS}
    try:
        evaluate(
            [ep for ep in episodes if ep.episode_id not in done],
            args.policy if args.actions is None else factory,  # the factory carries --actions
            **settings,
            workers=args.workers,
            scenes_root=scenes_dir,
            env_config=args.config,
            sb3_algo=args.sb3_algo,
            progress=not args.quiet,
            trust_policy_file=args.trust_policy_file,
            on_error=args.on_error,
            on_result=_Signals.result(log.append),
            on_failure=_Signals.failure(failed),
            isolate=True,
        )
        results, summary = log.finish(episodes)
    except (KeyboardInterrupt, PointNavError, ValueError) as err:
        log.close()
        kept = f"{len(log.done)} of {len(episodes)} episodes finished, kept in {log.path}; rerun with --resume to finish"
        if isinstance(err, KeyboardInterrupt) or _Signals.arrived:
            print(f"pointnav eval: {_Signals.name}: {kept}", file=sys.stderr)
            return 130
        if isinstance(err, ValueError):
            raise
        print(f"pointnav eval: error: {err}; {kept}", file=sys.stderr)
        return 1
    for message in failed:
        print(f"pointnav eval: skipped: {message}", file=sys.stderr)
    if summary is None:
        print("pointnav eval: error: no episode finished", file=sys.stderr)
        return 1
    plot_results(results, plot_path)
    _print_summary(args, summary, len(dataset))
    written = [results_path, plot_path]
    if results_path.endswith(".csv"):
        written.insert(1, summary_path(results_path))
    print(f"wrote {', '.join(written[:-1])} and {written[-1]}")
    return 1 if failed else 0


class _Signals:
    """SIGTERM raises KeyboardInterrupt as Ctrl-C does; ``name`` says which arrived.

    ``arrived`` stays set once one has: a KeyboardInterrupt raised inside an import comes
    out as an ImportError, or as an episode's error, and must still end the run as an
    interruption. Only the first signal raises: a second Ctrl-C while the run is being
    wound up (workers ended, the log closed) must not cut that short.
    """

    name = "interrupted"
    arrived = False

    @classmethod
    def handler(cls, signum: int, _frame: Any) -> None:
        if cls.arrived:
            return
        cls.name, cls.arrived = f"interrupted by {signal.Signals(signum).name}", True
        raise KeyboardInterrupt

    @classmethod
    def install(cls) -> list[Any]:
        cls.name, cls.arrived = "interrupted", False
        return [signal.signal(s, cls.handler) for s in (signal.SIGINT, signal.SIGTERM)]

    @classmethod
    def result(cls, keep: Callable[[Any], None]) -> Callable[[Any], None]:
        """An ``on_result`` that keeps each result, then stops the run if a signal came
        whose KeyboardInterrupt something swallowed (a ``__del__`` prints and drops one)."""

        def note(result: Any) -> None:
            keep(result)
            if cls.arrived:
                raise KeyboardInterrupt

        return note

    @classmethod
    def failure(cls, failed: list[str]) -> Callable[[Any, str], None]:
        """An ``on_failure`` that keeps each message, or stops the run once a signal came."""

        def note(_episode: Any, message: str) -> None:
            if cls.arrived:
                raise KeyboardInterrupt
            failed.append(message)

        return note


def reporting(
    command: str, func: Callable[[argparse.Namespace], int]
) -> Callable[[argparse.Namespace], int]:
    """Run ``func``; bad input (a ValueError, a file that cannot be read or written, a
    sampling failure, any of the library's errors) is printed as one line
    ``pointnav COMMAND: error: ...`` on stderr, with exit status 2. Ctrl-C and SIGTERM end
    it with one line and exit status 130."""
    from pointnav_core.errors import PointNavError

    def run(args: argparse.Namespace) -> int:
        previous = _Signals.install()
        try:
            return func(args)
        except KeyboardInterrupt:
            print(f"pointnav {command}: {_Signals.name}", file=sys.stderr)
            return 130
        except (ValueError, OSError, PointNavError) as err:
            if _Signals.arrived:  # an interruption that surfaced as another error
                print(f"pointnav {command}: {_Signals.name}", file=sys.stderr)
                return 130
            print(f"pointnav {command}: error: {err}", file=sys.stderr)
            return 2
        finally:
            for signum, old in zip((signal.SIGINT, signal.SIGTERM), previous):
                signal.signal(signum, old)

    return run


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None


def add_commands(sub: Any, positive_int: Callable[[str], int]) -> None:
    """Add ``dataset generate`` and ``eval`` to the ``pointnav`` sub-command parser."""
    _add_generate(sub, positive_int)
    _add_eval(sub, positive_int)


def _add_generate(sub: Any, positive_int: Callable[[str], int]) -> None:
    """Add ``dataset generate``."""
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
    gen.add_argument(
        "--pedestrians",
        default=None,
        metavar="JSON_OR_PRESET",
        help="record a crowd in every episode: a pedestrians dict as JSON ('{\"count\": 5}') or igibson",
    )
    gen.add_argument("--habitat-frame", action="store_true", help="write Habitat's y-up frame")
    gen.add_argument("--quiet", action="store_true", help="no progress bar")
    gen.set_defaults(func=reporting("dataset generate", _dataset_generate))


def _add_eval(sub: Any, positive_int: Callable[[str], int]) -> None:
    """Add ``eval``."""
    ev = sub.add_parser("eval", help="evaluate a policy on an episode dataset")
    ev.add_argument("--dataset", required=True, metavar="FILE")
    ev.add_argument(
        "--policy", default="oracle",
        help="oracle, MODULE:CALLABLE, a checkpoint .pt of pointnav train (played with its own env config), "
        "baseline:scan-ppo (the shipped one) or a Stable-Baselines3 .zip"
    )
    ev.add_argument(
        "--sb3-algo", default="PPO", help="algorithm class of an SB3 .zip (default PPO)"
    )
    ev.add_argument(
        "--actions", choices=ACTIONS, default=None,
        help="how a checkpoint .pt acts: its most likely action, or one drawn from its distribution with a "
        "generator seeded by the episode (default: the checkpoint's own, set by pointnav train's eval_actions)",
    )
    ev.add_argument(
        "--env-config",
        default=None,
        metavar="FILE",
        help="the env config (.yaml or .json) the policy was trained with: sensors, actions, robot, "
        "backend, task settings, max steps (default: a checkpoint's own)",
    )
    ev.add_argument("--backend", default=None, help="default kinematic (or the env config's)")
    ev.add_argument("--drive", choices=("differential", "holonomic"), default=None, help="default differential")
    ev.add_argument("--workers", type=positive_int, default=1, metavar="N")
    ev.add_argument("--max-steps", type=positive_int, default=None, metavar="N", help="default 1000")
    ev.add_argument(
        "--limit", default=None, metavar="N", help="play only the first N episodes (after --stride)"
    )
    ev.add_argument(
        "--stride", default="1", metavar="K", help="play every K-th episode, from the first (default 1)"
    )
    ev.add_argument(
        "--scenes-dir",
        default=None,
        metavar="DIR",
        help="folder the dataset's scene paths are read from, and must stay in (default: the current folder)",
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
    ev.add_argument(
        "--resume",
        action="store_true",
        help="finish an interrupted run: play only the episodes missing from RESULTS.partial",
    )
    ev.add_argument(
        "--on-error",
        choices=("stop", "skip"),
        default="stop",
        help="when the policy raises in an episode: stop the run (default), or leave the episode out and go on",
    )
    ev.add_argument(
        "--trust-policy-file",
        action="store_true",
        help="allow an SB3 .zip policy: loading one runs the Python code pickled in it",
    )
    ev.set_defaults(func=reporting("eval", _eval))
