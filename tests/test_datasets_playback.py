"""Both environments play dataset episodes, in order or shuffled; bad episodes are named."""

from __future__ import annotations

import dataclasses
import math
import subprocess
import sys

import numpy as np
import pytest

from pointnav_core import Scene
from pointnav_core.datasets import EpisodeDataset, GeneratorConfig, generate_episodes
from pointnav_core.datasets.playback import EpisodeSchedule, episode_seed
from pointnav_core.envs.multi_pointnav import MultiPointNavEnv
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.transforms import quat2yaw

RES = 0.1


@pytest.fixture(scope="module")
def scene() -> Scene:
    free = np.zeros((50, 70), bool)
    free[1:49, 1:69] = True
    free[20:30, 30:34] = False
    return Scene.from_array(free, RES)


@pytest.fixture(scope="module")
def dataset(scene) -> EpisodeDataset:
    config = GeneratorConfig(
        geodesic_range=(1.0, 5.0), ratio_threshold=1.0, island_radius_limit=1.0
    )
    return EpisodeDataset(generate_episodes(scene, "box", 12, seed=0, config=config))


def test_single_env_plays_the_episode(scene, dataset):
    env = PointNavEnv(scene=scene)
    for ep in list(dataset)[:4]:
        _, info = env.reset(seed=1, options={"episode": ep})
        pos, quat = env.backend.get_pose(0)
        assert tuple(pos[:2]) == ep.start_xy
        assert math.isclose(float(quat2yaw(quat)), ep.start_yaw, abs_tol=1e-9)
        assert tuple(env.task.get_goal_pos()[:2]) == ep.goal_xy
        assert abs(info["geodesic_dist"] - ep.geodesic_distance) <= 1e-6
    # Without an episode the env samples as before.
    _, info = env.reset(seed=1)
    assert tuple(env.task.get_goal_pos()[:2]) not in {ep.goal_xy for ep in dataset}


def test_schedule_in_order_and_shuffled(dataset):
    ids = [ep.episode_id for ep in dataset]
    assert [ep.episode_id for ep in EpisodeSchedule(dataset).take(2 * len(ids))] == ids + ids
    first = [
        ep.episode_id for ep in EpisodeSchedule(dataset, shuffle=True, seed=3).take(2 * len(ids))
    ]
    again = [
        ep.episode_id for ep in EpisodeSchedule(dataset, shuffle=True, seed=3).take(2 * len(ids))
    ]
    assert first == again
    assert sorted(first[: len(ids)]) == sorted(ids) == sorted(first[len(ids) :])
    assert first[: len(ids)] != ids and first[: len(ids)] != first[len(ids) :]
    with pytest.raises(ValueError, match="no episodes for scene_id 'elsewhere'"):
        EpisodeSchedule(dataset, scene_id="elsewhere")
    with pytest.raises(ValueError, match="shuffle must be True or False"):
        EpisodeSchedule(dataset, shuffle="yes")


def test_episode_seed_depends_on_the_episode_only(dataset):
    seeds = [episode_seed(ep) for ep in dataset]
    assert len(set(seeds)) == len(seeds)
    assert episode_seed(dataset[3]) == episode_seed(
        dataclasses.replace(dataset[3], start_position=(0.0, 0.0, 0.0))
    )
    assert all(0 <= s < 2**63 for s in seeds)


def test_start_not_valid_for_the_robot_names_episode_and_field(scene, dataset):
    env = PointNavEnv(scene=scene, robot={"radius": 0.6})
    bad = next(ep for ep in dataset if not scene.is_usable(0, ep.start_xy, 0.6))
    with pytest.raises(
        ValueError,
        match=rf"episode '{bad.episode_id}' \(scene 'box'\): field 'start_position' .* not valid for robot 0 \(radius 0.6 m\)",
    ):
        env.reset(options={"episode": bad})
    blocked_goal = dataclasses.replace(dataset[0], goal_position=(3.15, 2.5, 0.0))
    env = PointNavEnv(scene=scene)
    with pytest.raises(ValueError, match=r"field 'goals\[0\].position'"):
        env.reset(options={"episode": blocked_goal})
    with pytest.raises(
        ValueError, match=r"field 'info.floor' is 1, but robot 0's task navigates floor 0"
    ):
        env.reset(options={"episode": dataclasses.replace(dataset[0], floor=1)})
    with pytest.raises(ValueError, match=r"field 'start_position' has z = 0.5 m"):
        env.reset(
            options={
                "episode": dataclasses.replace(
                    dataset[0], start_position=(*dataset[0].start_xy, 0.5)
                )
            }
        )
    with pytest.raises(ValueError, match="episode must be a PointNavEpisode"):
        env.reset(options={"episode": {"start": (1, 1)}})
    # The env recovers: a good episode plays after a bad one.
    env.reset(options={"episode": dataset[0]})


