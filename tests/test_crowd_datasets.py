"""Crowds pinned in datasets (issue 33, "Scenario presets, pinned in datasets"): an episode
records each pedestrian's start, goals, seed, radius and speed; the record round-trips in
both frames and is refused naming the field when bad; an env places exactly the recorded
crowd; ``pointnav eval`` gives the same results whatever the order and the workers; the old
dataset's bytes do not change.

Checks are against numbers written here (the recorded starts, the Habitat frame's
``(x, h, -y)``, the presets' hand-computed starts), not against the code's own helpers.
"""

from __future__ import annotations

import copy
import gzip
import json
import math
import os
import pickle
from pathlib import Path

import numpy as np
import pytest
from crowd_reference import RES, room, wall_clearance
from map_data import PILLAR_ROOM

from pointnav_core import scenes
from pointnav_core.cli import main
from pointnav_core.crowds.record import PedestrianRecord
from pointnav_core.datasets import (
    VALIDATION_DATASET,
    EpisodeDataset,
    PointNavEpisode,
    generate_episodes,
    load_scene,
)
from pointnav_core.datasets import presets as preset_data
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.errors import SamplingError
from pointnav_core.evaluation.run import evaluate

CROWD = (
    PedestrianRecord(start=(1.25, 0.75), goals=((4.5, 3.25), (0.5, 0.5)), loop=True, seed=7, radius=0.2, speed=0.8),
    PedestrianRecord(start=(4.75, 3.3), goals=(), loop=False, seed=2**53 - 1, radius=0.25, speed=1.0),
    PedestrianRecord(start=(3.1, 1.9), goals=((1.0, 3.0),), loop=False, seed=0, radius=0.3, speed=0.55),
)


def episode(pedestrians=CROWD, z: float = 0.0) -> PointNavEpisode:
    return PointNavEpisode("e1", "room", 0, (0.6, 3.4, z), (0.0, 0.0, 0.0, 1.0), (5.2, 0.6, z), 0.5, 6.0, 0.18,
                           pedestrians)


# ---------------------------------------------------------------------- the file format
@pytest.mark.parametrize("frame", ["z-up", "habitat"])
def test_the_record_round_trips_exactly_in_both_frames(frame):
    plain = PointNavEpisode("e2", "room", 0, (0.6, 3.4, 0.75), (0.0, 0.0, 0.0, 1.0), (5.2, 0.6, 0.75), None, 6.0, 0.18)
    data = EpisodeDataset([episode(z=0.75), plain])
    back = EpisodeDataset.from_json(json.loads(gzip.decompress(data.to_bytes(frame))))
    assert back == data
    assert back[0].pedestrians == CROWD and back[1].pedestrians is None
    raw = json.loads(gzip.decompress(data.to_bytes(frame)))["episodes"]
    assert "pedestrians" not in raw[1]["info"]
    first = raw[0]["info"]["pedestrians"][0]
    if frame == "habitat":  # (x, y) on a floor at h is Habitat's (x, h, -y), like start_position
        assert first["start"] == [1.25, 0.75, -0.75] and first["goals"] == [[4.5, 0.75, -3.25], [0.5, 0.75, -0.5]]
        assert raw[0]["start_position"] == [0.6, 0.75, -3.4]
    else:
        assert first["start"] == [1.25, 0.75] and first["goals"] == [[4.5, 3.25], [0.5, 0.5]]
    assert (first["seed"], first["radius"], first["speed"], first["loop"]) == (7, 0.2, 0.8, True)


def test_an_empty_crowd_is_kept_apart_from_none():
    data = EpisodeDataset([episode(pedestrians=())])
    assert EpisodeDataset.from_json(data.to_json())[0].pedestrians == ()


