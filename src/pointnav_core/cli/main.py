"""The ``pointnav`` command line.

``pointnav demo`` is the main job: it builds a generated house, drives the oracle
(:class:`~pointnav_core.policies.oracle.ShortestPathFollower`) to sampled goals on the default
kinematic backend, and prints success, SPL, SoftSPL, path length, collisions and speed.

``pointnav demo --scene FILE`` drives on a scene file instead: a ROS map ``.yaml``, a ProcTHOR
or HouseExpo ``.json``, a MovingAI ``.map`` or a traversability PNG (any ``scene_id``).
``pointnav dataset generate`` and ``pointnav eval`` are in :mod:`pointnav_core.cli.datasets`,
``pointnav train`` in :mod:`pointnav_core.cli.train`.

``--gif FILE`` writes the first episode as an animated GIF and ``--png FILE`` its last frame
(top-down, :func:`pointnav_core.render.recording.render_env`). When either is given, the demo's tasks
show their markers (``visualize_goal`` and ``visualize_path``): the start in red, the goal in
blue and the shortest path ahead as green waypoints. ``--every N`` keeps one frame in N in
the GIF (which then still plays in real time).
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Sequence

import numpy as np
from tqdm import tqdm

from pointnav_core import scenes
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.errors import ArgumentError
from pointnav_core.policies.oracle import ShortestPathFollower

__all__ = ["main", "run_demo"]


def run_demo(
    episodes: int = 20,
    seed: int = 0,
    houses: int = 4,
    max_steps: int = 1000,
    backend: str = "kinematic",
    drive: str = "differential",
    progress: bool = True,
    frames: list | None = None,
    every: int = 1,
    pixels_per_meter: float | None = None,
    scene: str | None = None,
) -> dict[str, float]:
    """Run the oracle for ``episodes`` episodes spread over ``houses`` generated houses.

    Parameters
    ----------
    episodes : int
        Number of episodes (>= 1).
    seed : int
        Seeds the houses and the episodes.
    houses : int
        Number of distinct ``rooms`` houses the episodes cycle through.
    max_steps : int
        Step limit per episode. A 20 x 15 m house has geodesics up to about 30 m, more than
        OmniGibson's default 500 steps at 0.5 m/s can drive, hence 1000.
    backend : str
        Registered backend name.
    drive : str
        ``"differential"`` or ``"holonomic"``.
    progress : bool
        Show a progress bar.
    frames : list, optional
        If given, the rendered frames of the first episode are appended to it, and the
        tasks show their start, goal and path markers.
    every : int
        With ``frames``: keep the frame after reset, every ``every``-th step's frame, and
        the last one.
    pixels_per_meter : float, optional
        With ``frames``: the picture scale (default 20 px/m, see
        :func:`pointnav_core.render.recording.render_env`).
    scene : str, optional
        A scene file instead of generated houses: a ROS map ``.yaml``, a ProcTHOR or
        HouseExpo ``.json``, a MovingAI ``.map``, an OmniGibson ``floor_trav_<n>.png`` or a
        folder of them (any ``scene_id``, see
        :func:`pointnav_core.datasets.load_scene`); ``houses`` is then ignored.

    Returns
    -------
    dict
        ``episodes``, ``success``, ``spl``, ``soft_spl``, ``path_length`` (m, mean),
        ``collisions`` (mean per episode), ``steps``, ``steps_per_second``.
    """
    if episodes < 1:
        raise ArgumentError(f"episodes must be >= 1, got {episodes}")
    if houses < 1:
        raise ArgumentError(f"houses must be >= 1, got {houses}")
    if every < 1:
        raise ArgumentError(f"every must be >= 1, got {every}")
    envs = _demo_envs(seed, houses, max_steps, backend, drive, frames, pixels_per_meter, scene)
    houses = len(envs)
    results: dict[str, list[float]] = {k: [] for k in ("success", "spl", "soft_spl", "path_length", "collisions")}
    steps = 0
    elapsed = 0.0
    for episode in tqdm(range(episodes), disable=not progress, desc="episodes", unit="ep"):
        env = envs[episode % houses]
        _, info = env.reset(seed=seed * 100_003 + episode)
        info, episode_steps, seconds = _play_oracle(env, frames if episode == 0 else None, every)
        steps += episode_steps
        elapsed += seconds
        for key in results:
            results[key].append(float(info[key]))
    for env in envs:
        env.close()
    summary = {key: float(np.mean(values)) for key, values in results.items()}
    summary.update(episodes=float(episodes), steps=float(steps), steps_per_second=steps / elapsed)
    return summary


def _demo_envs(
    seed: int,
    houses: int,
    max_steps: int,
    backend: str,
    drive: str,
    frames: list | None,
    pixels_per_meter: float | None,
    scene: str | None,
) -> list[PointNavEnv]:
    """One env per house of :func:`run_demo` (one for a ``scene`` file), rendering when
    ``frames`` is given."""
    task: dict = {"termination_config": {"max_steps": max_steps}}
    if frames is not None:
        task.update(visualize_goal=True, visualize_path=True)
    if scene is not None:
        from pointnav_core.datasets import load_scene

        houses, loaded = 1, [load_scene(scene)]
    else:
        loaded = [scenes.rooms(seed=seed + h) for h in range(houses)]
    envs = [
        PointNavEnv(
            scene=loaded[h],
            robot={"drive": drive},
            task=task,
            backend=backend,
            render_mode="rgb_array" if frames is not None else None,
        )
        for h in range(houses)
    ]
    if pixels_per_meter is not None:
        for env in envs:
            env.render_pixels_per_meter = pixels_per_meter  # read by render_env
    return envs


def _play_oracle(env: PointNavEnv, frames: list | None, every: int) -> tuple[dict, int, float]:
    """Play the just-reset ``env``'s episode with the oracle.

    Returns the last ``info``, the step count and the seconds spent stepping (oracle and
    first frame not counted). With ``frames``, its frames are appended: after reset, every
    ``every``-th step, and the last.
    """
    oracle = ShortestPathFollower(env)
    if frames is not None:
        frames.append(env.render())
    done = False
    episode_steps = 0
    info: dict = {}
    start = time.perf_counter()
    while not done:
        _, _, terminated, truncated, info = env.step(oracle.act())
        episode_steps += 1
        done = terminated or truncated
        if frames is not None and (done or episode_steps % every == 0):
            frames.append(env.render())
    return info, episode_steps, time.perf_counter() - start


def _demo(args: argparse.Namespace) -> int:
    from pointnav_core.utils.outputs import check_output

    for name, path in (("--gif", args.gif), ("--png", args.png)):
        if path:  # before any episode is played
            check_output(name, path, [args.scene] if args.scene else [])
    frames: list | None = [] if (args.gif or args.png) else None
    summary = run_demo(
        episodes=args.episodes,
        seed=args.seed,
        houses=args.houses,
        max_steps=args.max_steps,
        backend=args.backend,
        drive=args.drive,
        progress=not args.quiet,
        frames=frames,
        every=args.every,
        pixels_per_meter=args.pixels_per_meter,
        scene=args.scene,
    )
    rows = [
        ("episodes", f"{int(summary['episodes'])}"),
        ("success rate", f"{summary['success']:.3f}"),
        ("mean SPL", f"{summary['spl']:.3f}"),
        ("mean SoftSPL", f"{summary['soft_spl']:.3f}"),
        ("mean path length", f"{summary['path_length']:.2f} m"),
        ("collisions / episode", f"{summary['collisions']:.2f}"),
        ("env steps / second", f"{summary['steps_per_second']:.0f} (oracle included)"),
    ]
    width = max(len(name) for name, _ in rows)
    where = args.scene if args.scene else f"{args.houses} generated houses"
    print(f"oracle on {where}, {args.backend} backend, {args.drive} drive")
    for name, value in rows:
        print(f"  {name:<{width}}  {value}")
    if frames:
        from pointnav_core.render.recording import save_gif, save_png

        if args.gif:
            save_gif(frames, args.gif, fps=PointNavEnv.metadata["render_fps"] / args.every)
            print(f"wrote {args.gif} ({len(frames)} frames)")
        if args.png:
            save_png(frames[-1], args.png)
            print(f"wrote {args.png}")
    return 0


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be an integer >= 1, got {text!r}")
    return value


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``pointnav`` console script."""
    parser = argparse.ArgumentParser(prog="pointnav", description="pointnav-core command line")
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="drive the oracle to goals in generated houses")
    demo.add_argument("--episodes", type=_positive_int, default=20, metavar="N")
    demo.add_argument("--houses", type=_positive_int, default=4, metavar="N")
    demo.add_argument("--seed", type=int, default=0)
    demo.add_argument("--max-steps", type=_positive_int, default=1000, metavar="N")
    demo.add_argument("--backend", default="kinematic")
    demo.add_argument("--drive", choices=("differential", "holonomic"), default="differential")
    demo.add_argument(
        "--gif", help="write the first episode as an animated GIF (with start, goal and path markers)"
    )
    demo.add_argument("--png", help="write the first episode's last frame as a PNG (with markers)")
    demo.add_argument(
        "--every", type=_positive_int, default=1, metavar="N", help="keep one GIF frame in N (default 1)"
    )
    demo.add_argument(
        "--pixels-per-meter", type=float, default=None, metavar="PPM",
        help="picture scale of --gif/--png (default 20: a 20 m house is 400 px wide)",
    )
    demo.add_argument(
        "--scene", metavar="FILE",
        help="a scene file instead of generated houses: a ROS map .yaml, a ProcTHOR or HouseExpo .json, "
        "a MovingAI .map, an OmniGibson floor_trav_<n>.png or a folder of them",
    )
    demo.add_argument("--quiet", action="store_true", help="no progress bar")
    from pointnav_core.cli import datasets as cli_datasets
    from pointnav_core.cli import scenes as cli_scenes
    from pointnav_core.cli import train as cli_train

    demo.set_defaults(func=cli_datasets.reporting("demo", _demo))

    cli_datasets.add_commands(sub, _positive_int)
    cli_train.add_command(sub, cli_datasets.reporting)
    cli_scenes.add_commands(sub, _positive_int, cli_datasets.reporting)
    args = parser.parse_args(argv)
    return int(args.func(args))

