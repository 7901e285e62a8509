"""Scene sets: disjoint splits, folders of maps, scenes addressed by scene_id."""

from __future__ import annotations

import dataclasses
import hashlib

import numpy as np
import pytest
from PIL import Image

from pointnav_core import scenes
from pointnav_core.datasets import EpisodeDataset, GeneratorConfig, generate_split
from pointnav_core.datasets.scene_sets import (
    SCENE_SETS,
    SceneSet,
    folder_scene_set,
    generated_scene_set,
    load_scene,
    scene_set,
)

MAP = """type octile
height 6
width 8
map
@@@@@@@@
@......@
@......@
@..@@..@
@......@
@@@@@@@@
"""


def _fingerprint(scene) -> str:
    return hashlib.sha256(b"".join(f.codes.tobytes() for f in scene.floors)).hexdigest()


@pytest.mark.parametrize("name", sorted(SCENE_SETS))
def test_named_sets_never_share_a_scene_between_splits(name):
    splits = SCENE_SETS[name].splits
    assert set(splits) == {"train", "val", "test"}
    ids = [s for split in splits.values() for s in split]
    assert len(ids) == len(set(ids))
    assert all(len(split) > 0 for split in splits.values())


def test_val_and_test_houses_are_different_houses():
    houses = SCENE_SETS["houses"]
    picked = (
        list(houses.scene_ids("val")[:2])
        + list(houses.scene_ids("test")[:2])
        + [houses.scene_ids("train")[-1]]
    )
    prints = {_fingerprint(load_scene(s)) for s in picked}
    assert len(prints) == len(picked)
    # A generated scene_id builds exactly the library's generated house.
    seed = int(houses.scene_ids("val")[0].split(":")[1])
    assert _fingerprint(load_scene(f"rooms:{seed}")) == _fingerprint(scenes.rooms(seed=seed))


def test_overlapping_splits_are_rejected():
    with pytest.raises(ValueError, match="'rooms:1' is in both 'train' and 'test'"):
        SceneSet("bad", {"train": ("rooms:0", "rooms:1"), "val": (), "test": ("rooms:1",)})
    with pytest.raises(ValueError, match=r"split must be one of \['train', 'val', 'test'\]"):
        generated_scene_set("x", "rooms", (1, 1, 1)).scene_ids("validation")


@pytest.fixture
def scene_folder(tmp_path):
    for i in range(5):
        (tmp_path / f"m{i}.map").write_text(MAP)
    # An OmniGibson scene: layout/floor_trav_0.png, 0.01 m per pixel, 255 = free.
    image = np.zeros((300, 300), np.uint8)
    image[20:280, 20:280] = 255
    (tmp_path / "omni" / "layout").mkdir(parents=True)
    Image.fromarray(image).save(tmp_path / "omni" / "layout" / "floor_trav_0.png")
    (tmp_path / "notes.txt").write_text("not a scene")
    (tmp_path / "empty").mkdir()
    return tmp_path


def test_folder_set_splits_maps_and_omnigibson_scenes(scene_folder):
    found = folder_scene_set(scene_folder, seed=0)
    ids = [s for split in found.splits.values() for s in split]
    assert sorted(ids) == sorted(
        [f"movingai:{scene_folder}/m{i}.map" for i in range(5)] + [f"trav:{scene_folder}/omni"]
    )
    assert len(found.splits["val"]) >= 1 and len(found.splits["test"]) >= 1
    assert folder_scene_set(scene_folder, seed=0) == found
    assert scene_set(str(scene_folder)).splits == found.splits
    for scene_id in ids:
        scene = load_scene(scene_id)
        assert scene.n_floors == 1
    omni = load_scene(f"trav:{scene_folder}/omni")
    assert omni.is_usable(0, (0.0, 0.0), 0.18) and not omni.is_usable(0, (1.45, 0.0), 0.18)


