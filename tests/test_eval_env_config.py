"""``pointnav eval --env-config``: a policy trained on a scan env evaluates with no adapter."""

from __future__ import annotations

import pytest
from map_data import pillar_room_dataset

from pointnav_core.cli import main
from pointnav_core.datasets import EpisodeDataset
from pointnav_core.envs.config import EnvConfig
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.evaluation.report import read_results, read_run
from pointnav_core.evaluation.run import evaluate

SCAN = EnvConfig(
    sensors={"scan": {"n_rays": 16}}, action_space="discrete", discrete_actions={"stop": False},
    task={"goal_in_polar": True}, max_steps=12,
)


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    """A 3-episode dataset on the room, and the scan config saved as YAML."""
    folder = tmp_path_factory.mktemp("room")
    pillar_room_dataset(folder, 3)
    SCAN.save(folder / "scan.yaml")
    return folder


def _eval(folder, tmp_path, *extra):
    return main(["eval", "--dataset", str(folder / "val.json.gz"), "--scenes-dir", str(folder),
                 "--results", str(tmp_path / "r.jsonl"), "--plot", str(tmp_path / "r.png"), "--quiet", *extra])


def test_module_policy_gets_the_configs_env(data):
    episodes = list(EpisodeDataset.load(data / "val.json.gz"))
    results = evaluate(episodes, "eval_policies:scan16_forward", env_config=SCAN, scenes_root=str(data))
    assert len(results) == 3
    # max_steps counts discrete actions: a forward-only robot either arrives or runs 12 of them.
    assert all(r.steps <= 12 and (r.success or r.steps == 12) for r in results)
    assert any(r.path_length > 0.25 * 5 for r in results)  # moved forward_step per action, several times
    with pytest.raises(ValueError, match="max_steps given beside env_config"):
        evaluate(episodes, "oracle", env_config=SCAN, max_steps=50, scenes_root=str(data))


def test_sb3_model_trained_on_a_scan_env_evaluates_with_its_config(data, tmp_path, capsys):
    sb3 = pytest.importorskip("stable_baselines3")
    model = sb3.PPO("MlpPolicy", PointNavEnv(config=SCAN), n_steps=64, batch_size=64, n_epochs=1,
                    policy_kwargs={"net_arch": [16]}, device="cpu", seed=0)
    model.learn(64)
    zip_path = str(tmp_path / "scan.zip")
    model.save(zip_path)
    policy = ["--policy", zip_path, "--trust-policy-file"]

    assert _eval(data, tmp_path, *policy, "--env-config", str(data / "scan.yaml")) == 0
    records = read_run(tmp_path / "r.jsonl")
    run, summary = records["pointnav_eval"], records["summary"]
    assert run["env_config"] == SCAN.to_dict() and run["max_steps"] == 12 and run["backend"] == "kinematic"
    assert summary["episodes"] == 3 and all(r.steps <= 12 for r in read_results(tmp_path / "r.jsonl"))
    capsys.readouterr()

    # Without the config: the model's scan observations do not fit the plain env.
    assert _eval(data, tmp_path, *policy, "--results", str(tmp_path / "b.jsonl")) == 2
    err = capsys.readouterr().err
    assert "takes observations of shape (24,), but the env built for it gives (8,)" in err
    assert "--env-config" in err and err.count("\n") == 1

    # A config for another robot radius than the dataset's.
    (tmp_path / "wide.json").write_text('{"robot": {"radius": 0.25}, "sensors": {"scan": {"n_rays": 16}}}')
    assert _eval(data, tmp_path, *policy, "--env-config", str(tmp_path / "wide.json")) == 2
    err = capsys.readouterr().err
    assert "robot radius is 0.25 m, but episode '0'" in err and "radius 0.18 m" in err

    # Flags the config sets, beside it.
    assert _eval(data, tmp_path, "--env-config", str(data / "scan.yaml"), "--max-steps", "50") == 2
    assert "--max-steps given beside --env-config" in capsys.readouterr().err
