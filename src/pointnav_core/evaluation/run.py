"""Evaluate a policy on an episode dataset: per-episode results, summary, and a plot.

Every episode is played in its own fresh start: the env is reset with the episode's own
seed (:func:`~pointnav_core.datasets.playback.episode_seed`, from its scene and episode ids)
and the policy is built anew for it, so an episode's result is the same whatever the order
of the episodes or the number of worker processes.

Each episode is played by a robot of the radius it was made for (``info.robot_radius``),
with the goal tolerance it records (``goals[0].radius``; the task's 0.5 m when None), on
the floor it records, for at most ``max_steps`` steps.

Policies (``policy`` argument, or ``pointnav eval --policy``):

- ``"oracle"``: :class:`~pointnav_core.policies.oracle.ShortestPathFollower` (ignores
  pedestrians);
- ``"orca_robot"``, ``"dwa"``: the crowd baselines of :mod:`pointnav_core.policies.crowd`
  (an ORCA robot, the dynamic window approach), toward the oracle's carrot;
- ``"MODULE:CALLABLE"``: ``CALLABLE(env)`` is called after each reset and returns a
  function ``observation -> action``;
- a path to a Stable-Baselines3 ``.zip``: the model (``sb3_algo``, PPO by default) acts
  deterministically; it gets the flat observation when its observation space is a ``Box``;
- a path to a checkpoint ``.pt`` (``pointnav train``'s,
  :mod:`pointnav_core.policies.checkpoint`): its network acts as the checkpoint says,
  deterministically (the most likely action, or the mean) or by draws seeded with the
  episode's seed (:mod:`pointnav_core.policies.checkpoint_policy`; ``pointnav eval
  --actions`` overrides it), in envs built from the env config it carries, unless
  ``env_config`` is given. Loading one runs no code, so it needs no trust flag.
- ``"baseline:NAME"``: a checkpoint shipped with the package
  (:mod:`pointnav_core.policies.baselines`; ``baseline:scan-ppo``), played as above.

``limit`` and ``stride`` (``--limit N``, ``--stride K``) play a subset: every ``K``-th
episode of the dataset from the first, then the first ``N`` of those
(:func:`select_episodes`).

An SB3 ``.zip`` holds pickled Python objects that run code when they are loaded: it is
loaded only with ``trust_policy_file=True`` (``--trust-policy-file``).

A run survives its faults (:func:`evaluate`): each result is handed to ``on_result`` as
its episode ends, an episode whose policy raises is named and stopped on or skipped
(``on_error``), and worker processes end with the run, whatever ends it. Every argument,
and every episode's scene id, is checked before any episode is played; an error names the
episode and the field.

With an ``env_config`` (:mod:`pointnav_core.envs.config`), every episode's env is built from
it (sensors, actions, robot, backend, task settings, ``max_steps``) with the episode's scene,
floor, start, goal and goal radius; ``backend``, ``max_steps`` and ``drive`` must then keep
their defaults, and every episode's robot radius must be the config's. Without one, a policy
factory with an ``env_config`` attribute (a checkpoint's) plays in envs built from that.

``isolate=True`` plays in worker processes even with one worker, so that a signal handler
that raises in this process never lands inside the policy's or the compiler's code
(``pointnav eval`` does: see :mod:`pointnav_core.cli.datasets`).

This module drives the envs, so it is not part of the core; the CLI uses it.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from typing import Any

from pointnav_core.datasets.format import EpisodeDataset, PointNavEpisode
from pointnav_core.datasets.playback import episode_seed
from pointnav_core.datasets.scene_sets import load_scene, locate_scene
from pointnav_core.envs.config import EnvConfig
from pointnav_core.errors import ArgumentError, EpisodeError
from pointnav_core.evaluation.config import (
    check_beside_config,
    check_robot_radius,
    episode_config,
)
from pointnav_core.evaluation.policy_specs import (
    PolicyFactory,
    make_policy,
)
from pointnav_core.evaluation.report import EpisodeResult
from pointnav_core.task import metrics
from pointnav_core.utils.validation import integer
from pointnav_core.utils.workers import WorkerError, WorkerPool, usable_cores

__all__ = ["check_scene_ids", "evaluate", "select_episodes"]

#: Default step limit: a 30 m geodesic at 0.5 m/s and 10 Hz takes 600 steps, plus turns.
DEFAULT_MAX_STEPS = 1000
#: What ``on_error`` may say when an episode's policy raises.
ON_ERROR = ("stop", "skip")
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
        trust_policy_file: bool = False,
        env_config: EnvConfig | None = None,
    ) -> None:
        self.factory = (
            make_policy(policy, sb3_algo, trust_policy_file) if isinstance(policy, str) else policy
        )
        self.backend, self.max_steps, self.drive = backend, max_steps, drive
        self.scenes_root, self.envs = scenes_root, {}
        self.env_config = env_config

    def env_for(self, ep: PointNavEpisode) -> Any:
        from pointnav_core.envs.pointnav import PointNavEnv

        key = (ep.scene_id, ep.floor, ep.robot_radius, ep.goal_radius)
        if key not in self.envs:
            if len(self.envs) >= 4:  # a worker moves on from scene to scene
                self.envs.pop(next(iter(self.envs))).close()
            try:
                scene = load_scene(ep.scene_id, self.scenes_root)
            except (ValueError, FileNotFoundError) as err:
                raise ArgumentError(f"episode {ep.episode_id!r}: field 'scene_id': {err}") from None
            if ep.floor >= scene.n_floors:
                raise ArgumentError(
                    f"episode {ep.episode_id!r}: field 'info.floor' is {ep.floor}, but scene "
                    f"{ep.scene_id!r} has {scene.n_floors} floor(s)"
                )
            if self.env_config is not None:
                self.envs[key] = PointNavEnv(scene=scene, config=episode_config(self.env_config, ep))
                return self.envs[key]
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

    def outcome(self, ep: PointNavEpisode) -> tuple[str, Any]:
        """Play ``ep``: ``("ok", EpisodeResult)``, ``("input", message)`` for an episode that
        does not suit its scene, or ``("error", message)`` for a policy that raised."""
        step = 0
        try:
            try:
                env = self.env_for(ep)
                check = getattr(self.factory, "check_env", None)
                if check is not None:  # a model that cannot read this env is bad input
                    check(env)
                obs, info = env.reset(seed=episode_seed(ep), options={"episode": ep})
            except (ValueError, FileNotFoundError) as err:
                return "input", str(err)
            policy = self.factory(env)
            done = False
            while not done:
                obs, _, terminated, truncated, info = env.step(policy(obs))
                done = terminated or truncated
                step += 1
        except Exception as err:  # whatever the user's policy raises names its episode
            return "error", (
                f"episode {ep.episode_id!r} (scene {ep.scene_id!r}) failed at step {step}: "
                f"{type(err).__name__}: {err}"
            )
        return "ok", self.result(ep, env, info)

    def result(self, ep: PointNavEpisode, env: Any, info: dict[str, Any]) -> EpisodeResult:
        """The record of ``ep``, played to its end in ``env`` (last step's ``info``)."""
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
            pedestrian_collisions=info.get("pedestrian_collisions"),
            social=info.get("social"),
        )


