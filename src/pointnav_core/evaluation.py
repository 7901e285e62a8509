"""Evaluate a policy on an episode dataset: per-episode results, summary, and a plot.

Every episode is played in its own fresh start: the env is reset with the episode's own
seed (:func:`~pointnav_core.datasets.playback.episode_seed`, from its scene and episode ids)
and the policy is built anew for it, so an episode's result is the same whatever the order
of the episodes or the number of worker processes.

Each episode is played by a robot of the radius it was made for (``info.robot_radius``),
with the goal tolerance it records (``goals[0].radius``; the task's 0.5 m when None), on
the floor it records, for at most ``max_steps`` steps.

Policies (``policy`` argument, or ``pointnav eval --policy``):

- ``"oracle"``: :class:`~pointnav_core.policies.ShortestPathFollower`;
- ``"MODULE:CALLABLE"``: ``CALLABLE(env)`` is called after each reset and returns a
  function ``observation -> action``;
- a path to a Stable-Baselines3 ``.zip``: the model (``sb3_algo``, PPO by default) acts
  deterministically; it gets the flat observation when its observation space is a ``Box``.

This module drives the envs, so it is not part of the core; the CLI uses it.
"""

from __future__ import annotations

import csv
import importlib
import json
import math
import os
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass, fields
from multiprocessing import get_context
from typing import Any

import numpy as np

from pointnav_core import metrics
from pointnav_core.datasets.format import EpisodeDataset, PointNavEpisode
from pointnav_core.datasets.playback import episode_seed
from pointnav_core.datasets.scene_sets import load_scene

__all__ = [
    "EpisodeResult",
    "evaluate",
    "make_policy",
    "plot_results",
    "summarize",
    "write_results",
]

#: Default step limit: a 30 m geodesic at 0.5 m/s and 10 Hz takes 600 steps, plus turns.
DEFAULT_MAX_STEPS = 1000
#: Episodes handed to a worker process at once (all of one scene, so it builds few envs).
_CHUNK = 8

Policy = Callable[[Any], Any]
PolicyFactory = Callable[[Any], Policy]


@dataclass(frozen=True)
class EpisodeResult:
    """What happened in one episode.

    Attributes
    ----------
    episode_id, scene_id : str
    floor : int
    geodesic_distance : float
        Recorded in the dataset (m).
    success : bool
    spl, soft_spl : float
    distance_to_goal : float
        Geodesic distance (m) from where the robot ended to the goal.
    path_length : float
        Distance driven (m).
    collisions : int
        Steps in which the robot touched something.
    steps : int
    ended_by : str
        The termination conditions that ended the episode, joined by ``+``.
    """

    episode_id: str
    scene_id: str
    floor: int
    geodesic_distance: float
    success: bool
    spl: float
    soft_spl: float
    distance_to_goal: float
    path_length: float
    collisions: int
    steps: int
    ended_by: str


# ---------------------------------------------------------------------- policies
def _oracle(env: Any) -> Policy:
    from pointnav_core.policies import ShortestPathFollower

    follower = ShortestPathFollower(env)
    return lambda _obs: follower.act()


class _SB3Policy:
    """A picklable factory for a Stable-Baselines3 model, loaded once per process."""

    def __init__(self, path: str, algo: str) -> None:
        self.path, self.algo = path, algo
        self._model: Any = None

    def __getstate__(self) -> dict[str, Any]:
        return {"path": self.path, "algo": self.algo, "_model": None}

    @property
    def model(self) -> Any:
        if self._model is None:
            try:
                import stable_baselines3
            except ImportError:
                raise ValueError(
                    "an SB3 .zip policy needs stable-baselines3 (pip install 'pointnav-core[rl]')"
                ) from None
            cls = getattr(stable_baselines3, self.algo, None)
            if cls is None:
                raise ValueError(
                    f"sb3_algo must name a Stable-Baselines3 algorithm (PPO, SAC, ...), got {self.algo!r}"
                )
            self._model = cls.load(self.path, device="cpu")
        return self._model

    @property
    def flat(self) -> bool:
        from gymnasium import spaces

        return isinstance(self.model.observation_space, spaces.Box)

    def __call__(self, env: Any) -> Policy:
        model = self.model
        return lambda obs: model.predict(obs, deterministic=True)[0]


