"""PPO on the batched engine, from the library: :mod:`pointnav_core.training.ppo`.

``VectorPointNavEnv`` steps thousands of worlds as arrays, so one rollout of ``--num-steps``
steps gives ``num_envs * num_steps`` samples (16,384 with the defaults) without a Python
loop over worlds. The policy acts with Habitat's discrete actions (MOVE_FORWARD 0.25 m,
TURN_LEFT/RIGHT 10 deg; STOP with ``--stop``). The PPO itself (observation and reward
normalisation, the engine's next-step autoreset respected) is the library's, the one
``pointnav train`` runs; this script only builds the env and prints each rollout.

Run (one torch thread; the default scene is the default house as a grid)::

    python examples/ppo_vector.py --total-steps 200000
    python examples/ppo_vector.py --num-envs 1024 --device cpu   # the engine on torch too

``pointnav train --config FILE`` trains the same PPO from a config file, and saves
checkpoints that ``pointnav eval --policy CHECKPOINT`` plays. ``Config`` and :func:`train`
are reused by ``benchmarks/bench_learning_vector.py``.
"""

from __future__ import annotations

import argparse
from typing import Any

import torch

from pointnav_core.training.ppo import PPOSettings as Config
from pointnav_core.training.ppo import train

__all__ = ["Config", "main", "train"]


def main() -> None:
    from pointnav_core.vector import VectorPointNavEnv

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--num-envs", type=int, default=512)
    p.add_argument("--device", default="numpy", help="the engine's: numpy, cpu or cuda")
    p.add_argument("--total-steps", type=int, default=Config.total_steps)
    p.add_argument("--num-steps", type=int, default=Config.num_steps)
    p.add_argument("--max-steps", type=int, default=150, help="actions per episode")
    p.add_argument("--stop", action="store_true", help="STOP is an action (success needs it)")
    p.add_argument("--seed", type=int, default=0)
    args = p.parse_args()
    torch.set_num_threads(1)
    env = VectorPointNavEnv(
        args.num_envs, device=args.device, seed=args.seed, max_episode_steps=args.max_steps,
        task={"goal_in_polar": True, "reward_type": "geodesic"},
        action_space="discrete", discrete_actions={"stop": args.stop}, pool_size=4, starts_per_goal=32,
    )
    cfg = Config(total_steps=args.total_steps, num_steps=args.num_steps, seed=args.seed)

    def log(s: dict[str, float], *_: Any) -> bool:
        print(f"{s['steps']:>9.0f} steps  {s['steps'] / s['wall_s']:>7.0f} steps/s  "
              f"success {s['success']:.3f}  SPL {s['spl']:.3f}  ({s['episodes']:.0f} episodes)", flush=True)
        return True

    train(env, cfg, log)


if __name__ == "__main__":
    main()
