"""Agreement of the batched engine with one kinematic PointNavEnv per world, measured.

20 cluttered rooms (24 x 30 cells of 0.1 m, 10 % obstacle cells, a 3 x 3 hole), 8 worlds
each with random starts, goals and headings, 300 steps of random actions (half of them
full speed ahead, into walls), with the L2 and with the geodesic reward; episodes end by
success, falling, 30 contact steps or the 80-step limit and are autoreset. Prints the
largest observation and reward differences and how many episode ends, contact steps and
autoresets the runs held. Uses ``tests/vector_reference.py``. ``--drive holonomic``
drives holonomic robots instead (their actions also full speed diagonally 30 % of the
time: the backend's two sub-steps near walls); ``--scenes N`` plays the first N rooms.

Run: ``PYTHONPATH=tests python benchmarks/bench_vector_agreement.py [--drive holonomic] [--scenes N]``
"""

from __future__ import annotations

import argparse

import numpy as np
from vector_reference import compare, random_episodes

from pointnav_core.scenes import Scene


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--drive", choices=("differential", "holonomic"), default="differential")
    parser.add_argument("--scenes", type=int, default=20, help="rooms to play (default 20)")
    args = parser.parse_args()
    worst = {"obs_diff": 0.0, "reward_diff": 0.0}
    totals = {"ends": 0, "contacts": 0, "autoresets": 0}
    for seed in range(args.scenes):
        rng = np.random.default_rng(seed)
        grid = np.zeros((24, 30), np.uint8)
        grid[rng.random(grid.shape) < 0.1] = 1
        grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = 1
        grid[10:13, 3:6] = 2
        grid[3:9, 12:18] = 0
        scene = Scene.from_array(grid, 0.1)
        dim = 3 if args.drive == "holonomic" else 2
        actions = rng.uniform(-1.2, 1.2, (300, 8, dim)).astype(np.float32)
        actions[rng.random((300, 8)) < 0.5, 0] = 1.0
        if dim == 3:
            diagonal = rng.random((300, 8)) < 0.3
            actions[diagonal, :2] = rng.choice([-1.0, 1.0], size=(int(diagonal.sum()), 2))
        for reward_type in ("l2", "geodesic"):
            task = {"reward_type": reward_type, "termination_config": {"max_steps": 80, "max_collisions": 30}}
            stats = compare(scene, random_episodes(scene, 8, rng), actions, task=task, robot={"drive": args.drive})
            for key in worst:
                worst[key] = max(worst[key], stats[key])
            for key in totals:
                totals[key] += int(stats[key])
    print(f"largest observation difference {worst['obs_diff']:.3g}, reward difference {worst['reward_diff']:.3g}")
    print(f"episode ends {totals['ends']}, contact steps {totals['contacts']}, autoresets {totals['autoresets']}")


if __name__ == "__main__":
    main()