def test_the_shipped_dataset_without_crowds_loads_and_saves_byte_for_byte(tmp_path):
    data = EpisodeDataset.load(VALIDATION_DATASET)
    assert all(ep.pedestrians is None for ep in data)
    data.save(tmp_path / "again.json.gz")
    assert (tmp_path / "again.json.gz").read_bytes() == Path(VALIDATION_DATASET).read_bytes()


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda p: p.__setitem__("seed", True), "info.pedestrians[1].seed"),
        (lambda p: p.__setitem__("seed", "3"), "info.pedestrians[1].seed"),
        (lambda p: p.__setitem__("seed", -1), "info.pedestrians[1].seed"),
        (lambda p: p.__setitem__("seed", 2**53), "info.pedestrians[1].seed"),
        (lambda p: p.__setitem__("seed", 3.0), "info.pedestrians[1].seed"),
        (lambda p: p.__setitem__("radius", 0), "info.pedestrians[1].radius"),
        (lambda p: p.__setitem__("radius", "0.2"), "info.pedestrians[1].radius"),
        (lambda p: p.__setitem__("speed", False), "info.pedestrians[1].speed"),
        (lambda p: p.__setitem__("speed", math.inf), "info.pedestrians[1].speed"),
        (lambda p: p.__setitem__("start", [1.0]), "info.pedestrians[1].start"),
        (lambda p: p.__setitem__("start", [1.0, "2"]), "info.pedestrians[1].start[1]"),
        (lambda p: p.__setitem__("goals", [[1.0, True]]), "info.pedestrians[1].goals[0][1]"),
        (lambda p: p.__setitem__("goals", "none"), "info.pedestrians[1].goals"),
        (lambda p: p.__setitem__("loop", 1), "info.pedestrians[1].loop"),
        (lambda p: p.update(loop=True, goals=[]), "info.pedestrians[1].goals"),
        (lambda p: p.pop("seed"), "info.pedestrians[1]"),
        (lambda p: p.__setitem__("colour", "red"), "info.pedestrians[1]"),
    ],
)
def test_a_bad_record_is_refused_naming_the_episode_and_the_field(edit, field):
    raw = EpisodeDataset([episode()]).to_json()
    edit(raw["episodes"][0]["info"]["pedestrians"][1])
    with pytest.raises(ValueError, match=r"episode 'e1' \(index 0 of f.json\): field '" + field.replace("[", r"\[")
                       .replace("]", r"\]") + "'"):
        EpisodeDataset.from_json(raw, source="f.json")


@pytest.mark.parametrize("bad", [{"a": 1}, "x", None])
def test_a_crowd_that_is_not_a_list_is_refused(bad):
    raw = EpisodeDataset([episode()]).to_json()
    raw["episodes"][0]["info"]["pedestrians"] = bad
    with pytest.raises(ValueError, match=r"field 'info.pedestrians' must be a list"):
        EpisodeDataset.from_json(raw)


def test_a_habitat_point_needs_three_numbers():
    raw = EpisodeDataset([episode()]).to_json("habitat")
    raw["episodes"][0]["info"]["pedestrians"][0]["start"] = [1.0, 2.0]
    with pytest.raises(ValueError, match=r"field 'info.pedestrians\[0\].start' must be a list of 3"):
        EpisodeDataset.from_json(raw)


# ---------------------------------------------------------------------- the env
GRID = room(60, 40, boxes=0)


def room_env(**kwargs) -> PointNavEnv:
    scene = scenes.Scene.from_array(GRID, RES)
    scene.scene_id = "room"
    return PointNavEnv(scene=scene, **kwargs)


def rollout(env: PointNavEnv, steps: int) -> np.ndarray:
    out = []
    for _ in range(steps):
        env.step(np.array([0.2, 0.3]))
        out.append(env.crowd.positions.copy())
    return np.array(out)


