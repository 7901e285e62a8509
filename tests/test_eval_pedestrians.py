"""``pointnav eval`` with pedestrians: an env config's crowd walks in every episode, the
results carry the social metrics, and the same episode meets the same crowd in any order
and any number of workers (issue 33, points 3, 4 and must-show 4)."""

from __future__ import annotations

import pytest
from map_data import pillar_room_dataset

from pointnav_core.cli import main
from pointnav_core.datasets import EpisodeDataset
from pointnav_core.envs.config import EnvConfig
from pointnav_core.evaluation.report import read_results, read_run, summarize
from pointnav_core.evaluation.run import evaluate

CROWD = EnvConfig(pedestrians={"count": 3, "radius": 0.15}, flatten_obs=False, max_steps=60)


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    """A 4-episode dataset on the pillar room, and the crowd config saved as YAML."""
    folder = tmp_path_factory.mktemp("room")
    pillar_room_dataset(folder, 4)
    CROWD.save(folder / "crowd.yaml")
    return folder


def test_results_carry_the_crowds_metrics_whatever_the_order_and_workers(data):
    episodes = list(EpisodeDataset.load(data / "val.json.gz"))
    one = evaluate(episodes, "oracle", env_config=CROWD, scenes_root=str(data))
    two = evaluate(episodes, "oracle", env_config=CROWD, scenes_root=str(data), workers=2)
    backwards = evaluate(episodes[::-1], "oracle", env_config=CROWD, scenes_root=str(data))
    assert one == two == backwards[::-1]
    for result in one:
        assert result.pedestrian_collisions is not None and result.pedestrian_collisions >= 0
        assert result.social is not None and 0.0 <= result.social["psc"] <= 1.0
    summary = summarize(one)
    psc = [r.social["psc"] for r in one]
    assert summary["social_psc"] == pytest.approx(sum(psc) / len(psc))
    assert summary["pedestrian_collisions"] == pytest.approx(sum(r.pedestrian_collisions for r in one) / len(one))


def test_without_pedestrians_results_have_none(data):
    episodes = list(EpisodeDataset.load(data / "val.json.gz"))[:1]
    result, = evaluate(episodes, "oracle", scenes_root=str(data))
    assert result.pedestrian_collisions is None and result.social is None
    assert not any(key.startswith("social_") or key == "pedestrian_collisions" for key in summarize([result]))


@pytest.mark.parametrize("suffix", [".jsonl", ".csv"])
def test_the_cli_prints_and_writes_them(data, tmp_path, capsys, suffix):
    out = tmp_path / f"r{suffix}"
    assert main(["eval", "--dataset", str(data / "val.json.gz"), "--scenes-dir", str(data), "--env-config",
                 str(data / "crowd.yaml"), "--results", str(out), "--plot", str(tmp_path / "r.png"), "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert "pedestrian contacts" in printed and "PSC" in printed
    summary = read_run(out)["summary"]
    assert 0.0 <= summary["social_psc"] <= 1.0
    if suffix == ".jsonl":
        assert all(r.social is not None for r in read_results(out))