def test_multi_robot_env_plays_one_episode_per_robot(scene, dataset):
    env = MultiPointNavEnv(scene=scene, n_robots=2)
    far_apart = [dataset[0]] + [
        ep for ep in dataset if math.dist(ep.start_xy, dataset[0].start_xy) > 1.0
    ][:1]
    _, infos = env.reset(seed=0, options={"episodes": far_apart})
    for i, ep in enumerate(far_apart):
        assert tuple(env.backend.get_pose(i)[0][:2]) == ep.start_xy
        assert tuple(env.tasks[i].get_goal_pos()[:2]) == ep.goal_xy
        assert abs(infos[f"robot_{i}"]["geodesic_dist"] - ep.geodesic_distance) <= 1e-6
    _, infos = env.reset(seed=0, options={"episodes": {"robot_1": far_apart[0]}})
    assert tuple(env.backend.get_pose(1)[0][:2]) == far_apart[0].start_xy
    with pytest.raises(ValueError, match=r"one episode per robot \(2\), got 1"):
        env.reset(options={"episodes": far_apart[:1]})
    with pytest.raises(ValueError, match="unknown agent 'robot_7'"):
        env.reset(options={"episodes": {"robot_7": far_apart[0]}})
    same = dataclasses.replace(far_apart[0], episode_id="twin")
    with pytest.raises(ValueError, match=r"episode '(twin|0)': field 'start_position'"):
        env.reset(options={"episodes": [far_apart[0], same]})


def test_datasets_load_no_env_library():
    code = (
        "import sys, pointnav_core.datasets, pointnav_core.datasets.playback\n"
        "print(sorted(m for m in ('gymnasium', 'pettingzoo', 'PIL') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"


def test_wrappers_play_the_schedule_at_every_reset(scene, dataset):
    from pointnav_core.envs.dataset_wrappers import (
        DatasetEpisodes,
        ParallelDatasetEpisodes,
    )

    env = DatasetEpisodes(PointNavEnv(scene=scene, flatten_obs=True), dataset, shuffle=True, seed=5)
    expected = EpisodeSchedule(dataset, shuffle=True, seed=5).take(2 * len(dataset))
    for ep in expected:
        _, info = env.reset()
        assert env.episode is ep
        assert tuple(env.unwrapped.backend.get_pose(0)[0][:2]) == ep.start_xy
        assert abs(info["geodesic_dist"] - ep.geodesic_distance) <= 1e-6
    env.reset(options={"episode": dataset[1]})
    assert tuple(env.unwrapped.task.get_goal_pos()[:2]) == dataset[1].goal_xy
    obs, *_ = env.step(env.action_space.sample())
    assert env.observation_space.contains(obs)

    far = [dataset[0]] + [
        ep for ep in dataset if math.dist(ep.start_xy, dataset[0].start_xy) > 1.0
    ][:1]
    multi = ParallelDatasetEpisodes(MultiPointNavEnv(scene=scene, n_robots=2), far)
    _, infos = multi.reset(seed=0)
    assert [e.episode_id for e in multi.episodes] == [far[0].episode_id, far[1].episode_id]
    assert abs(infos["robot_1"]["geodesic_dist"] - far[1].geodesic_distance) <= 1e-6
    assert multi.agents == ["robot_0", "robot_1"]


def test_dataset_env_builds_the_scene_robot_and_floor(tmp_path):
    from pointnav_core.envs.dataset_wrappers import dataset_env

    map_path = tmp_path / "room.map"
    map_path.write_text(
        "type octile\nheight 8\nwidth 8\nmap\n"
        + "\n".join(["@" * 8] + ["@......@"] * 6 + ["@" * 8])
        + "\n"
    )
    config = GeneratorConfig(
        geodesic_range=(1.0, 3.0), ratio_threshold=1.0, island_radius_limit=0.5, robot_radius=0.25
    )
    scene_id = f"movingai:{map_path}"
    from pointnav_core.datasets import load_scene

    eps = generate_episodes(load_scene(scene_id), scene_id, 3, seed=0, config=config)
    env = dataset_env(eps, scene_id)
    assert env.unwrapped.robot.radius == 0.25
    _, info = env.reset(seed=0)
    assert env.episode is eps[0] and abs(info["geodesic_dist"] - eps[0].geodesic_distance) <= 1e-6
    with pytest.raises(ValueError, match="no episode has scene_id 'rooms:1'"):
        dataset_env(eps, "rooms:1")
    mixed = [eps[0], dataclasses.replace(eps[1], robot_radius=0.1)]
    with pytest.raises(ValueError, match=r"differ in field 'info.robot_radius' \(\[0.1, 0.25\]\)"):
        dataset_env(mixed, scene_id)
