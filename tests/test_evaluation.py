"""``pointnav dataset generate`` and ``pointnav eval``: reproducible files, oracle results
that do not depend on the order or the number of processes, and clear errors."""

from __future__ import annotations

import csv
import dataclasses
import json

import numpy as np
import pytest
from PIL import Image

from pointnav_core.cli import main
from pointnav_core.datasets import EpisodeDataset
from pointnav_core.evaluation import evaluate, make_policy, read_results, summarize, write_results

# 9 x 7 m at 0.5 m per character: two rooms joined by a door, and a pillar.
MAP = """type octile
height 14
width 18
map
@@@@@@@@@@@@@@@@@@
@........@.......@
@........@.......@
@...@@...@.......@
@...@@...........@
@........@.......@
@........@.......@
@@@@..@@@@@@..@@@@
@................@
@................@
@.....@@@........@
@................@
@................@
@@@@@@@@@@@@@@@@@@
"""


@pytest.fixture(scope="module")
def dataset_file(tmp_path_factory):
    folder = tmp_path_factory.mktemp("scenes")
    for name in ("a", "b", "c"):
        (folder / f"{name}.map").write_text(
            MAP.replace("@@...", "@@..." if name != "b" else "@@.@.")
        )
    out = folder / "val.json.gz"
    args = [
        "dataset",
        "generate",
        "--scenes",
        str(folder),
        "--split",
        "train",
        "--episodes",
        "6",
        "--max-geodesic",
        "4",
        "--out",
        str(out),
        "--quiet",
    ]
    assert main(args) == 0
    again = folder / "again.json.gz"
    assert main([*args[:-2], str(again), "--quiet"]) == 0
    assert again.read_bytes() == out.read_bytes()  # same command, same bytes
    return out


def test_generate_flags_reach_the_rules(tmp_path, dataset_file):
    out = tmp_path / "loose.json.gz"
    args = [
        "dataset",
        "generate",
        "--scenes",
        str(dataset_file.parent),
        "--split",
        "train",
        "--episodes",
        "3",
        "--min-geodesic",
        "2",
        "--max-geodesic",
        "3",
        "--robot-radius",
        "0.2",
        "--goal-radius",
        "0.3",
        "--ratio-threshold",
        "1.0",
        "--island-radius",
        "0.5",
        "--seed",
        "4",
        "--out",
        str(out),
        "--quiet",
    ]
    assert main(args) == 0
    data = EpisodeDataset.load(out)
    assert data.metadata["generator"] == {
        "geodesic_range": [2.0, 3.0],
        "ratio_threshold": 1.0,
        "island_radius_limit": 0.5,
        "retries_per_goal": 10,
        "robot_radius": 0.2,
        "goal_radius": 0.3,
        "max_goals_per_episode": 1000,
    }
    assert data.metadata["seed"] == 4
    assert all(
        2.0 <= ep.geodesic_distance <= 3.0 and ep.robot_radius == 0.2 and ep.goal_radius == 0.3
        for ep in data
    )


def test_generated_file_loads(dataset_file):
    data = EpisodeDataset.load(dataset_file)
    assert len(data) == 6
    assert all(1.0 <= ep.geodesic_distance <= 4.0 for ep in data)
    assert data.metadata["split"] == "train"


def test_oracle_results_do_not_depend_on_order_or_workers(dataset_file):
    data = list(EpisodeDataset.load(dataset_file))
    in_order = evaluate(data, "oracle")
    assert summarize(in_order)["success"] >= 0.99
    assert all(r.collisions == 0 for r in in_order)
    shuffled = [data[i] for i in np.random.default_rng(0).permutation(len(data))]
    by_id = {r.episode_id: r for r in evaluate(shuffled, "oracle")}
    assert [by_id[r.episode_id] for r in in_order] == in_order
    assert evaluate(data, "oracle", workers=2) == in_order