@pytest.mark.parametrize("pedestrians", [{"count": 5, "behaviour": "orca"}, None])
def test_a_recorded_crowd_is_placed_as_recorded_and_a_pickled_copy_walks_the_same(pedestrians):
    env = room_env(pedestrians=pedestrians)
    env.reset(seed=3, options={"episode": episode()})
    np.testing.assert_array_equal(env.crowd.positions, [[1.25, 0.75], [4.75, 3.3], [3.1, 1.9]])
    np.testing.assert_array_equal(env.crowd.radius, [0.2, 0.25, 0.3])
    np.testing.assert_array_equal(env.crowd.speed, [0.8, 1.0, 0.55])
    np.testing.assert_array_equal(env.crowd.goals[[0, 2]], [[4.5, 3.25], [1.0, 3.0]])
    assert env.crowd.record() == CROWD
    twin = pickle.loads(pickle.dumps(env))
    walked = rollout(env, 120)
    np.testing.assert_array_equal(walked, rollout(twin, 120))
    assert (wall_clearance(GRID, walked.reshape(-1, 2)) >= np.tile([0.2, 0.25, 0.3], len(walked)) - 1e-9).all()
    # Another reset seed: the same crowd (it draws nothing from the env's stream).
    again = room_env(pedestrians=pedestrians)
    again.reset(seed=99, options={"episode": episode()})
    np.testing.assert_array_equal(rollout(again, 120), walked)


def test_without_pedestrians_the_crowd_lasts_the_recorded_episode_only():
    env = room_env()
    _, info = env.reset(seed=0, options={"episode": episode()})
    assert env.crowd.n == 3 and info["pedestrian_collisions"] == 0
    assert env.crowd.config.behaviour == "orca" and env.crowd.config.radius == (0.2, 0.3)  # the defaults
    _, info = env.reset(seed=0)
    assert env.crowd is None and "pedestrian_collisions" not in info


def test_a_recorded_start_in_a_wall_is_refused_naming_it():
    bad = (CROWD[0], PedestrianRecord((0.05, 0.05), (), False, 1, 0.2, 1.0))
    with pytest.raises(SamplingError, match=r"pedestrians\[1\].start"):
        room_env().reset(seed=0, options={"episode": episode(bad)})


def test_one_pedestrians_replans_do_not_shift_anothers_draws():
    """Pedestrian 0 is the same in both crowds, pedestrian 1 has another seed; they walk
    their paths without seeing each other, so pedestrian 0 must walk exactly the same."""
    def walk(seed: int) -> np.ndarray:
        crowd = (PedestrianRecord((1.0, 1.0), (), False, 11, 0.2, 1.0), PedestrianRecord((5.0, 3.0), (), False, seed, 0.2, 1.0))
        env = room_env(pedestrians={"count": 2, "behaviour": lambda view: view.preferred, "sees_robots": False})
        env.reset(seed=0, options={"episode": episode(crowd)})
        return rollout(env, 250)

    a, b = walk(1), walk(2)
    np.testing.assert_array_equal(a[:, 0], b[:, 0])
    assert not np.array_equal(a[:, 1], b[:, 1])


# ---------------------------------------------------------------------- generating
def test_generated_episodes_record_a_crowd_clear_of_the_robot_and_the_walls():
    scene = scenes.Scene.from_array(GRID, RES)
    plain = generate_episodes(scene, "room", 6, seed=4)
    crowded = generate_episodes(scene, "room", 6, seed=4, pedestrians={"count": 4, "speed": 0.7})
    assert [ep.start_position for ep in plain] == [ep.start_position for ep in crowded]
    for ep in crowded:
        starts = np.array([p.start for p in ep.pedestrians])
        radii = np.array([p.radius for p in ep.pedestrians])
        assert len(starts) == 4 and ((0.2 <= radii) & (radii <= 0.3)).all()
        assert {p.speed for p in ep.pedestrians} == {0.7}
        assert (wall_clearance(GRID, starts) >= radii).all()
        assert (np.hypot(*(starts - ep.start_xy).T) >= radii + 0.18).all()
        assert all(len(p.goals) == 1 and not p.loop for p in ep.pedestrians)
    assert generate_episodes(scene, "room", 6, seed=4, pedestrians={"count": 4, "speed": 0.7}) == crowded


