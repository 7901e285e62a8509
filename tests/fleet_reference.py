"""The reference for several robots per world: one PettingZoo ``MultiPointNavEnv`` per world.

:func:`compare_fleet` plays the same fixed episodes and actions on a ``VectorPointNavEnv``
with ``n_robots`` robots and on ``num_envs`` separate ``parallel_env``s (kinematic
backend), resetting a parallel env the step after its last agent left (the batched
engine's next-step autoreset), and fails at the first step where they disagree beyond
the tolerances of issue 14.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from local_map_reference import assert_obs, obs_ties

from pointnav_core.envs.multi_pointnav import parallel_env
from pointnav_core.vector import VectorPointNavEnv

OBS_TOL = 1e-4
REWARD_TOL = 1e-5
INFO_KEYS = ("success", "spl", "soft_spl", "collisions", "episode_length", "path_length", "distance_to_goal")


def _fixed_task(task: dict, start: Any, yaw: float, goal: Any) -> dict:
    return dict(
        task,
        initial_pos=[float(start[0]), float(start[1])],
        initial_quat=[0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)],
        goal_pos=[float(goal[0]), float(goal[1])],
    )


def compare_fleet(
    scene: Any,
    episodes: list[list[tuple[Any, float, Any]]],
    actions: np.ndarray,
    task: dict | list[dict] | None = None,
    device: str = "numpy",
    finished: str = "park",
    max_cycles: int = 500,
    sensors: dict | None = None,
    robot: Any = None,
    action_space: str = "continuous",
    discrete_actions: dict | None = None,
) -> dict[str, Any]:
    """Step both for ``len(actions)`` steps; return counts of what happened.

    ``episodes`` holds, per world, one ``(start_xy, yaw, goal_xy)`` per robot; ``actions``
    has shape ``(steps, num_envs, n_robots, 2)``, or ``(steps, num_envs, n_robots)`` of
    ints with ``action_space="discrete"`` (and ``discrete_actions``, both sides).
    ``sensors`` (both sides) adds the scan to the flat observations compared. ``task`` and
    ``robot`` (both sides) may be lists with one entry per robot.
    """
    n, r = len(episodes), len(episodes[0])
    tasks = [dict(t or {}) for t in task] if isinstance(task, list) else [dict(task or {})] * r
    venv = VectorPointNavEnv(n, n_robots=r, scene=scene, task=task, device=device, seed=0, pool_size=1,
                             finished=finished, max_cycles=max_cycles, sensors=sensors, robot=robot,
                             action_space=action_space, discrete_actions=discrete_actions)
    dim = venv.single_observation_space.shape[0]
    refs = [
        parallel_env(scene=scene, n_robots=r, task=[_fixed_task(t, *rb) for t, rb in zip(tasks, world)],
                     backend="kinematic", finished=finished, max_cycles=max_cycles, sensors=sensors, robot=robot,
                     action_space=action_space, discrete_actions=discrete_actions)
        for world in episodes
    ]
    agents = refs[0].possible_agents
    to_np = venv.arrays.numpy
    vobs, vinfo = venv.reset(options={"episodes": episodes})
    sobs = np.zeros((n, r, dim), np.float32)
    # Local map cells whose centre is on a cell edge or a disc's rim may round either way.
    ties = np.zeros((n, r, dim), bool)
    for i, env in enumerate(refs):
        obs, _ = env.reset(seed=i)  # world i of an engine seeded with 0: the scan noise's seed i
        sobs[i] = [obs[a] for a in agents]
        ties[i] = [obs_ties(env, k, sensors, dim) for k in range(r)]
    stats = {"ends": 0, "successes": 0, "contacts": 0, "autoresets": 0, "robot_contacts": 0, "parked_steps": 0,
             "falls": 0, "stops": 0, "map_ties": 0, "falling_steps": 0}
    assert to_np(vinfo["active"]).all()
    for t, act in enumerate(actions):
        stats["map_ties"] += assert_obs(to_np(vobs), sobs, ties, OBS_TOL, f"observations before step {t}")
        vobs, vrew, vterm, vtrunc, vinfo = venv.step(act)
        vrew, vterm, vtrunc, vobs_np = to_np(vrew), to_np(vterm), to_np(vtrunc), to_np(vobs)
        vinfo = {k: to_np(v) for k, v in vinfo.items()}
        sobs = np.zeros((n, r, dim), np.float32)
        ties = np.zeros((n, r, dim), bool)
        for i, env in enumerate(refs):
            where = f"world {i}, step {t}"
            if not env.agents:
                obs, _ = env.reset()
                sobs[i] = [obs[a] for a in agents]
                ties[i] = [obs_ties(env, k, sensors, dim) for k in range(r)]
                stats["autoresets"] += 1
                assert vinfo["autoreset"][i].all(), f"{where}: should autoreset"
                assert (vrew[i] == 0.0).all() and not vterm[i].any() and not vtrunc[i].any(), where
                assert vinfo["active"][i].all(), where
                continue
            assert not vinfo["autoreset"][i].any(), f"{where}: should not autoreset"
            acting = list(env.agents)
            stats["parked_steps"] += r - len(acting)
            obs, rew, term, trunc, info = env.step({a: act[i, agents.index(a)] for a in acting})
            for k, a in enumerate(agents):
                if a not in acting:  # not an agent since an earlier step: zero and False
                    assert vrew[i, k] == 0.0 and not vterm[i, k] and not vtrunc[i, k], f"{where}, robot {k}"
                    assert not vinfo["active"][i, k] and (vobs_np[i, k] == 0.0).all(), f"{where}, robot {k}"
                    assert vinfo["episode_length"][i, k] == 0 and not vinfo["success"][i, k], f"{where}, robot {k}"
                    continue
                sobs[i, k] = obs[a]
                ties[i, k] = obs_ties(env, k, sensors, dim)
                assert abs(rew[a] - vrew[i, k]) <= REWARD_TOL, f"reward {where}, robot {k}: {rew[a]} vs {vrew[i, k]}"
                assert (term[a], trunc[a]) == (bool(vterm[i, k]), bool(vtrunc[i, k])), f"flags {where}, robot {k}"
                assert (a in env.agents) == bool(vinfo["active"][i, k]), f"active {where}, robot {k}"
                for key in INFO_KEYS:
                    ref, got = info[a][key], vinfo[key][i, k]
                    assert ref == got or abs(ref - got) <= 1e-6, f"{key} {where}, robot {k}: {ref} vs {got}"
                stats["ends"] += term[a] or trunc[a]
                stats["stops"] += action_space == "discrete" and bool(term[a]) and int(act[i, k]) == 3
                stats["successes"] += info[a]["success"]
                stats["contacts"] += bool(vinfo["in_contact"][i, k])
                stats["robot_contacts"] += bool(vinfo["in_contact"][i, k]) and _touches_robot(env, k)
                stats["falls"] += bool(term[a]) and env.backend.get_pose(k)[0][2] < env.tasks[k].floor_height
                stats["falling_steps"] += not term[a] and env.backend.get_pose(k)[0][2] < env.tasks[k].floor_height
            # Every robot's height, falls over several steps included (parked falling robots too).
            z = np.array([env.backend.get_pose(k)[0][2] for k in range(r)])
            np.testing.assert_allclose(to_np(venv.state.z)[i], z, rtol=0, atol=1e-9, err_msg=f"z {where}")
    return stats


def _touches_robot(env: Any, k: int) -> bool:
    """Whether robot ``k`` of the reference env touches another robot in the world."""
    backend = env.backend
    pk = backend.get_pose(k)[0]
    return any(
        j != k and backend.is_present(j)
        and math.dist(pk[:2], backend.get_pose(j)[0][:2]) <= env.robots[k].radius + env.robots[j].radius + 1e-6
        for j in range(len(env.robots))
    )


def fleet_episodes(
    scene: Any, n_worlds: int, n_robots: int, rng: np.random.Generator, radius: float = 0.18, goal_gap: float = 0.4,
    at_start: float = 0.0,
) -> list[list[tuple[Any, float, Any]]]:
    """Random fixed episodes: starts where the robot fits, at least two radii apart; goals
    at least ``goal_gap`` m apart (the multi-robot env's separation for the task used).
    With probability ``at_start`` a robot's goal is its start instead, where that keeps
    the goals apart (so that STOP can succeed at once)."""
    def apart(gap: float) -> list[Any]:
        points: list[Any] = []
        for _ in range(10_000):  # rejection sampling; a scene with room for the robots ends early
            _, p = scene.get_random_point(0, robot=radius, rng=rng)
            if all(math.dist(p[:2], q) >= gap for q in points):
                points.append(p[:2])
                if len(points) == n_robots:
                    return points
        raise AssertionError(f"no room for {n_robots} robots {gap} m apart")

    worlds = []
    for _ in range(n_worlds):
        starts, goals = apart(2 * radius), apart(goal_gap)
        for k, start in enumerate(starts):
            others = goals[:k] + goals[k + 1 :]
            if rng.random() < at_start and all(math.dist(start, q) >= goal_gap for q in others):
                goals[k] = start
        worlds.append([(s, float(rng.uniform(-math.pi, math.pi)), g) for s, g in zip(starts, goals)])
    return worlds
