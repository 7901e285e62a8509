"""RLlib PPO (new API stack) on several robots of ``pointnav_core/MultiPointNav-v0``.

The script starts its own one-node Ray instance on the loopback address only
(``init_local_ray``) and prints the cluster's nodes. ``register_rllib_envs`` puts both env
ids in RLlib's registry, so the remote env runner, another process, builds the env from
``config.environment("pointnav_core/MultiPointNav-v0")``. Three robots share one policy;
``PointNavMetricsCallbacks`` reports each robot's success, SPL, SoftSPL and collisions.

Run: ``python examples/rllib_ppo_multi.py`` (needs the ``rl`` extra). Expected output:

    Ray node 127.0.0.1: alive=True, CPUs=2
    iteration 1: 2000 env steps, 86 env steps/s, return 1.33, success 0.03, SPL 0.02
    iteration 2: 4000 env steps, 84 env steps/s, return -0.34, success 0.00, SPL 0.00
    iteration 3: 6000 env steps, 83 env steps/s, return 2.14, success 0.07, SPL 0.03
    iteration 4: 8000 env steps, 85 env steps/s, return 1.65, success 0.03, SPL 0.02
    iteration 5: 10000 env steps, 85 env steps/s, return -0.06, success 0.03, SPL 0.02
    iteration 6: 12000 env steps, 94 env steps/s, return 1.82, success 0.03, SPL 0.02
    iteration 7: 14000 env steps, 106 env steps/s, return -0.28, success 0.00, SPL 0.00
    iteration 8: 16000 env steps, 116 env steps/s, return 1.99, success 0.07, SPL 0.03

(On a 2-core x86_64 CPU machine that two other heavy jobs shared, 165 s, Ray's start and
setup included; alone on it the same run gave about 300 env steps/s and 73 s. An env step moves all three robots. RLlib samples in another process, and the
numbers may differ a little from run to run; Ray's own log lines go to stderr.)
"""

from __future__ import annotations

import time

import ray
import torch
from ray.rllib.algorithms.ppo import PPOConfig
from ray.rllib.core.rl_module.default_model_config import DefaultModelConfig

from pointnav_core import scenes
from pointnav_core.integrations.rllib import (
    MULTI_ENV_ID,
    PointNavMetricsCallbacks,
    init_local_ray,
    register_rllib_envs,
)

ITERATIONS = 8
torch.set_num_threads(1)  # the learner runs here, beside the env runner: one thread each

init_local_ray(num_cpus=2, log_to_driver=False)
for node in ray.nodes():
    print(
        f"Ray node {node['NodeManagerAddress']}: alive={node['Alive']}, "
        f"CPUs={node['Resources'].get('CPU', 0):.0f}"
    )
register_rllib_envs()

config = (
    PPOConfig()
    .environment(
        MULTI_ENV_ID,
        env_config={
            "scene": scenes.rooms(seed=0, size=(8.0, 6.0)),
            "n_robots": 3,
            "max_cycles": 200,
        },
    )
    .multi_agent(policies={"shared"}, policy_mapping_fn=lambda agent_id, *args, **kwargs: "shared")
    .env_runners(num_env_runners=1)
    .training(train_batch_size_per_learner=2000, minibatch_size=500, num_epochs=5)
    .rl_module(model_config=DefaultModelConfig(fcnet_hiddens=[64, 64]))
    .callbacks(PointNavMetricsCallbacks)
    .debugging(seed=0)
)
algo = config.build_algo()
env_steps = 0
start = time.perf_counter()
for iteration in range(1, ITERATIONS + 1):
    result = algo.train()
    runners = result["env_runners"]
    env_steps += runners["num_env_steps_sampled"]
    pointnav = runners.get("pointnav", {})
    print(
        f"iteration {iteration}: {env_steps} env steps, "
        f"{env_steps / (time.perf_counter() - start):.0f} env steps/s, "
        f"return {runners.get('episode_return_mean', float('nan')):.2f}, "
        f"success {pointnav.get('success', float('nan')):.2f}, "
        f"SPL {pointnav.get('spl', float('nan')):.2f}"
    )
algo.stop()
ray.shutdown()
