"""The shipped baseline: ``pointnav eval --policy baseline:scan-ppo``.

The checkpoint ships in the package (``pointnav_core/policies/baselines``); these tests
hold that it loads by name, carries the env config of its recipe
(``examples/train_scan.yaml``), stays small, and that ``pointnav eval`` plays it as it plays
the file itself and records that file. Its figures on the full validation set are the
README's, measured by the command given there (minutes, not a unit test).
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import pytest

pytest.importorskip("torch")

from pointnav_core.cli import main
from pointnav_core.datasets import VALIDATION_DATASET
from pointnav_core.evaluation.policy_specs import make_policy
from pointnav_core.policies.baselines import baseline_path, names
from pointnav_core.policies.checkpoint import load_checkpoint


def test_the_scan_baseline_ships_small_and_carries_its_recipes_env(monkeypatch) -> None:
    from pointnav_core.training.config import TrainConfig

    assert "scan-ppo" in names()
    path = baseline_path("scan-ppo")
    assert os.path.getsize(path) < 1 << 20  # the bound: under 1 MB
    checkpoint = load_checkpoint(path)
    # What the README says it is: a 64-ray scan to 12 m, the polar goal, discrete actions without STOP,
    # acting by draws; and the env that examples/train_scan.yaml (its recipe) trains with.
    assert checkpoint.env_config.sensors == {"scan": {"n_rays": 64, "max_range": 12.0}}
    assert checkpoint.env_config.discrete_actions == {"stop": False} and checkpoint.actions == "sampled"
    root = Path(__file__).resolve().parents[1]
    monkeypatch.chdir(root)
    recipe = TrainConfig.load(root / "examples" / "train_scan.yaml")
    assert checkpoint.env_config == recipe.policy_config()
    assert checkpoint.step <= recipe.ppo.total_steps


def test_an_unknown_baseline_is_refused_naming_the_shipped_ones(capsys) -> None:
    with pytest.raises(ValueError, match=r"unknown baseline 'scan-sac': the shipped baselines are \['scan-ppo'"):
        make_policy("baseline:scan-sac")
    assert main(["eval", "--policy", "baseline:nothing", "--dataset", str(VALIDATION_DATASET), "--quiet"]) == 2
    assert "unknown baseline 'nothing'" in capsys.readouterr().err


def test_eval_plays_the_baseline_by_name_and_records_its_file(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    results = tmp_path / "base.jsonl"
    argv = ["eval", "--policy", "baseline:scan-ppo", "--dataset", str(VALIDATION_DATASET), "--limit", "2",
            "--results", str(results), "--plot", str(tmp_path / "base.png"), "--quiet"]
    assert main(argv) == 0
    lines = [json.loads(line) for line in results.read_text().splitlines()]
    run = next(line for line in lines if "policy_sha256" in json.dumps(line))
    with open(baseline_path("scan-ppo"), "rb") as f:
        digest = hashlib.sha256(f.read()).hexdigest()
    assert digest in json.dumps(run)
    episodes = [line for line in lines if "episode_id" in line]
    assert len(episodes) == 2
    # The same two episodes through the checkpoint's own path: the same results, to the episode.
    same = tmp_path / "same.jsonl"
    argv_file = [*argv[:2], baseline_path("scan-ppo"), *argv[3:]]
    argv_file[argv_file.index(str(results))] = str(same)
    argv_file[argv_file.index(str(tmp_path / "base.png"))] = str(tmp_path / "same.png")
    assert main(argv_file) == 0
    again = [line for line in map(json.loads, same.read_text().splitlines()) if "episode_id" in line]
    assert [(e["success"], e["spl"], e["steps"]) for e in episodes] == [(e["success"], e["spl"], e["steps"]) for e in again]
