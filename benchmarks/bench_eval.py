"""The oracle's evaluation as a multiple of stepping the same episodes alone.

``--episodes`` episodes are generated afresh on the ``houses`` scene set (the split and seed
given), then played twice through :func:`pointnav_core.evaluation.run.evaluate` with one
worker, the same code as ``pointnav eval --workers 1``:

1. by the oracle (:class:`~pointnav_core.policies.oracle.ShortestPathFollower`), whose actions are
   recorded;
2. by a policy that replays those actions: the same env builds, resets, steps and final
   distances, with no planning.

Both passes are timed whole, each in a fresh process (so that neither finds the other's
scenes, planners or goal fields in memory; both read the geometry cache on disk, as every
new process does), so the ratio is the oracle's cost (its planning and its clearance
checks) on top of everything else an evaluation does. The two passes must give
the same results, which the script checks. Printed: both wall times, the ratio (the
geometry issue's target is at most 3 x), and the oracle's success, SPL and SoftSPL.

Run: ``python benchmarks/bench_eval.py [--episodes 40] [--split val] [--seed 7]``
"""

from __future__ import annotations

import argparse
import time
from collections import deque
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from typing import Any

from pointnav_core.datasets.generator import generate_split
from pointnav_core.datasets.scene_sets import scene_set
from pointnav_core.evaluation.report import summarize
from pointnav_core.evaluation.run import evaluate
from pointnav_core.policies.oracle import ShortestPathFollower


def _play(episodes: list[Any], recorded: list[list[Any]] | None) -> tuple[float, list[Any], list[list[Any]]]:
    """One timed pass in this (fresh) process: the oracle's, recording its actions, or with
    ``recorded`` given, the replay of them. Returns the wall time, results and actions."""
    actions_of: deque[list[Any]] = deque(recorded or [])
    kept: list[list[Any]] = []

    def oracle(env: Any) -> Any:
        follower, actions = ShortestPathFollower(env), []
        kept.append(actions)

        def act(_obs: Any) -> Any:
            actions.append(follower.act())
            return actions[-1]

        return act

    def replay(_env: Any) -> Any:
        actions = iter(actions_of.popleft())
        return lambda _obs: next(actions)

    start = time.perf_counter()
    results = evaluate(episodes, oracle if recorded is None else replay)
    return time.perf_counter() - start, results, kept


def _fresh(*args: Any) -> Any:
    """``_play`` in a fresh interpreter: neither pass finds the other's scenes, planners or
    goal fields in memory (both read the geometry cache on disk, as any new process does)."""
    with ProcessPoolExecutor(1, mp_context=get_context("spawn")) as pool:
        return pool.submit(_play, *args).result()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=40)
    parser.add_argument("--split", default="val")
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()
    episodes = list(generate_split(scene_set("houses"), args.split, args.episodes, seed=args.seed))
    t_oracle, played, recorded = _fresh(episodes, None)
    t_replay, replayed, _ = _fresh(episodes, recorded)
    if [r.steps for r in played] != [r.steps for r in replayed] or summarize(played) != summarize(replayed):
        raise SystemExit("the replay did not reproduce the oracle's episodes")
    s = summarize(played)
    steps = sum(r.steps for r in played)
    print(f"{len(episodes)} episodes, {steps} steps on 'houses' ({args.split}, seed {args.seed}), each pass in a fresh process")
    print(f"oracle evaluation   {t_oracle:8.2f} s")
    print(f"replayed actions    {t_replay:8.2f} s")
    print(f"oracle / replay     {t_oracle / t_replay:8.2f} x   (target <= 3 x)")
    print(f"success {s['success']:.4f}  SPL {s['spl']:.4f}  SoftSPL {s['soft_spl']:.4f}")


if __name__ == "__main__":
    main()