def test_cli_eval_prints_and_writes(dataset_file, tmp_path, capsys):
    results, plot = tmp_path / "r.jsonl", tmp_path / "r.png"
    assert (
        main(
            [
                "eval",
                "--dataset",
                str(dataset_file),
                "--results",
                str(results),
                "--plot",
                str(plot),
                "--scenes-dir",
                str(dataset_file.parent),
                "--quiet",
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    for label in ("success", "SPL", "SoftSPL", "distance to goal", "collisions"):
        assert label in out
    rows = read_results(results)
    assert [r.episode_id for r in rows] == [str(i) for i in range(6)]
    assert f"success           {summarize(rows)['success']:.4f}" in out
    with Image.open(plot) as image:
        assert image.format == "PNG" and image.size == (720, 420)
    csv_path = tmp_path / "r.csv"
    write_results(rows, csv_path)
    with open(csv_path) as fh:
        table = list(csv.DictReader(fh))
    assert [float(row["spl"]) for row in table] == [r.spl for r in rows]


def test_module_callable_policy(dataset_file):
    data = list(EpisodeDataset.load(dataset_file))[:2]
    results = evaluate(data, "eval_policies:standstill", max_steps=5)
    assert [(r.success, r.steps, r.ended_by, r.path_length) for r in results] == [
        (False, 5, "timeout", 0.0)
    ] * 2
    assert all(r.distance_to_goal == pytest.approx(r.geodesic_distance, abs=1e-6) for r in results)


@pytest.mark.parametrize(
    "spec, match",
    [
        ("", "policy must be 'oracle'"),
        ("no_colon", "policy must be 'oracle'"),
        ("no_such_module_xyz:f", "cannot import module 'no_such_module_xyz'"),
        ("eval_policies:missing", "has no attribute 'missing'"),
        ("missing.zip", "no such SB3 .zip"),
    ],
)
def test_bad_policy(spec, match):
    with pytest.raises(ValueError, match=match):
        make_policy(spec)


def test_unknown_scene_id_names_the_episode(dataset_file, tmp_path, capsys):
    data = EpisodeDataset.load(dataset_file)
    bad = [dataclasses.replace(data[0], scene_id="castle:1")]
    with pytest.raises(
        ValueError, match=r"episode '0': field 'scene_id': unknown scene_id 'castle:1'"
    ):
        evaluate(bad)
    # (2.25, 2.25) is the pillar's square in the map: no robot stands there.
    blocked = [dataclasses.replace(data[0], start_position=(2.25, 2.25, 0.0))]
    with pytest.raises(
        ValueError,
        match=r"episode '0' \(scene 'movingai:.*\.map'\): field 'start_position' \[2.25, 2.25, 0.0\] is not valid for robot 0",
    ):
        evaluate(blocked)
    raw = data.to_json()
    raw["episodes"][1]["goals"][0]["position"] = [1.0, "2.0", 0.0]
    (tmp_path / "bad.json").write_text(json.dumps(raw))
    assert main(["eval", "--dataset", str(tmp_path / "bad.json"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert (
        "pointnav eval: error: episode '1' (index 1 of bad.json): field 'goals[0].position'" in err
    )
    assert (
        main(
            [
                "dataset",
                "generate",
                "--scenes",
                str(dataset_file.parent),
                "--split",
                "validation",
                "--episodes",
                "2",
                "--out",
                str(tmp_path / "x.json.gz"),
                "--quiet",
            ]
        )
        == 2
    )
    assert (
        "pointnav dataset generate: error: split must be one of ['train', 'val', 'test']"
        in capsys.readouterr().err
    )


def test_demo_on_a_scene_file(dataset_file, capsys):
    scene = dataset_file.parent / "a.map"
    assert main(["demo", "--scene", str(scene), "--episodes", "2", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert f"oracle on {scene}" in out and "success rate" in out


def test_sb3_zip_policy(dataset_file, tmp_path):
    sb3 = pytest.importorskip("stable_baselines3")
    from pointnav_core.env import PointNavEnv

    model = sb3.PPO(
        "MlpPolicy", PointNavEnv(flatten_obs=True), n_steps=16, batch_size=16, device="cpu", seed=0
    )
    model.save(tmp_path / "ppo.zip")
    data = list(EpisodeDataset.load(dataset_file))[:2]
    first = evaluate(data, str(tmp_path / "ppo.zip"), max_steps=10, trust_policy_file=True)
    assert [r.steps for r in first] == [10, 10] and all(r.path_length > 0 for r in first)
    assert evaluate(data[::-1], str(tmp_path / "ppo.zip"), max_steps=10, trust_policy_file=True)[::-1] == first