def test_a_generated_crowd_is_the_one_the_env_draws():
    """The generator's crowd, replayed from its record, walks as the crowd an env with the
    same settings spawned from that record: its first goals are where the record says."""
    scene = scenes.Scene.from_array(GRID, RES)
    scene.scene_id = "room"
    ep, = generate_episodes(scene, "room", 1, seed=8, pedestrians={"count": 3})
    env = PointNavEnv(scene=scene, pedestrians={"count": 3})
    env.reset(seed=0, options={"episode": ep})
    np.testing.assert_array_equal(env.crowd.positions, [p.start for p in ep.pedestrians])
    np.testing.assert_array_equal(env.crowd.goals, [p.goals[0] for p in ep.pedestrians])


def test_presets_as_a_dataset():
    data = preset_data.dataset(["corridor", "doorway", "circle_crossing"], episodes_per=2, seed=1)
    assert [ep.episode_id for ep in data] == ["corridor_0", "corridor_1", "doorway_0", "doorway_1",
                                              "circle_crossing_0", "circle_crossing_1"]
    corridor = data[0]
    assert corridor.scene_id == "preset:corridor" and corridor.start_xy == (-6.0, 0.0)
    # The corridor's people: x = 6 - 1.5 (k // 2), lanes at -+ 2.4 / 8 = 0.3 m.
    assert [p.start for p in corridor.pedestrians] == [(6.0, -0.3), (6.0, 0.3), (4.5, -0.3), (4.5, 0.3)]
    assert all(p.loop and p.radius == 0.25 and 0.8 <= p.speed <= 1.0 for p in corridor.pedestrians)
    assert corridor.pedestrians[0].goals == ((-6.0, -0.3), (6.0, -0.3))
    assert data[0].pedestrians != data[1].pedestrians  # new seeds each episode
    circle = [p.start for p in data[4].pedestrians]
    assert all(3.0 <= math.hypot(*s) <= 5.0 for s in circle)  # 4 m, moved at most 0.5 m in x and y
    assert circle != [p.start for p in data[5].pedestrians]  # new start noise each episode
    assert preset_data.dataset(["corridor"], episodes_per=2, seed=1)[:] == data[:2]
    assert load_scene("preset:doorway").n_floors == 1
    with pytest.raises(ValueError, match="unknown preset 'igibson_density'"):
        preset_data.dataset(["igibson_density"])
    with pytest.raises(ValueError, match=r"preset: takes one of"):
        load_scene("preset:nowhere")


# ---------------------------------------------------------------------- pointnav eval
@pytest.fixture(scope="module")
def crowd_data(tmp_path_factory):
    """The pillar room and 3 episodes generated with ``--pedestrians '{"count": 3, ...}'``."""
    folder = tmp_path_factory.mktemp("crowd_room")
    (folder / "room.map").write_text(PILLAR_ROOM)
    here = os.getcwd()
    os.chdir(folder)  # scene ids relative to the folder, as the pillar room dataset's
    try:
        assert main(["dataset", "generate", "--scenes", ".", "--split", "train", "--episodes", "3",
                     "--max-geodesic", "4", "--out", "val.json.gz", "--quiet",
                     "--pedestrians", '{"count": 3, "radius": 0.15}']) == 0
    finally:
        os.chdir(here)
    return folder


def test_eval_of_recorded_crowds_is_the_same_whatever_the_order_and_workers(crowd_data):
    data = EpisodeDataset.load(crowd_data / "val.json.gz")
    assert data.metadata["pedestrians"] == {"count": 3, "radius": 0.15}
    episodes = list(data)
    assert all(len(ep.pedestrians) == 3 for ep in episodes)
    one = evaluate(episodes, "oracle", scenes_root=str(crowd_data), max_steps=80)
    two = evaluate(episodes, "oracle", scenes_root=str(crowd_data), max_steps=80, workers=2)
    backwards = evaluate(episodes[::-1], "oracle", scenes_root=str(crowd_data), max_steps=80)
    assert one == two == backwards[::-1]
    for result in one:
        assert result.pedestrian_collisions is not None and result.social is not None


