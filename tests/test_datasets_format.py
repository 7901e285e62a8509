"""Episode dataset files: round trips, reproducible bytes, Habitat's frame, clear errors."""

from __future__ import annotations

import copy
import gzip
import json
import math

import pytest

from pointnav_core.datasets.format import (
    EpisodeDataset,
    PointNavEpisode,
    from_habitat_position,
    to_habitat_position,
    to_habitat_rotation,
)


def _episode(i: int, yaw: float = 0.7) -> PointNavEpisode:
    return PointNavEpisode(
        episode_id=str(i),
        scene_id="rooms:3",
        floor=0,
        start_position=(1.25 + i, -2.5, 0.0),
        start_rotation=(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)),
        goal_position=(4.0, 3.1 + 0.1 * i, 0.0),
        goal_radius=0.5,
        geodesic_distance=7.123456789012345,
        robot_radius=0.18,
    )


@pytest.fixture
def dataset() -> EpisodeDataset:
    return EpisodeDataset([_episode(i, yaw=0.3 * i - 1.0) for i in range(5)], {"split": "val"})


def test_file_round_trips_exactly(tmp_path, dataset):
    path = tmp_path / "val.json.gz"
    dataset.save(path)
    loaded = EpisodeDataset.load(path)
    assert loaded == dataset
    assert loaded.metadata == {"split": "val"}
    # And the bytes written again are the same bytes.
    loaded.save(tmp_path / "again.json.gz")
    assert (tmp_path / "again.json.gz").read_bytes() == path.read_bytes()


def test_bytes_are_reproducible_gzip_without_mtime(dataset):
    data = dataset.to_bytes()
    assert data == EpisodeDataset(list(dataset), {"split": "val"}).to_bytes()
    # gzip header bytes 4..8 are the mtime: written as 0, so the file does not depend on when.
    assert data[4:8] == b"\x00\x00\x00\x00"
    text = gzip.decompress(data).decode()
    assert text == json.dumps(json.loads(text), sort_keys=True, separators=(",", ":"))


def test_file_has_habitat_keys(dataset):
    raw = json.loads(gzip.decompress(dataset.to_bytes()))
    ep = raw["episodes"][0]
    assert set(ep) == {
        "episode_id",
        "scene_id",
        "start_position",
        "start_rotation",
        "goals",
        "info",
    }
    assert set(ep["goals"][0]) == {"position", "radius"}
    assert set(ep["info"]) == {"geodesic_distance", "floor", "robot_radius"}
    assert raw["pointnav_core"]["frame"] == "z-up"


def test_habitat_frame_axis_mapping():
    # Ours: z up. Habitat: y up, the agent looks along -z.
    assert to_habitat_position((1.0, 2.0, 3.0)) == (1.0, 3.0, -2.0)
    assert from_habitat_position((1.0, 3.0, -2.0)) == (1.0, 2.0, 3.0)
    for yaw, habitat_forward in ((0.0, (1.0, 0.0, 0.0)), (math.pi / 2, (0.0, 0.0, -1.0))):
        # Rotate Habitat's forward (0, 0, -1) by the stored quaternion about +y.
        _, qy, _, qw = to_habitat_rotation(yaw)
        angle = 2 * math.atan2(qy, qw)
        forward = (-math.sin(angle), 0.0, -math.cos(angle))
        assert forward == pytest.approx(habitat_forward, abs=1e-12)
        # ... which is our heading mapped into Habitat's frame.
        ours = (math.cos(yaw), math.sin(yaw), 0.0)
        assert to_habitat_position(ours) == pytest.approx(forward, abs=1e-12)