def make_policy(spec: str, sb3_algo: str = "PPO") -> PolicyFactory:
    """The policy factory named by ``spec`` (see the module notes).

    Raises
    ------
    ValueError
        For a spec of no known form, a module or attribute that does not exist, or a
        ``.zip`` that does not exist.
    """
    if not isinstance(spec, str) or not spec:
        raise ValueError(
            f"policy must be 'oracle', MODULE:CALLABLE or a path to an SB3 .zip, got {spec!r}"
        )
    if spec == "oracle":
        return _oracle
    if spec.endswith(".zip"):
        if not os.path.isfile(spec):
            raise ValueError(f"policy {spec!r}: no such SB3 .zip file")
        return _SB3Policy(spec, sb3_algo)
    module_name, sep, attr = spec.partition(":")
    if not sep or not module_name or not attr:
        raise ValueError(
            f"policy must be 'oracle', MODULE:CALLABLE or a path to an SB3 .zip, got {spec!r}"
        )
    try:
        target: Any = importlib.import_module(module_name)
    except ImportError as err:
        raise ValueError(f"policy {spec!r}: cannot import module {module_name!r} ({err})") from None
    for part in attr.split("."):
        if not hasattr(target, part):
            raise ValueError(f"policy {spec!r}: module {module_name!r} has no attribute {attr!r}")
        target = getattr(target, part)
    if not callable(target):
        raise ValueError(f"policy {spec!r}: {attr!r} is not callable")
    return target


# ---------------------------------------------------------------------- playing
class _Runner:
    """Plays episodes in one process, keeping one env per (scene, floor, robot, tolerance)."""

    def __init__(
        self,
        policy: str | PolicyFactory,
        backend: str,
        max_steps: int,
        drive: str,
        scenes_root: str | None,
        sb3_algo: str,
    ) -> None:
        self.factory = make_policy(policy, sb3_algo) if isinstance(policy, str) else policy
        self.backend, self.max_steps, self.drive = backend, max_steps, drive
        self.scenes_root, self.envs = scenes_root, {}

    def env_for(self, ep: PointNavEpisode) -> Any:
        from pointnav_core.env import PointNavEnv

        key = (ep.scene_id, ep.floor, ep.robot_radius, ep.goal_radius)
        if key not in self.envs:
            if len(self.envs) >= 4:  # a worker moves on from scene to scene
                self.envs.pop(next(iter(self.envs))).close()
            try:
                scene = load_scene(ep.scene_id, self.scenes_root)
            except (ValueError, FileNotFoundError) as err:
                raise ValueError(f"episode {ep.episode_id!r}: field 'scene_id': {err}") from None
            if ep.floor >= scene.n_floors:
                raise ValueError(
                    f"episode {ep.episode_id!r}: field 'info.floor' is {ep.floor}, but scene "
                    f"{ep.scene_id!r} has {scene.n_floors} floor(s)"
                )
            task: dict[str, Any] = {
                "floor": ep.floor,
                "termination_config": {"max_steps": self.max_steps},
            }
            if ep.goal_radius is not None:
                task["goal_tolerance"] = ep.goal_radius
            flat = bool(getattr(self.factory, "flat", False))
            self.envs[key] = PointNavEnv(
                scene=scene,
                robot={"radius": ep.robot_radius, "drive": self.drive},
                task=task,
                backend=self.backend,
                flatten_obs=flat,
            )
        return self.envs[key]

    def play(self, ep: PointNavEpisode) -> EpisodeResult:
        env = self.env_for(ep)
        obs, info = env.reset(seed=episode_seed(ep), options={"episode": ep})
        policy = self.factory(env)
        done = False
        while not done:
            obs, _, terminated, truncated, info = env.step(policy(obs))
            done = terminated or truncated
        ended = "+".join(name for name, r in info["termination_conditions"].items() if r["done"])
        # The step infos read distances from the goal field's lookup table, whose cells settle
        # as queries arrive, so a value can depend on what this worker played before (within
        # the table's accuracy). The results use the exact distance at the end, which does not.
        final = env.task.get_current_pos(env)
        distance = env.scene.geodesic_distance(ep.floor, final, env.task.get_goal_pos(), robot=ep.robot_radius)
        d0, length = float(info["geodesic_dist"]), float(info["path_length"])
        return EpisodeResult(
            episode_id=ep.episode_id,
            scene_id=ep.scene_id,
            floor=ep.floor,
            geodesic_distance=ep.geodesic_distance,
            success=bool(info["success"]),
            spl=float(info["spl"]),
            soft_spl=metrics.soft_spl(distance, d0, length),
            distance_to_goal=float(distance),
            path_length=float(info["path_length"]),
            collisions=int(info["collisions"]),
            steps=int(info["episode_length"]),
            ended_by=ended,
        )