def _floor_of(ep: PointNavEpisode) -> tuple[str, int, float]:
    """The floor geometry an episode needs: a worker keeps to one while it has episodes."""
    return ep.scene_id, ep.floor, ep.robot_radius


def _play(runner: _Runner, ep: PointNavEpisode) -> tuple[str, Any]:
    """A worker's task (module level, so that ``spawn`` can find it)."""
    return runner.outcome(ep)


def check_scene_ids(episodes: Sequence[PointNavEpisode], scenes_root: str | None) -> None:
    """Refuse an unknown, missing or escaping scene (a ValueError naming the first episode
    that has it) without building any scene."""
    seen: set[str] = set()
    for ep in episodes:
        if ep.scene_id not in seen:
            seen.add(ep.scene_id)
            try:
                locate_scene(ep.scene_id, scenes_root)
            except (ValueError, FileNotFoundError) as err:
                raise ArgumentError(f"episode {ep.episode_id!r}: field 'scene_id': {err}") from None


def select_episodes(
    episodes: EpisodeDataset | Sequence[PointNavEpisode],
    limit: int | None = None,
    stride: int = 1,
) -> list[PointNavEpisode]:
    """Every ``stride``-th episode from the first, then the first ``limit`` of those (all
    with None): ``list(episodes)[::stride][:limit]``.

    Raises
    ------
    ValueError
        For a ``limit`` or ``stride`` that is not an integer >= 1.
    """
    integer("stride", stride, minimum=1)
    if limit is not None:
        integer("limit", limit, minimum=1)
    return list(episodes)[::stride][:limit]


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
    trust_policy_file: bool = False,
    on_error: str = "stop",
    on_result: Callable[[EpisodeResult], None] | None = None,
    on_failure: Callable[[PointNavEpisode, str], None] | None = None,
    limit: int | None = None,
    stride: int = 1,
    env_config: EnvConfig | None = None,
    isolate: bool = False,
) -> list[EpisodeResult]:
    """Play every episode once (or the subset ``limit`` and ``stride`` select): see the module notes.

    Parameters
    ----------
    episodes : EpisodeDataset or sequence of PointNavEpisode
    policy : str or callable
        A :func:`make_policy` spec, or a factory ``env -> (observation -> action)`` (picklable with ``workers > 1``).
    backend : str
        Registered backend name.
    workers : int
        Worker processes (1: play here); at most one per episode and per usable core.
    max_steps : int
        Step limit per episode.
    drive : {"differential", "holonomic"}
        The robot's drive.
    scenes_root : str, optional
        Folder relative scene paths in ``scene_id`` are read from (and must stay under).
    sb3_algo : str
        Stable-Baselines3 algorithm class of a ``.zip`` policy.
    progress : bool
        Show a progress bar.
    trust_policy_file : bool
        Allow an SB3 ``.zip`` policy (see the module notes).
    on_error : {"stop", "skip"}
        When the policy raises in an episode: raise :class:`~pointnav_core.errors.EpisodeError`
        at once, or leave the episode out and go on.
    on_result : callable, optional
        Called with each result as its episode ends (in the order they end).
    on_failure : callable, optional
        With ``on_error="skip"``: called with each failed episode and its message (default: a ``RuntimeWarning``).
    limit, stride : int, optional
        Play only :func:`select_episodes` ``(episodes, limit, stride)``.
    env_config : EnvConfig, optional
        Build every episode's env from this config (see the module notes).
    isolate : bool
        Play in worker processes even with one worker (see the module notes).

    Returns
    -------
    list of EpisodeResult
        The results in the episodes' order, without the skipped episodes.

    Raises
    ------
    ValueError
        For a bad argument, or an episode that does not suit its scene or robot.
    EpisodeError
        With ``on_error="stop"``: the first episode whose policy raised, or a dead worker.
    KeyboardInterrupt
        Passed on, after every worker process has ended.
    """
    episodes = select_episodes(episodes, limit, stride)
    args = _runner_args(episodes, policy, workers, on_error, backend, max_steps, drive, scenes_root, sb3_algo,
                        trust_policy_file, env_config)
    recorder = _Recorder(episodes, on_error, on_result, on_failure, progress)
    try:
        _play_all(episodes, args, recorder, min(workers, len(episodes), usable_cores()), isolate)
    finally:
        recorder.bar.close()
    return [r for r in recorder.results if r is not None]


