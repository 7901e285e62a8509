"""The crowd baselines on the crowd presets: success, SPL, PSC and pedestrian contacts.

For each preset of :mod:`pointnav_core.crowds.presets` (circle crossing, corridor, doorway)
and each policy (``oracle``, which ignores people; ``orca_robot``; ``dwa``), ``--episodes``
episodes are played: circle crossing with its start noise drawn from seeds 0, 1, ...; the
corridor and the doorway with the reset seeds 0, 1, ... (which draw the pedestrians' speeds
in their ranges). Each episode runs to its end (500 steps at most). The table gives the
means, with the policies as ``pointnav eval`` plays them (``make_policy``).

The shipped validation set with crowds is ``pointnav eval`` itself (see the README):
``pointnav eval --dataset src/pointnav_core/datasets/data/houses_val_300.json.gz --policy P
--env-config crowd.yaml`` with ``crowd.yaml`` holding ``pedestrians: {density: 0.125}``.

Run: ``python benchmarks/bench_crowd_baselines.py [--episodes 10]``
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from pointnav_core.crowds import presets
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.evaluation.policy_specs import make_policy

POLICIES = ("oracle", "orca_robot", "dwa")


def play(scenario: presets.Scenario, policy: str, seed: int) -> dict[str, float]:
    """One episode of ``scenario`` with ``policy`` from reset seed ``seed``."""
    env = PointNavEnv(**scenario.env_arguments())
    obs, _ = env.reset(seed=seed)
    act = make_policy(policy)(env)
    while True:
        obs, _, terminated, truncated, info = env.step(act(obs))
        if terminated or truncated:
            break
    return {"success": float(info["success"]), "spl": info["spl"], "psc": info["social"]["psc"],
            "contacts": float(info["pedestrian_collisions"]), "steps": float(info["episode_length"])}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=10)
    args = parser.parse_args()
    print("| preset | policy | success | SPL | PSC | pedestrian contact steps | steps |")
    print("|---|---|---|---|---|---|---|")
    start = time.perf_counter()
    for name in ("circle_crossing", "corridor", "doorway"):
        for policy in POLICIES:
            rows = []
            for k in range(args.episodes):
                scenario = presets.circle_crossing(seed=k) if name == "circle_crossing" else getattr(presets, name)()
                rows.append(play(scenario, policy, seed=k))
            mean = {key: float(np.mean([r[key] for r in rows])) for key in rows[0]}
            print(f"| {name} | {policy} | {mean['success']:.2f} | {mean['spl']:.3f} | {mean['psc']:.3f} | "
                  f"{mean['contacts']:.1f} | {mean['steps']:.0f} |", flush=True)
    print(f"({args.episodes} episodes per row, {time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
