"""A folder mixing a ROS map, a MovingAI map and a ProcTHOR house, end to end: the demo on a
map.yaml, ``dataset generate --scenes DIR`` and the oracle's evaluation of the result."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from test_floorplan_files import two_room_house

from pointnav_core.cli import main
from pointnav_core.datasets import EpisodeDataset, scene_set
from pointnav_core.evaluation.report import summarize
from pointnav_core.evaluation.run import evaluate

DATA = Path(__file__).parent / "data"
FOREST = "type octile\nheight 12\nwidth 16\nmap\n" + "\n".join(
    "".join("T" if (3 * i + 5 * j) % 11 == 0 and 0 < i < 11 else "." for j in range(16)) for i in range(12)
) + "\n"


@pytest.fixture(scope="module")
def mixed(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("mixed")
    for suffix in (".yaml", ".pgm"):
        shutil.copy(DATA / "nav2_maps" / f"tb3_sandbox{suffix}", folder)
    (folder / "forest.map").write_text(FOREST)
    (folder / "house.json").write_text(json.dumps(two_room_house()))
    return folder


def test_demo_runs_on_a_map_yaml(capsys):
    assert main(["demo", "--scene", str(DATA / "nav2_maps" / "tb3_sandbox.yaml"), "--episodes", "2", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "tb3_sandbox.yaml" in out and "success rate          1.000" in out


def test_a_mixed_folder_generates_a_dataset_the_oracle_solves(mixed, tmp_path, capsys):
    # Three scenes: one per split, each of a different kind.
    ids = scene_set(str(mixed), seed=1).splits
    kinds = sorted(i.split(":")[0] for split in ids.values() for i in split)
    assert kinds == ["movingai", "procthor", "ros"]
    out = tmp_path / "mixed.json.gz"
    for split in ("train", "val", "test"):
        argv = ["dataset", "generate", "--scenes", str(mixed), "--split", split, "--episodes", "3",
                "--out", str(out.with_name(f"{split}.json.gz")), "--seed", "1", "--quiet"]
        assert main(argv) == 0
    episodes = []
    for split in ("train", "val", "test"):
        episodes += list(EpisodeDataset.load(out.with_name(f"{split}.json.gz")))
    assert {e.scene_id.split(":")[0] for e in episodes} == {"movingai", "procthor", "ros"}
    summary = summarize(evaluate(episodes, "oracle", max_steps=500))
    assert summary["episodes"] == len(episodes) and summary["success"] >= 0.99