def test_scene_ids_with_a_root_and_plain_paths(scene_folder):
    by_root = load_scene("movingai:m1.map", root=scene_folder)
    plain = load_scene(str(scene_folder / "m1.map"))
    assert _fingerprint(by_root) == _fingerprint(plain)
    png = load_scene(str(scene_folder / "omni" / "layout" / "floor_trav_0.png"))
    assert _fingerprint(png) == _fingerprint(load_scene(str(scene_folder / "omni")))


@pytest.mark.parametrize(
    "scene_id, error, match",
    [
        ("kitchen:3", ValueError, "unknown scene_id 'kitchen:3'"),
        ("rooms:abc", ValueError, "rooms: takes an integer seed"),
        ("", ValueError, "scene_id must be a non-empty string"),
        ("movingai:nowhere.map", FileNotFoundError, "no such file"),
        ("notes.txt", ValueError, "unknown scene_id 'notes.txt'"),
        ("empty", ValueError, "has no floor_trav"),
    ],
)
def test_unknown_scene_ids(scene_folder, scene_id, error, match):
    with pytest.raises(error, match=match):
        load_scene(scene_id, root=scene_folder)


def test_unknown_set_and_bad_folder(tmp_path):
    with pytest.raises(ValueError, match=r"one of \['clutter', 'houses', 'mazes'\] or a folder"):
        scene_set("castles")
    with pytest.raises(ValueError, match="holds no scene: no .map, map_server .yaml"):
        folder_scene_set(tmp_path)


def test_generate_split_spreads_episodes_and_is_reproducible(scene_folder):
    found = folder_scene_set(scene_folder, seed=0)
    config = GeneratorConfig(
        geodesic_range=(1.0, 4.0), island_radius_limit=0.5, ratio_threshold=1.0
    )
    data = generate_split(found, "train", 9, seed=3, config=config)
    assert [ep.episode_id for ep in data] == [str(i) for i in range(9)]
    counts = [sum(ep.scene_id == s for ep in data) for s in found.splits["train"]]
    assert max(counts) - min(counts) <= 1 and sum(counts) == 9
    assert data.metadata["split"] == "train" and data.metadata["seed"] == 3
    again = generate_split(found, "train", 9, seed=3, config=config)
    assert again.to_bytes() == data.to_bytes()
    assert EpisodeDataset.from_json(data.to_json()) == data
    # A scene's episodes depend on the seed and the scene only, not on the other scenes.
    first = found.splits["train"][0]
    alone = generate_split(
        SceneSet("one", {"train": (first,)}), "train", counts[0], seed=3, config=config
    )
    mine = [ep for ep in data if ep.scene_id == first]
    assert [(e.start_position, e.goal_position) for e in alone] == [
        (e.start_position, e.goal_position) for e in mine
    ]


def test_shipped_validation_dataset_regenerates_byte_identically():
    from pointnav_core.datasets import (
        SCENE_SETS,
        VALIDATION_DATASET,
        validation_dataset,
    )
    from pointnav_core.datasets.generator import generate_split

    shipped = validation_dataset()
    assert len(shipped) == 300
    assert set(shipped.scene_ids) == set(SCENE_SETS["houses"].scene_ids("val"))
    assert not set(shipped.scene_ids) & set(
        SCENE_SETS["houses"].scene_ids("train") + SCENE_SETS["houses"].scene_ids("test")
    )
    assert shipped.metadata == {
        "scene_set": "houses",
        "split": "val",
        "seed": 0,
        "generator": {**dataclasses.asdict(GeneratorConfig()), "geodesic_range": [1.0, 30.0]},
    }
    # Every scene's episodes depend on the seed and the scene only: regenerate the first
    # house's 15 episodes (the whole file takes ~10 s; the README gives its command).
    first = SCENE_SETS["houses"].scene_ids("val")[0]
    part = generate_split(SceneSet("first", {"val": (first,)}), "val", 15, seed=0)
    assert part.episodes == shipped.episodes[:15]
    assert (
        EpisodeDataset(shipped.episodes, shipped.metadata).to_bytes()
        == VALIDATION_DATASET.read_bytes()
    )