@pytest.mark.parametrize("value", ["lots", "[1, 2]", '{"count": 3, "colour": 1}'])
def test_the_cli_refuses_bad_pedestrians(tmp_path, capsys, value):
    code = main(["dataset", "generate", "--scenes", "houses", "--episodes", "1", "--out", str(tmp_path / "x.json.gz"),
                 "--pedestrians", value, "--quiet"])
    assert code == 2 and "--pedestrians" in capsys.readouterr().err
    assert not (tmp_path / "x.json.gz").exists()


def test_igibson_is_a_preset_of_the_cli(tmp_path):
    folder = tmp_path
    (folder / "room.map").write_text(PILLAR_ROOM)
    here = os.getcwd()
    os.chdir(folder)
    try:
        assert main(["dataset", "generate", "--scenes", ".", "--split", "train", "--episodes", "1",
                     "--max-geodesic", "4", "--out", "i.json.gz", "--quiet", "--pedestrians", "igibson"]) == 0
    finally:
        os.chdir(here)
    ep, = EpisodeDataset.load(folder / "i.json.gz")
    free = 5.0 * 3.0 - 1.0  # the pillar room's free floor (m²): 1 pedestrian per 8 m²
    assert len(ep.pedestrians) == math.floor(free / 8.0 + 0.5)
    assert copy.deepcopy(ep) == ep


def test_the_record_of_a_crowd_the_env_drew_replays_it_step_for_step():
    drew = room_env(pedestrians={"count": 4})
    drew.reset(seed=21)
    pose, quat = drew.backend.get_pose(0)
    goal = drew.task.get_goal_pos()
    played = PointNavEpisode("d", "room", 0, tuple(map(float, pose)), tuple(map(float, quat)),
                             tuple(map(float, goal)), None, 1.0, 0.18, drew.crowd.record())
    replay = room_env(pedestrians={"count": 4})
    replay.reset(seed=5, options={"episode": played})
    np.testing.assert_array_equal(rollout(drew, 300), rollout(replay, 300))


def test_the_multi_robot_env_places_the_first_robots_recorded_crowd():
    from pointnav_core.envs.multi_pointnav import MultiPointNavEnv

    scene = scenes.Scene.from_array(GRID, RES)
    scene.scene_id = "room"
    other = PointNavEpisode("e2", "room", 0, (5.4, 2.0, 0.0), (0.0, 0.0, 0.0, 1.0), (0.6, 1.0, 0.0), 0.5, 5.0, 0.18)
    env = MultiPointNavEnv(scene=scene, n_robots=2, pedestrians={"count": 6})
    env.reset(seed=1, options={"episodes": [episode(), other]})
    np.testing.assert_array_equal(env.crowd.positions, [[1.25, 0.75], [4.75, 3.3], [3.1, 1.9]])
    env.reset(seed=1)
    assert env.crowd.n == 6


def test_the_multi_robot_env_without_pedestrians_walks_a_recorded_crowd_for_that_episode_only():
    from pointnav_core.envs.multi_pointnav import MultiPointNavEnv

    scene = scenes.Scene.from_array(GRID, RES)
    scene.scene_id = "room"
    other = PointNavEpisode("e2", "room", 0, (5.4, 2.0, 0.0), (0.0, 0.0, 0.0, 1.0), (0.6, 1.0, 0.0), 0.5, 5.0, 0.18)
    env = MultiPointNavEnv(scene=scene, n_robots=2)
    _, infos = env.reset(seed=1, options={"episodes": [episode(), other]})
    np.testing.assert_array_equal(env.crowd.positions, [[1.25, 0.75], [4.75, 3.3], [3.1, 1.9]])
    assert env.crowd.config.behaviour == "orca" and env.crowd.config.radius == (0.2, 0.3)  # the defaults
    assert all(info["pedestrian_collisions"] == 0 for info in infos.values())
    before = env.crowd.positions.copy()
    env.step({agent: np.zeros(2, dtype=np.float32) for agent in env.agents})
    assert not np.array_equal(env.crowd.positions, before)  # it walks
    _, infos = env.reset(seed=1)
    assert env.crowd is None and all("pedestrian_collisions" not in info for info in infos.values())
