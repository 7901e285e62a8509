"""Pedestrians in the batched engine (``VectorPointNavEnv(..., pedestrians={...})``).

The reference is one ``PointNavEnv`` per world, playing the world's episode and its crowd
(the world's record, :meth:`VectorCrowd.record`, or the dataset episode's): step for step
the pedestrians stand at the same places, the scans read the same, the contacts and the
episode's ends agree. The scan's sight of a pedestrian is also checked against a range to a
disc computed by hand.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from crowd_reference import world_episode
from vector_reference import random_actions

from pointnav_core.datasets import presets
from pointnav_core.datasets.format import PointNavEpisode
from pointnav_core.datasets.scene_sets import load_scene
from pointnav_core.envs.multi_pointnav import parallel_env
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.errors import ArgumentError
from pointnav_core.scenes import Scene
from pointnav_core.vector import VectorPointNavEnv
from pointnav_core.vector.social import SocialTracker

pytest.importorskip("numba")

SCAN = {"scan": {"n_rays": 16, "max_range": 4.0}}


def _house() -> Scene:
    grid = np.zeros((60, 80), np.uint8)  # 8 x 6 m, two rooms and a door
    grid[[0, -1], :] = grid[:, [0, -1]] = 1
    grid[:, 40] = 1
    grid[25:35, 40] = 0
    grid[10:14, 15:20] = 1
    return Scene.from_array(grid, 0.1)


def _play_alongside(venv: VectorPointNavEnv, singles: list[PointNavEnv], actions: np.ndarray) -> dict[str, int]:
    """Step the engine and the single envs (each reset to its world's episode, :func:`_singles`)
    until each world's first episode ends, checking every step; counts of what happened."""
    live = [True] * venv.num_envs
    seen = {"touches": 0, "ends": 0, "steps": 0, "moved": 0}
    for t, act in enumerate(actions):
        before = venv.crowd.positions.copy()
        obs, reward, term, trunc, info = venv.step(act)
        for w, env in enumerate(singles):
            if not live[w]:
                continue
            sob, srew, sterm, strunc, sinfo = env.step(act[w])
            where = f"world {w}, step {t}"
            k = env.crowd.n
            np.testing.assert_allclose(venv.crowd.positions[w, :k], env.crowd.positions, atol=1e-9, rtol=0, err_msg=where)
            np.testing.assert_allclose(venv.crowd.velocities[w, :k], env.crowd.velocities, atol=1e-9, rtol=0, err_msg=where)
            np.testing.assert_allclose(obs[w], sob, atol=1e-4, err_msg=where)
            assert abs(float(reward[w]) - srew) <= 1e-5, where
            assert (bool(term[w]), bool(trunc[w])) == (sterm, strunc), where
            assert int(info["pedestrian_collisions"][w]) == sinfo["pedestrian_collisions"], where
            seen["touches"] += int(info["pedestrian_collisions"][w] > 0)
            seen["moved"] += int(np.abs(venv.crowd.positions[w, :k] - before[w, :k]).max(initial=0.0) > 0)
            seen["steps"] += 1
            if sterm or strunc:
                live[w] = False
                seen["ends"] += 1
        if not any(live):
            break
    return seen


def _singles(obs: np.ndarray, scene: Scene | list[Scene], pedestrians: dict, task: dict, episodes: list[PointNavEpisode],
             sensors: dict = SCAN, **kwargs: object) -> list[PointNavEnv]:
    """One single env per world, reset to the world's ``episodes`` (its crowd recorded), whose
    first observations equal the engine's reset's ``obs``."""
    singles = []
    for w, episode in enumerate(episodes):
        here = scene[w % len(scene)] if isinstance(scene, list) else scene  # world w's scene
        env = PointNavEnv(scene=here, flatten_obs=True, sensors=sensors, task=task, pedestrians=pedestrians, **kwargs)
        sob, _ = env.reset(seed=w, options={"episode": episode})
        np.testing.assert_allclose(obs[w], sob, atol=1e-4, err_msg=f"world {w} at the reset")
        singles.append(env)
    return singles


@pytest.mark.parametrize("pedestrians", [
    {"count": 6, "end_on_collision": False},
    {"count": 4, "sees_robots": False, "speed": (0.8, 1.3), "end_on_collision": True},
    {"density": 0.15, "radius": 0.25},
    {"count": 5, "behaviour": "static"},
])
def test_each_world_walks_as_a_single_env(pedestrians: dict) -> None:
    scene, n = _house(), 6
    task = {"termination_config": {"max_steps": 120, "max_collisions": 50}}
    venv = VectorPointNavEnv(n, scene=scene, seed=3, sensors=SCAN, task=task, pedestrians=pedestrians, pool_size=3)
    obs, _ = venv.reset(seed=3)
    episodes = [world_episode(venv, w) for w in range(n)]
    singles = _singles(obs, scene, pedestrians, task, episodes)
    actions = random_actions(np.random.default_rng(0), (140, n))
    actions[:, :, 0] = np.abs(actions[:, :, 0])  # drive ahead, into the crowd
    seen = _play_alongside(venv, singles, actions)
    assert seen["ends"] == n  # every world's episode played to its end
    if pedestrians.get("behaviour") != "static":
        assert seen["moved"] > seen["steps"] // 2
    # The recorded crowds are what the engine placed: each pedestrian clear of the robot.
    for w, episode in enumerate(episodes):
        for ped in episode.pedestrians:
            gap = math.dist(ped.start, episode.start_position[:2]) - ped.radius - venv.robot.radius
            assert gap >= 0.0, f"world {w}: a pedestrian starts on the robot"


def test_worlds_of_several_scenes_walk_crowds_of_their_own_sizes() -> None:
    # A density gives each scene its own count: the engine's rows are the largest's.
    grid = np.zeros((40, 50), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = 1
    scenes = [_house(), Scene.from_array(grid, 0.1)]
    task = {"termination_config": {"max_steps": 60, "max_collisions": 50}}
    pedestrians = {"density": 0.2, "radius": 0.2}
    venv = VectorPointNavEnv(4, scene=scenes, seed=1, sensors=SCAN, task=task, pedestrians=pedestrians, pool_size=2)
    obs, _ = venv.reset(seed=1)
    # 0.2 a m² of free floor (0.01 m² a cell), halves up.
    assert venv.crowd.count.tolist()[:2] == [math.floor(0.2 * s.floors[0].free.sum() * 0.01 + 0.5) for s in scenes]
    assert venv.crowd.count[0] != venv.crowd.count[1]
    singles = _singles(obs, scenes, pedestrians, task, [world_episode(venv, w) for w in range(4)])
    seen = _play_alongside(venv, singles, random_actions(np.random.default_rng(2), (60, 4)))
    assert seen["ends"] == 4 and seen["moved"] > 0


def test_a_dataset_crowd_is_placed_as_recorded() -> None:
    # Circle crossing: the preset's fixed starts and goals, walked round and round.
    episodes = list(presets.dataset(["circle_crossing"], episodes_per=3, seed=1).episodes)
    scene = load_scene("preset:circle_crossing")
    pedestrians = {"count": len(episodes[0].pedestrians)}
    task = {"termination_config": {"max_steps": 80}}
    venv = VectorPointNavEnv(3, scene=scene, seed=0, sensors=SCAN, task=task, pedestrians=pedestrians)
    obs, _ = venv.reset(options={"episodes": episodes})
    for w, episode in enumerate(episodes):
        assert venv.crowd.record(w) == episode.pedestrians
        np.testing.assert_array_equal(venv.crowd.positions[w, :5], [p.start for p in episode.pedestrians])
    singles = _singles(obs, scene, pedestrians, task, episodes)
    seen = _play_alongside(venv, singles, np.tile([[0.6, 0.0]], (80, 3, 1)))
    assert seen["ends"] == 3 and seen["moved"] > 0


def test_scan_sees_a_pedestrian_at_the_hand_computed_range() -> None:
    # One pedestrian of radius 0.25 m fixed 2 m ahead of the robot, walking nowhere (static).
    grid = np.zeros((40, 60), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = 1
    scene = Scene.from_array(grid, 0.1)
    ped = {"count": 1, "behaviour": "static", "radius": 0.25, "starts": [[3.5, 2.0]], "goals": [[[3.5, 1.0]]]}
    venv = VectorPointNavEnv(1, scene=scene, seed=0, pedestrians=ped,
                             sensors={"scan": {"n_rays": 4, "max_range": 5.0}})
    obs, _ = venv.reset(options={"episodes": [((1.5, 2.0), 0.0, (5.0, 3.0))]})
    behind, ahead = obs[0, 8], obs[0, 10]  # rays at -pi and 0 (scan_angles)
    # The ray from (1.5, 2.0) along +x meets the disc centred 2 m ahead at 2 - 0.25 m.
    assert ahead == pytest.approx(1.75, abs=1e-6)
    # Behind (-x): the wall's cell edge at x = 0.1 m, 1.4 m away.
    assert behind == pytest.approx(1.4, abs=1e-6)


@pytest.mark.parametrize(("kwargs", "names"), [
    ({"pedestrians": {"count": 2, "behaviour": "social_force"}}, "pedestrians['behaviour']"),
    ({"pedestrians": {"count": 2}, "device": "cpu"}, "device='numpy'"),
    ({"pedestrians": {"density": -1.0}}, "pedestrians['density']"),
    ({"pedestrians": {"count": 2, "behavior": "orca"}}, "unknown key 'behavior'"),
])
def test_what_the_engine_cannot_walk_is_refused(kwargs: dict, names: str) -> None:
    with pytest.raises(ArgumentError, match=names.replace("[", r"\[").replace("]", r"\]")):
        VectorPointNavEnv(2, scene=_house(), **kwargs)


def test_a_recorded_crowd_needs_pedestrians() -> None:
    episodes = list(presets.dataset(["corridor"], episodes_per=1).episodes)
    venv = VectorPointNavEnv(1, scene=load_scene("preset:corridor"), seed=0)
    with pytest.raises(ArgumentError, match=r"options\['episodes'\]\[0\] records a crowd"):
        venv.reset(options={"episodes": episodes})


def _fleet_refs(venv: VectorPointNavEnv, obs: np.ndarray, scene: Scene, task: dict, pedestrians: dict,
                sensors: dict = SCAN, **kwargs: object) -> list[object]:
    """One ``parallel_env`` per world of a fleet engine (``obs`` its reset's), reset to the
    world's episodes and crowd."""
    refs = []
    for w in range(venv.num_envs):
        env = parallel_env(scene=scene, n_robots=venv.n_robots, task=task, backend="kinematic", sensors=sensors,
                           pedestrians=pedestrians, **kwargs)
        sob, _ = env.reset(seed=w, options={"episodes": [world_episode(venv, w, k) for k in range(venv.n_robots)]})
        np.testing.assert_allclose(obs[w], [sob[a] for a in env.possible_agents], atol=1e-4, err_msg=f"world {w}")
        refs.append(env)
    return refs


def _play_fleet(venv: VectorPointNavEnv, refs: list, actions: np.ndarray) -> dict[str, int]:
    """Step a fleet engine and its ``parallel_env``s until every agent is done, checking
    each acting robot every step; counts of what happened."""
    agents = refs[0].possible_agents
    seen = {"touches": 0, "ends": 0, "parked": 0}
    for t, act in enumerate(actions):
        obs, reward, term, trunc, info = venv.step(act)
        for w, env in enumerate(refs):
            if not env.agents:
                continue
            acting = list(env.agents)
            sob, srew, sterm, strunc, sinfo = env.step({a: act[w, agents.index(a)] for a in acting})
            where = f"world {w}, step {t}"
            k = env.crowd.n
            np.testing.assert_allclose(venv.crowd.positions[w, :k], env.crowd.positions, atol=1e-9, rtol=0, err_msg=where)
            seen["parked"] += len(agents) - len(acting)
            for j, a in enumerate(agents):
                if a not in acting:
                    continue
                np.testing.assert_allclose(obs[w, j], sob[a], atol=1e-4, err_msg=f"{where}, robot {j}")
                assert abs(float(reward[w, j]) - srew[a]) <= 1e-5, f"{where}, robot {j}"
                assert (bool(term[w, j]), bool(trunc[w, j])) == (sterm[a], strunc[a]), f"{where}, robot {j}"
                assert int(info["pedestrian_collisions"][w, j]) == sinfo[a]["pedestrian_collisions"], f"{where}, robot {j}"
                seen["touches"] += int(sinfo[a]["pedestrian_collisions"] > 0)
                seen["ends"] += sterm[a] or strunc[a]
        if not any(env.agents for env in refs):
            break
    return seen


@pytest.mark.parametrize(("finished", "pedestrians"), [
    ("park", {"count": 6}),
    ("remove", {"count": 5, "end_on_collision": True, "speed": (0.9, 1.3)}),
])
def test_several_robots_walk_beside_one_crowd_as_in_the_multi_robot_env(finished: str, pedestrians: dict) -> None:
    scene, n, r = _house(), 4, 3
    task = {"termination_config": {"max_steps": 90, "max_collisions": 50}}
    venv = VectorPointNavEnv(n, n_robots=r, scene=scene, seed=5, sensors=SCAN, task=task, pedestrians=pedestrians,
                             pool_size=2, finished=finished)
    obs, _ = venv.reset(seed=5)
    refs = _fleet_refs(venv, obs, scene, task, pedestrians, finished=finished)
    actions = random_actions(np.random.default_rng(1), (100, n, r))
    actions[..., 0] = np.abs(actions[..., 0])
    seen = _play_fleet(venv, refs, actions)
    assert seen["ends"] == n * r and seen["touches"] > 0 and seen["parked"] > 0


@pytest.mark.parametrize("n_robots", [1, 2])
def test_with_discrete_actions_the_crowd_walks_each_control_step(n_robots: int) -> None:
    # Habitat's actions: a forward step or a turn lasts several control steps, and ends at a
    # contact; STOP (3) lasts none. The crowd walks each control step the action lasts.
    scene, n = _house(), 4
    task = {"termination_config": {"max_steps": 40, "max_collisions": 50}}
    kwargs = {"action_space": "discrete", "discrete_actions": {"forward_step": 0.5, "turn_angle": 0.5}}
    pedestrians = {"count": 6, "speed": (0.8, 1.2)}
    venv = VectorPointNavEnv(n, n_robots=n_robots, scene=scene, seed=2, sensors=SCAN, task=task,
                             pedestrians=pedestrians, pool_size=2, **kwargs)
    obs, _ = venv.reset(seed=2)
    choices = np.random.default_rng(3).choice(4, size=(40, n, n_robots), p=[0.6, 0.15, 0.15, 0.1])
    if n_robots == 1:
        singles = _singles(obs, scene, pedestrians, task, [world_episode(venv, w) for w in range(n)], **kwargs)
        seen = _play_alongside(venv, singles, choices[..., 0])
        assert seen["ends"] == n and seen["moved"] > 0
    else:
        seen = _play_fleet(venv, _fleet_refs(venv, obs, scene, task, pedestrians, **kwargs), choices)
        assert seen["ends"] == n * n_robots


def test_a_pool_refresh_keeps_the_running_crowds_and_places_new_ones() -> None:
    task = {"termination_config": {"max_steps": 30}}
    venv = VectorPointNavEnv(3, scene=_house(), seed=4, task=task, pedestrians={"count": 4}, pool_size=2)
    venv.reset(seed=4)
    rng = np.random.default_rng(0)
    for _ in range(5):
        venv.step(rng.uniform(-1, 1, (3, 2)))
    before = [venv.crowd.record(w) for w in range(3)]
    positions = venv.crowd.positions.copy()
    venv.refresh_pool(wait=True)
    venv.step(np.zeros((3, 2)))  # the worlds walk on in their episodes, with their crowds
    assert [venv.crowd.record(w) for w in range(3)] == before
    assert np.abs(venv.crowd.positions - positions).max() > 0.0
    starts = {ped.start for record in before for ped in record}
    for _ in range(60):  # every world ends its episode and starts one of the new pool's
        venv.step(rng.uniform(-1, 1, (3, 2)))
    after = {ped.start for w in range(3) for ped in venv.crowd.record(w)}
    assert after.isdisjoint(starts)
    venv.close()


@pytest.mark.parametrize("n_robots", [1, 3])
def test_the_local_map_marks_the_pedestrians_as_the_single_env(n_robots: int) -> None:
    # Code 4 over the robots' discs (3) and the floor, with the single env's bounds.
    scene, n = _house(), 4
    sensors = {**SCAN, "local_map": {"size": 4.0, "cells": 20}}
    task = {"termination_config": {"max_steps": 50, "max_collisions": 50}}
    pedestrians = {"count": 8, "radius": (0.25, 0.35)}
    venv = VectorPointNavEnv(n, n_robots=n_robots, scene=scene, seed=6, sensors=sensors, task=task,
                             pedestrians=pedestrians, pool_size=2)
    obs, _ = venv.reset(seed=6)
    actions = random_actions(np.random.default_rng(4), (50, n, n_robots))
    if n_robots == 1:
        singles = _singles(obs, scene, pedestrians, task, [world_episode(venv, w) for w in range(n)], sensors)
        assert singles[0].observation_space == venv.single_observation_space
        _play_alongside(venv, singles, actions[..., 0, :])
    else:
        refs = _fleet_refs(venv, obs, scene, task, pedestrians, sensors)
        assert refs[0].observation_space(refs[0].possible_agents[0]) == venv.single_observation_space
        _play_fleet(venv, refs, actions)
    cells = venv.local_map.size
    assert (obs[..., -cells:] == 4).any(), "no pedestrian on any map at the reset"


def test_placing_many_crowds_shows_progress(capsys: pytest.CaptureFixture[str]) -> None:
    venv = VectorPointNavEnv(4, scene=_house(), seed=0, pedestrians={"count": 2}, pool_size=4, progress=True)
    venv.reset(seed=0)
    assert "placing crowds" in capsys.readouterr().err
    quiet = VectorPointNavEnv(4, scene=_house(), seed=0, pedestrians={"count": 2}, pool_size=4)
    quiet.reset(seed=0)  # a few crowds: no bar
    assert "placing crowds" not in capsys.readouterr().err


def _same_metrics(got: dict, want: dict, where: str) -> None:
    assert got.keys() == want.keys(), where
    for key, value in want.items():
        if value is None:
            assert got[key] is None, f"{where}: {key}"
        else:
            assert got[key] == pytest.approx(value, rel=1e-9, abs=1e-9), f"{where}: {key}"


DISCRETE = {"action_space": "discrete", "discrete_actions": {"forward_step": 0.5, "turn_angle": 0.5}}


@pytest.mark.parametrize("discrete", [False, True])
def test_the_social_tracker_gives_each_episode_the_single_envs_metrics(discrete: bool) -> None:
    # With discrete actions both sample every control step of an action (STOP: none).
    scene, n = _house(), 4
    task = {"termination_config": {"max_steps": 60 if not discrete else 25, "max_collisions": 50}}
    pedestrians, kwargs = {"count": 6}, (DISCRETE if discrete else {})
    venv = VectorPointNavEnv(n, scene=scene, seed=8, sensors=SCAN, task=task, pedestrians=pedestrians, pool_size=2,
                             **kwargs)
    tracker = SocialTracker(venv)
    obs, _ = venv.reset(seed=8)
    tracker.reset()
    singles = _singles(obs, scene, pedestrians, task, [world_episode(venv, w) for w in range(n)], **kwargs)
    rng = np.random.default_rng(5)
    if discrete:
        actions = rng.choice(4, size=(60, n), p=[0.6, 0.15, 0.15, 0.1])
    else:
        actions = random_actions(rng, (60, n))
        actions[..., 0] = np.abs(actions[..., 0])
    done = [False] * n
    for t, act in enumerate(actions):
        _, _, term, trunc, info = venv.step(act)
        ended = tracker.step(term, trunc, info)
        for w, env in enumerate(singles):
            if done[w]:
                continue
            _, _, sterm, strunc, sinfo = env.step(act[w])
            assert ((w, 0) in ended) == (sterm or strunc), f"world {w}, step {t}"
            if sterm or strunc:
                _same_metrics(ended[w, 0], sinfo["social"], f"world {w}")
                done[w] = True
    assert all(done)
    with pytest.raises(ArgumentError, match="pedestrians"):
        SocialTracker(VectorPointNavEnv(1, scene=scene))


def test_the_social_tracker_follows_several_robots_as_the_multi_robot_env() -> None:
    scene, n, r = _house(), 3, 2
    task = {"termination_config": {"max_steps": 50, "max_collisions": 50}}
    pedestrians = {"count": 5}
    venv = VectorPointNavEnv(n, n_robots=r, scene=scene, seed=9, sensors=SCAN, task=task, pedestrians=pedestrians,
                             pool_size=2)
    tracker = SocialTracker(venv)
    obs, _ = venv.reset(seed=9)
    tracker.reset()
    refs = _fleet_refs(venv, obs, scene, task, pedestrians)
    agents = refs[0].possible_agents
    seen = 0
    for act in random_actions(np.random.default_rng(6), (60, n, r)):
        _, _, term, trunc, info = venv.step(act)
        ended = tracker.step(term, trunc, info)
        for w, env in enumerate(refs):
            if not env.agents:
                continue
            _, _, sterm, strunc, sinfo = env.step({a: act[w, agents.index(a)] for a in env.agents})
            for a in sinfo:
                k = agents.index(a)
                assert ((w, k) in ended) == (sterm[a] or strunc[a])
                if sterm[a] or strunc[a]:
                    _same_metrics(ended[w, k], sinfo[a]["social"], f"world {w}, robot {k}")
                    seen += 1
    assert seen == n * r