def test_habitat_frame_file_reads_back_into_ours(tmp_path, dataset):
    path = tmp_path / "habitat.json.gz"
    dataset.save(path, frame="habitat")
    raw = json.loads(gzip.decompress(path.read_bytes()))
    assert raw["pointnav_core"]["frame"] == "habitat"
    assert raw["episodes"][0]["start_position"] == [1.25, 0.0, 2.5]
    loaded = EpisodeDataset.load(path)
    for a, b in zip(loaded, dataset):
        assert a.start_position == b.start_position and a.goal_position == b.goal_position
        assert a.start_yaw == pytest.approx(b.start_yaw, abs=1e-12)
    # A plain Habitat file (no pointnav_core block) is read as y-up.
    del raw["pointnav_core"]
    assert EpisodeDataset.from_json(raw)[0].start_position == dataset[0].start_position


def test_plain_json_path(tmp_path, dataset):
    dataset.save(tmp_path / "val.json")
    assert json.loads((tmp_path / "val.json").read_text())["episodes"][0]["episode_id"] == "0"
    assert EpisodeDataset.load(tmp_path / "val.json") == dataset


def _raw(dataset: EpisodeDataset) -> dict:
    return copy.deepcopy(dataset.to_json())


@pytest.mark.parametrize(
    "edit, field",
    [
        (lambda ep: ep.update(start_position=[1.0, 2.0]), "start_position"),
        (lambda ep: ep.update(start_position=[1.0, "2", 0.0]), "start_position"),
        (lambda ep: ep.update(start_position=[True, 2.0, 0.0]), "start_position"),
        (lambda ep: ep.update(start_position=[float("nan"), 2.0, 0.0]), "start_position"),
        (lambda ep: ep.pop("start_position"), "start_position"),
        (lambda ep: ep.update(start_rotation=[0.0, 0.0, 0.0, 2.0]), "start_rotation"),
        (lambda ep: ep.update(start_rotation=[1.0, 0.0, 0.0, 0.0]), "start_rotation"),
        (lambda ep: ep.update(goals=[]), "goals"),
        (lambda ep: ep["goals"][0].update(position=[0.0, 0.0, None]), "goals[0].position"),
        (lambda ep: ep["goals"][0].update(radius=-1.0), "goals[0].radius"),
        (lambda ep: ep["goals"][0].update(radius="0.5"), "goals[0].radius"),
        (lambda ep: ep["info"].update(geodesic_distance=True), "info.geodesic_distance"),
        (lambda ep: ep["info"].pop("geodesic_distance"), "info.geodesic_distance"),
        (lambda ep: ep["info"].update(floor=1.0), "info.floor"),
        (lambda ep: ep["info"].update(floor=False), "info.floor"),
        (lambda ep: ep["info"].update(robot_radius=-0.1), "info.robot_radius"),
        (lambda ep: ep.update(info=None), "info"),
        (lambda ep: ep.update(scene_id=""), "scene_id"),
        (lambda ep: ep.update(episode_id=3), "episode_id"),
    ],
)
def test_malformed_episode_names_episode_and_field(dataset, edit, field):
    raw = _raw(dataset)
    edit(raw["episodes"][2])
    with pytest.raises(ValueError) as err:
        EpisodeDataset.from_json(raw, source="val.json.gz")
    message = str(err.value)
    assert f"field '{field}'" in message
    assert "index 2 of val.json.gz" in message
    if field != "episode_id":
        assert "episode '2'" in message


def test_duplicate_ids_and_bad_files(tmp_path, dataset):
    raw = _raw(dataset)
    raw["episodes"][3]["episode_id"] = "1"
    with pytest.raises(
        ValueError, match=r"episode '1' \(index 3\): field 'episode_id' must be unique"
    ):
        EpisodeDataset.from_json(raw)
    with pytest.raises(ValueError, match="'episodes' list"):
        EpisodeDataset.from_json({"episodes": {}})
    with pytest.raises(ValueError, match="frame"):
        EpisodeDataset.from_json({"episodes": [], "pointnav_core": {"frame": "x-up"}})
    (tmp_path / "bad.json.gz").write_bytes(gzip.compress(b"{not json"))
    with pytest.raises(ValueError, match="bad.json.gz is not a JSON dataset"):
        EpisodeDataset.load(tmp_path / "bad.json.gz")
    with pytest.raises(ValueError, match="frame must be one of"):
        dataset.to_json("y-up")
