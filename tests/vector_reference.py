"""The reference for the batched engine: one ``PointNavEnv`` (kinematic backend) per world.

:func:`compare` plays the same fixed episodes and actions on a ``VectorPointNavEnv`` and
on ``num_envs`` separate single envs, resetting each single env the step after its
episode ended (Gymnasium's next-step autoreset), and fails at the first step where they
disagree beyond the tolerances of issue 14.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from local_map_reference import assert_obs, obs_ties

from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.vector import VectorPointNavEnv

OBS_TOL = 1e-4
REWARD_TOL = 1e-5
INFO_KEYS = ("success", "spl", "soft_spl", "collisions", "episode_length", "path_length", "distance_to_goal")


def compare(
    scene: Any,
    episodes: list[tuple[Any, float, Any]],
    actions: np.ndarray,
    task: dict | None = None,
    device: str = "numpy",
    sensors: dict | None = None,
    **env_kwargs: Any,
) -> dict[str, Any]:
    """Step both for ``len(actions)`` steps; return counts of what happened (ends, contacts)
    and the largest observation and reward differences seen.

    ``episodes`` holds one ``(start_xy, yaw, goal_xy)`` per world; ``actions`` has shape
    ``(steps, num_envs, 2)``, or ``(steps, num_envs)`` for discrete actions; ``sensors``
    and ``env_kwargs`` (``action_space``, ``discrete_actions``) go to both engines.
    """
    task = dict(task or {})
    n = len(episodes)
    venv = VectorPointNavEnv(n, scene=scene, task=task, device=device, seed=0, sensors=sensors, **env_kwargs)
    singles = [
        PointNavEnv(
            scene=scene,
            flatten_obs=True,
            sensors=sensors,
            **env_kwargs,
            task=dict(
                task,
                initial_pos=[float(s[0]), float(s[1])],
                initial_quat=[0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)],
                goal_pos=[float(g[0]), float(g[1])],
            ),
        )
        for s, yaw, g in episodes
    ]
    to_np = venv.arrays.numpy
    vobs, _ = venv.reset(options={"episodes": episodes})
    # World i of an engine seeded with 0 keys its scan noise as a single env reset with seed i.
    sobs = np.array([env.reset(seed=i)[0] for i, env in enumerate(singles)])
    dim = sobs.shape[1]
    # Local map cells whose centre is on a cell edge or a disc's rim may round either way.
    ties = np.array([obs_ties(env, 0, sensors, dim) for env in singles])
    ended = [False] * n
    stats = {"ends": 0, "successes": 0, "contacts": 0, "autoresets": 0, "obs_diff": 0.0, "reward_diff": 0.0,
             "map_ties": 0, "falling_steps": 0}
    for t, act in enumerate(actions):
        stats["map_ties"] += assert_obs(to_np(vobs), sobs, ties, OBS_TOL, f"observations before step {t}")
        stats["obs_diff"] = max(stats["obs_diff"], float(np.where(ties, 0.0, np.abs(to_np(vobs) - sobs)).max()))
        vobs, vrew, vterm, vtrunc, vinfo = venv.step(act)
        vrew, vterm, vtrunc = to_np(vrew), to_np(vterm), to_np(vtrunc)
        vinfo = {k: to_np(v) for k, v in vinfo.items()}
        for i, env in enumerate(singles):
            if ended[i]:
                obs, _ = env.reset()
                reward, term, trunc, info = 0.0, False, False, None
                stats["autoresets"] += 1
                assert vinfo["autoreset"][i], f"world {i} should reset at step {t}"
            else:
                obs, reward, term, trunc, info = env.step(act[i])
            ended[i] = term or trunc
            sobs[i] = obs
            # The robot's height, falls over several steps included (the engine's state).
            z = float(env.backend.get_pose(0)[0][2])
            assert abs(z - float(to_np(venv.state.z)[i])) <= 1e-9, f"z world {i}, step {t}"
            stats["falling_steps"] += info is not None and z < env.task.floor_height and not term
            ties[i] = obs_ties(env, 0, sensors, dim)
            where = f"world {i}, step {t}"
            assert abs(reward - vrew[i]) <= REWARD_TOL, f"reward {where}: {reward} vs {vrew[i]}"
            stats["reward_diff"] = max(stats["reward_diff"], abs(reward - float(vrew[i])))
            assert (term, trunc) == (bool(vterm[i]), bool(vtrunc[i])), f"flags {where}"
            if info is None:
                continue
            for key in INFO_KEYS:
                ref, got = info[key], vinfo[key][i]
                assert ref == got or abs(ref - got) <= 1e-6, f"{key} {where}: {ref} vs {got}"
            stats["ends"] += term or trunc
            stats["successes"] += info["success"]
            stats["contacts"] += bool(info["collisions"]) and vinfo["in_contact"][i]
    return stats


def random_episodes(scene: Any, n: int, rng: np.random.Generator, radius: float = 0.18) -> list[tuple[Any, float, Any]]:
    """``n`` episodes with starts and goals drawn uniformly where the robot fits."""
    out = []
    for _ in range(n):
        _, start = scene.get_random_point(0, robot=radius, rng=rng)
        _, goal = scene.get_random_point(0, robot=radius, rng=rng)
        out.append((start[:2], float(rng.uniform(-math.pi, math.pi)), goal[:2]))
    return out


def random_actions(rng: np.random.Generator, shape: tuple[int, ...], drive: str = "differential") -> np.ndarray:
    """Float32 actions of ``shape + (action_dim,)`` for ``drive``: uniform in [-1.2, 1.2]
    (clipping), full speed ahead 40 % of the time (into walls and robots), and for a
    holonomic robot full speed diagonally 30 % of the time (a step of sqrt(2) times the top
    speed: the backend's two sub-steps)."""
    dim = 3 if drive == "holonomic" else 2
    actions = rng.uniform(-1.2, 1.2, (*shape, dim)).astype(np.float32)
    actions[rng.random(shape) < 0.4, 0] = 1.0
    if dim == 3:
        diagonal = rng.random(shape) < 0.3
        actions[diagonal, :2] = rng.choice([-1.0, 1.0], size=(int(diagonal.sum()), 2))
    return actions
