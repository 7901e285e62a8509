"""Two source trees, one workload at a time, timed in alternating bursts: a change's cost.

On a shared machine a benchmark's rate swings by a third or more between runs, far more than
the few percent a refactor may cost, so two runs of ``bench_env.py`` cannot tell a 5 % change
apart. Here each tree gets one worker process (its ``src`` first on ``PYTHONPATH``), which
builds every workload once; the workers then step the same workload in short bursts, one
tree after the other, the order swapped each pair. The machine's drift is shared by both
sides of a pair, so the median of the per-pair ratios (new time / old time) holds to a few
percent where the raw rates do not. Printed per workload: that median and its quartiles.

The workloads are the default rows of ``bench_env.py``, ``bench_parallel.py`` and
``bench_vector.py``: ``PointNav-v0`` on the default house (l2 reward; and with a 64-ray scan),
``MultiPointNav-v0`` with three robots and its default episodes (resets included), the
batched engine at 1,024 worlds x 4 robots (32-ray scan, none, and on torch) and 4,096 x 1,
and ``bench_crowd.py``'s single env with a 12-ray scan and 10 ORCA pedestrians.
Imports fall back to the module names before the package layout of 2026-11-28, so an older
tree can be the ``--old`` one.

Run: ``python benchmarks/bench_ab.py --old PATH --new PATH [--pairs 30] [--only TEXT ...]``
(each PATH a checkout's root, for example a ``git worktree add`` of the commit before;
``--only`` keeps the workloads whose names contain one of the texts).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from typing import Any

#: name -> (steps per burst, what it steps).
WORKLOADS: dict[str, tuple[int, str]] = {
    "PointNav-v0": (2000, "bench_env's default row"),
    "PointNav-v0 + scan 64": (800, "bench_env's scan row"),
    "PointNav-v0 + scan 12, 10 ORCA pedestrians": (600, "bench_crowd's single-env row, resets included"),
    "MultiPointNav-v0 (3 robots)": (600, "bench_parallel's defaults, resets included"),
    "vector 1,024 x 4, 32 rays": (5, "bench_vector, numpy"),
    "vector 1,024 x 4, no scan": (20, "bench_vector, numpy"),
    "vector 1,024 x 4, 32 rays, torch": (5, "bench_vector, torch cpu"),
    "vector 4,096 x 1, no scan": (20, "bench_vector, numpy"),
}


def _single(**kwargs: Any) -> Callable[[int], None]:
    import gymnasium as gym

    import pointnav_core  # noqa: F401  (registers the envs)
    from pointnav_core import scenes

    env = gym.make("pointnav_core/PointNav-v0", scene=scenes.rooms(seed=0), **kwargs)
    env.reset(seed=0)
    env.action_space.seed(0)
    actions = [env.action_space.sample() for _ in range(4096)]
    at = [0]

    def run(n: int) -> None:
        for _ in range(n):
            _, _, terminated, truncated, _ = env.step(actions[at[0] % len(actions)])
            at[0] += 1
            if terminated or truncated:
                env.reset()

    return run


def _multi() -> Callable[[int], None]:
    from pointnav_core import scenes

    try:
        from pointnav_core.envs.multi_pointnav import parallel_env
    except ImportError:  # before the package layout
        from pointnav_core.parallel import parallel_env  # type: ignore[no-redef]
    env = parallel_env(n_robots=3, scene=scenes.rooms(seed=0))
    env.reset(seed=0)
    for agent in env.possible_agents:
        env.action_space(agent).seed(0)

    def run(n: int) -> None:
        for _ in range(n):
            if not env.agents:
                env.reset()
            env.step({a: env.action_space(a).sample() for a in env.agents})

    return run


def _vector(worlds: int, robots: int, scan: bool, device: str = "numpy") -> Callable[[int], None]:
    import numpy as np

    from pointnav_core import scenes
    from pointnav_core.vector import VectorPointNavEnv

    env = VectorPointNavEnv(worlds, n_robots=robots, scene=scenes.rooms(seed=0), device=device, seed=0,
                            task={"reward_type": "geodesic"}, sensors={"scan": {"n_rays": 32}} if scan else None)
    env.reset(seed=0)
    shape = (worlds, robots, 2) if robots > 1 else (worlds, 2)
    actions: Any = np.random.default_rng(0).uniform(-1, 1, shape).astype(np.float32)
    if device != "numpy":
        import torch

        actions = torch.as_tensor(actions)

    def run(n: int) -> None:
        for _ in range(n):
            env.step(actions)

    return run


def _worker() -> None:
    """Build every workload, then answer ``name`` lines with the seconds a burst took."""
    runs = {
        "PointNav-v0": _single(),
        "PointNav-v0 + scan 64": _single(sensors={"scan": {"n_rays": 64}}),
        "PointNav-v0 + scan 12, 10 ORCA pedestrians": _single(sensors={"scan": {"n_rays": 12}},
                                                             pedestrians={"count": 10}),
        "MultiPointNav-v0 (3 robots)": _multi(),
        "vector 1,024 x 4, 32 rays": _vector(1024, 4, True),
        "vector 1,024 x 4, no scan": _vector(1024, 4, False),
        "vector 1,024 x 4, 32 rays, torch": _vector(1024, 4, True, "cpu"),
        "vector 4,096 x 1, no scan": _vector(4096, 1, False),
    }
    for name, run in runs.items():
        run(WORKLOADS[name][0])  # warm: compiled kernels, caches
    print("ready", flush=True)
    for line in sys.stdin:
        name = line.strip()
        started = time.perf_counter()
        runs[name](WORKLOADS[name][0])
        print(time.perf_counter() - started, flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--old", required=True, help="root of the checkout to compare against")
    parser.add_argument("--new", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    parser.add_argument("--pairs", type=int, default=30, help="alternated bursts per workload and tree")
    parser.add_argument("--only", nargs="+", default=None, metavar="TEXT",
                        help="run only the workloads whose names contain one of these")
    args = parser.parse_args()
    chosen = [name for name in WORKLOADS if args.only is None or any(t in name for t in args.only)]
    workers = {}
    for side in ("old", "new"):
        root = os.path.abspath(getattr(args, side))
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([f"{root}/src", f"{root}/src/backends"]),
                   OMP_NUM_THREADS="1")
        workers[side] = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--worker"], cwd=root, env=env,
                                         stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    for side, proc in workers.items():
        if proc.stdout.readline().strip() != "ready":  # type: ignore[union-attr]
            raise SystemExit(f"the {side} tree's worker failed to build its workloads")

    def burst(side: str, name: str) -> float:
        proc = workers[side]
        proc.stdin.write(name + "\n")  # type: ignore[union-attr]
        proc.stdin.flush()  # type: ignore[union-attr]
        return float(proc.stdout.readline())  # type: ignore[union-attr]

    print(f"new {args.new} against old {args.old}: new time / old time per burst, {args.pairs} pairs each")
    for name in chosen:
        steps, what = WORKLOADS[name]
        ratios = []
        for pair in range(args.pairs):
            times = {side: burst(side, name) for side in (("old", "new") if pair % 2 else ("new", "old"))}
            ratios.append(times["new"] / times["old"])
        lo, mid, hi = statistics.quantiles(ratios, n=4)
        print(f"{name:44s} median {statistics.median(ratios):.3f}  quartiles {lo:.3f}-{hi:.3f}  "
              f"({steps} steps a burst; {what})", flush=True)
    for proc in workers.values():
        proc.stdin.close()  # type: ignore[union-attr]
        proc.wait()


if __name__ == "__main__":
    if sys.argv[1:] == ["--worker"]:
        _worker()
    else:
        main()