_WORKER: _Runner | None = None


def _init_worker(*args: Any) -> None:
    global _WORKER
    _WORKER = _Runner(*args)


def _play_chunk(indexed: list[tuple[int, PointNavEpisode]]) -> list[tuple[int, EpisodeResult]]:
    assert _WORKER is not None
    return [(i, _WORKER.play(ep)) for i, ep in indexed]


def evaluate(
    episodes: EpisodeDataset | Sequence[PointNavEpisode],
    policy: str | PolicyFactory = "oracle",
    *,
    backend: str = "kinematic",
    workers: int = 1,
    max_steps: int = DEFAULT_MAX_STEPS,
    drive: str = "differential",
    scenes_root: str | None = None,
    sb3_algo: str = "PPO",
    progress: bool = False,
) -> list[EpisodeResult]:
    """Play every episode once; results in the episodes' order.

    Parameters
    ----------
    episodes : EpisodeDataset or sequence of PointNavEpisode
    policy : str or callable
        ``"oracle"``, ``"MODULE:CALLABLE"``, a path to an SB3 ``.zip``, or a factory
        ``env -> (observation -> action)`` (with ``workers > 1`` it must be picklable).
    backend : str
        Registered backend name.
    workers : int
        Worker processes (1: play here).
    max_steps : int
        Step limit per episode.
    drive : str
        ``"differential"`` or ``"holonomic"``.
    scenes_root : str, optional
        Folder relative scene paths in ``scene_id`` are read from.
    sb3_algo : str
        Stable-Baselines3 algorithm class of a ``.zip`` policy.
    progress : bool
        Show a progress bar.

    Raises
    ------
    ValueError
        For a bad argument, or an episode that does not suit its scene or robot (naming the
        episode and the field).
    """
    episodes = list(episodes)
    for name, value in (("workers", workers), ("max_steps", max_steps)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
    args = (policy, backend, max_steps, drive, scenes_root, sb3_algo)
    from tqdm import tqdm

    bar = tqdm(total=len(episodes), disable=not progress, desc="episodes", unit="ep")
    results: list[EpisodeResult | None] = [None] * len(episodes)
    try:
        if workers == 1:
            runner = _Runner(*args)
            for i, ep in enumerate(episodes):
                results[i] = runner.play(ep)
                bar.update(1)
        else:
            # Chunks of one scene each, so that a worker builds few envs.
            by_scene: dict[str, list[tuple[int, PointNavEpisode]]] = {}
            for i, ep in enumerate(episodes):
                by_scene.setdefault(ep.scene_id, []).append((i, ep))
            chunks = [
                group[k : k + _CHUNK]
                for group in by_scene.values()
                for k in range(0, len(group), _CHUNK)
            ]
            with ProcessPoolExecutor(
                workers, mp_context=get_context("spawn"), initializer=_init_worker, initargs=args
            ) as pool:
                futures = [pool.submit(_play_chunk, chunk) for chunk in chunks]
                for future in as_completed(futures):
                    for i, result in future.result():
                        results[i] = result
                        bar.update(1)
    finally:
        bar.close()
    return results  # type: ignore[return-value]


# ---------------------------------------------------------------------- reporting
def summarize(results: Sequence[EpisodeResult]) -> dict[str, float]:
    """Means over episodes: ``success``, ``spl``, ``soft_spl``, ``distance_to_goal`` (m),
    ``path_length`` (m), ``collisions`` (per episode), ``steps``; and ``episodes``."""
    if not results:
        raise ValueError("no results to summarize")
    keys = ("success", "spl", "soft_spl", "distance_to_goal", "path_length", "collisions", "steps")
    summary = {k: float(np.mean([float(getattr(r, k)) for r in results])) for k in keys}
    summary["episodes"] = float(len(results))
    return summary


def write_results(results: Iterable[EpisodeResult], path: str | os.PathLike[str]) -> None:
    """Write one row per episode: CSV for a ``.csv`` path, else JSON lines."""
    results = list(results)
    names = [f.name for f in fields(EpisodeResult)]
    with open(path, "w", newline="", encoding="utf-8") as fh:
        if os.fspath(path).endswith(".csv"):
            writer = csv.DictWriter(fh, fieldnames=names, lineterminator="\n")
            writer.writeheader()
            for r in results:
                writer.writerow(
                    {k: repr(v) if isinstance(v, float) else v for k, v in asdict(r).items()}
                )
        else:
            for r in results:
                fh.write(json.dumps(asdict(r), sort_keys=False, allow_nan=True) + "\n")


def read_results(path: str | os.PathLike[str]) -> list[EpisodeResult]:
    """Read results written by :func:`write_results` as JSON lines."""
    with open(path, encoding="utf-8") as fh:
        return [EpisodeResult(**json.loads(line)) for line in fh if line.strip()]


def plot_results(
    results: Sequence[EpisodeResult], path: str | os.PathLike[str], bin_width: float = 2.0
) -> None:
    """Draw SPL and success rate against geodesic distance as a PNG (Pillow).

    Each episode is a faint dot at its SPL; the lines join the means over bins of
    ``bin_width`` metres of geodesic distance (success green, SPL blue, SoftSPL orange).
    """
    from PIL import Image, ImageDraw

    if not results:
        raise ValueError("no results to plot")
    width, height, left, right, top, bottom = 720, 420, 60, 20, 40, 50
    geo = np.array([r.geodesic_distance for r in results])
    spl = np.array([r.spl for r in results])
    success = np.array([float(r.success) for r in results])
    x_max = max(bin_width, math.ceil(geo.max() / bin_width) * bin_width)
    image = Image.new("RGB", (width, height), "white")
    draw = ImageDraw.Draw(image)
    pw, ph = width - left - right, height - top - bottom

    def px(x: float, y: float) -> tuple[float, float]:
        return left + pw * x / x_max, top + ph * (1.0 - y)

    for k in range(11):  # grid and y ticks
        y = k / 10
        draw.line([px(0, y), px(x_max, y)], fill=(230, 230, 230))
        draw.text((left - 30, px(0, y)[1] - 6), f"{y:.1f}", fill="black")
    step = bin_width * max(1, round(x_max / bin_width / 10))
    x = 0.0
    while x <= x_max + 1e-9:
        draw.line([px(x, 0), (px(x, 0)[0], px(x, 0)[1] + 4)], fill="black")
        draw.text((px(x, 0)[0] - 8, px(x, 0)[1] + 8), f"{x:g}", fill="black")
        x += step
    draw.rectangle([px(0, 1), px(x_max, 0)], outline="black")
    for g, s in zip(geo, spl):
        cx, cy = px(g, s)
        draw.ellipse([cx - 1.5, cy - 1.5, cx + 1.5, cy + 1.5], fill=(170, 190, 235))
    edges = np.arange(0.0, x_max + bin_width / 2, bin_width)
    soft = np.array([r.soft_spl for r in results])
    # Success under the others, wider, so that equal curves stay visible.
    for values, colour, line in (
        (success, (20, 150, 60), 5),
        (soft, (230, 140, 20), 2),
        (spl, (30, 70, 200), 2),
    ):
        points = []
        for lo, hi in zip(edges[:-1], edges[1:]):
            sel = (geo >= lo) & (geo < hi)
            if sel.any():
                points.append(px((lo + hi) / 2, float(values[sel].mean())))
        if len(points) > 1:
            draw.line(points, fill=colour, width=line)
        for cx, cy in points:
            draw.ellipse([cx - 3, cy - 3, cx + 3, cy + 3], fill=colour)
    draw.text(
        (left, 12),
        f"success (green), SPL (blue) and SoftSPL (orange) vs geodesic distance, {len(results)} episodes",
        fill="black",
    )
    draw.text((left + pw / 2 - 60, height - 20), "geodesic distance (m)", fill="black")
    image.save(path)