def _runner_args(
    episodes: list[PointNavEpisode], policy: str | PolicyFactory, workers: int, on_error: str, backend: str,
    max_steps: int, drive: str, scenes_root: str | None, sb3_algo: str, trust_policy_file: bool,
    env_config: EnvConfig | None,
) -> tuple[Any, ...]:
    """Check :func:`evaluate`'s arguments and scene ids before anything is played; the
    arguments of a :class:`_Runner` (with the policy's own env config when none is given)."""
    for name, value in (("workers", workers), ("max_steps", max_steps)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ArgumentError(f"{name} must be an integer >= 1, got {value!r}")
    if on_error not in ON_ERROR:
        raise ArgumentError(f"on_error must be one of {list(ON_ERROR)}, got {on_error!r}")
    factory = make_policy(policy, sb3_algo, trust_policy_file) if isinstance(policy, str) else policy
    if env_config is None:  # a checkpoint carries the config it was trained with
        env_config = getattr(factory, "env_config", None)
    if env_config is not None:
        check_beside_config(env_config, backend=backend, max_steps=max_steps, drive=drive)
        check_robot_radius(env_config, episodes)
    check_scene_ids(episodes, scenes_root)
    return (policy, backend, max_steps, drive, scenes_root, sb3_algo, trust_policy_file, env_config)


class _Recorder:
    """Takes each episode's outcome as it arrives (:meth:`_Runner.outcome`): keeps results in
    the episodes' order, and stops on or skips failures as ``on_error`` says."""

    def __init__(
        self, episodes: list[PointNavEpisode], on_error: str, on_result: Callable[[EpisodeResult], None] | None,
        on_failure: Callable[[PointNavEpisode, str], None] | None, progress: bool,
    ) -> None:
        from tqdm import tqdm

        self.episodes, self.on_error, self.on_result, self.on_failure = episodes, on_error, on_result, on_failure
        self.results: list[EpisodeResult | None] = [None] * len(episodes)
        self.bar = tqdm(total=len(episodes), disable=not progress, desc="episodes", unit="ep")

    def __call__(self, i: int, kind: str, payload: Any) -> None:
        if kind == "input":
            raise ArgumentError(payload)
        if kind == "error":
            if self.on_error == "stop":
                raise EpisodeError(payload)
            (self.on_failure or self.warn)(self.episodes[i], payload)
        else:
            self.results[i] = payload
            if self.on_result is not None:
                self.on_result(payload)
        self.bar.update(1)

    @staticmethod
    def warn(_ep: PointNavEpisode, message: str) -> None:
        """The default ``on_failure``: a ``RuntimeWarning`` pointing at evaluate's caller."""
        warnings.warn(message, RuntimeWarning, stacklevel=5)  # here, __call__, _play_all, evaluate


def _play_all(
    episodes: list[PointNavEpisode], args: tuple[Any, ...], record: _Recorder, n_workers: int, isolate: bool
) -> None:
    """Play every episode, here or in ``n_workers`` processes, handing each outcome to ``record``."""
    if n_workers <= 1 and not isolate:
        runner = _Runner(*args)
        for i, ep in enumerate(episodes):
            record(i, *runner.outcome(ep))
    elif episodes:
        with WorkerPool(n_workers, _Runner, args, _play) as pool:
            try:
                for i, (kind, payload) in pool.imap_unordered(enumerate(episodes), group=_floor_of):
                    record(i, kind, payload)  # type: ignore[arg-type]
            except WorkerError as err:
                if err.key is None:
                    raise EpisodeError(str(err)) from None
                ep = episodes[err.key]  # type: ignore[index]
                raise EpisodeError(
                    f"episode {ep.episode_id!r} (scene {ep.scene_id!r}): {err.cause}"
                ) from None
