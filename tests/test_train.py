"""Training and checkpoints: ``pointnav train`` then ``pointnav eval --policy CHECKPOINT``.

The checkpoint tests hold a saved network to a hand computation of its actions (the
running statistics' standardisation, then the MLP) and refuse what is not a checkpoint
without running it. The training tests run ``pointnav train`` on a tiny budget in a small
room, and check that the trainer's held-out results are ``pointnav eval``'s, episode by
episode.
"""

from __future__ import annotations

import hashlib
import os
import pickle

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from map_data import PILLAR_ROOM

from pointnav_core.cli import main
from pointnav_core.envs.config import EnvConfig
from pointnav_core.evaluation.policy_specs import make_policy
from pointnav_core.evaluation.report import read_results
from pointnav_core.evaluation.run import evaluate
from pointnav_core.policies.checkpoint import load_checkpoint, save_checkpoint
from pointnav_core.policies.network import ActorCritic, RunningNorm

SCAN = EnvConfig(sensors={"scan": {"n_rays": 8}}, action_space="discrete", discrete_actions={"stop": False},
                 task={"goal_in_polar": True, "reward_type": "geodesic"}, max_steps=30)


def _trained_like(n_obs: int, n_actions: int, continuous: bool) -> tuple[ActorCritic, RunningNorm]:
    """A network and statistics far from their initial values (as after training)."""
    torch.manual_seed(3)
    agent = ActorCritic(n_obs, n_actions, 8, continuous)
    with torch.no_grad():
        for p in agent.parameters():
            p.add_(torch.randn_like(p))
    norm = RunningNorm((n_obs,))
    norm.update(torch.randn(50, n_obs, dtype=torch.float64) * 3 + 1)
    return agent, norm


def _by_hand(agent: ActorCritic, norm: RunningNorm, obs: np.ndarray, continuous: bool) -> np.ndarray:
    """The deterministic action, from the weights with numpy: standardise and clip to
    [-10, 10], two tanh layers, then the argmax (discrete) or the mean clipped to [-1, 1]."""
    z = np.clip((obs - norm.mean.numpy()) / np.sqrt(norm.var.numpy() + 1e-8), -10, 10).astype(np.float32)
    w = [m for m in agent.actor if isinstance(m, torch.nn.Linear)]
    h = np.tanh(z @ w[0].weight.detach().numpy().T + w[0].bias.detach().numpy())
    h = np.tanh(h @ w[1].weight.detach().numpy().T + w[1].bias.detach().numpy())
    out = h @ w[2].weight.detach().numpy().T + w[2].bias.detach().numpy()
    return np.clip(out, -1, 1) if continuous else out.argmax(-1)


@pytest.mark.parametrize("continuous", [False, True])
def test_checkpoint_round_trip_gives_the_same_actions(tmp_path, continuous) -> None:
    config = SCAN if not continuous else EnvConfig(sensors={"scan": {"n_rays": 8}}, max_steps=30)
    agent, norm = _trained_like(16, 2 if continuous else 3, continuous)
    path = tmp_path / "p.pt"
    save_checkpoint(path, agent, norm, config, step=1234, metrics={"success": 0.5})
    ckpt = load_checkpoint(path)
    assert (ckpt.step, ckpt.env_config, ckpt.metrics) == (1234, config, {"success": 0.5})
    assert ckpt.network == {"n_obs": 16, "n_actions": 2 if continuous else 3, "width": 8, "continuous": continuous}
    obs = np.random.default_rng(0).normal(0, 4, (64, 16)).astype(np.float32)
    want = _by_hand(agent, norm, obs, continuous)
    policy = make_policy(str(path))(None)  # the evaluation's policy: one observation at a time
    got = np.array([policy(o) for o in obs])
    if continuous:
        np.testing.assert_allclose(got, want, atol=1e-5)
        assert got.dtype == np.float32 and got.shape == (64, 2)
    else:
        assert got.tolist() == want.tolist() and len(set(got.tolist())) > 1


class _Marker:
    """Unpickling this runs code: it creates a file (a checkpoint must never do that)."""

    def __init__(self, path: str) -> None:
        self.path = path

    def __reduce__(self):
        return (open, (self.path, "w"))


def test_what_is_not_a_checkpoint_is_refused_naming_the_file(tmp_path) -> None:
    agent, norm = _trained_like(16, 3, False)
    good = tmp_path / "good.pt"
    save_checkpoint(good, agent, norm, SCAN, step=1)
    data = good.read_bytes()
    marker = tmp_path / "ran"
    cases = {
        "truncated.pt": data[: len(data) // 2],
        "empty.pt": b"",
        "text.pt": b"not a checkpoint\n",
        "pickle.pt": pickle.dumps(_Marker(str(marker))),
    }
    for name, content in cases.items():
        (tmp_path / name).write_bytes(content)
    torch.save({"weights": torch.zeros(3)}, tmp_path / "foreign.pt")
    torch.save({"x": _Marker(str(marker))}, tmp_path / "code.pt")
    for name in [*cases, "foreign.pt", "code.pt"]:
        path = str(tmp_path / name)
        with pytest.raises(ValueError, match=f"checkpoint {path!r}"):
            load_checkpoint(path)
    assert not marker.exists(), "loading a checkpoint ran code"
    with pytest.raises(ValueError, match="no such checkpoint file"):
        make_policy(str(tmp_path / "missing.pt"))


# ---------------------------------------------------------------------- pointnav train -> eval
def _train_config(out: str, env: EnvConfig, total_steps: int = 512, **extra) -> dict:
    """A tiny run: 16 worlds, 16 steps each per update, a held-out evaluation every 256 steps."""
    return {
        "env": env.to_dict(), "scenes": "maps", "split": "train", "path_range": [0.5, 3.0],
        "eval_dataset": "val.json.gz", "eval_every": 256, "out": out,
        "ppo": {"total_steps": total_steps, "num_steps": 16, "minibatch": 64, "width": 16, "epochs": 2},
        "engine": {"num_envs": 16, "pool_size": 2, "starts_per_goal": 4}, **extra,
    }


def _write(path, data: dict) -> str:
    import yaml

    with open(path, "w", encoding="utf-8") as fh:
        yaml.safe_dump(data, fh)
    return str(path)


@pytest.fixture(scope="module")
def room(tmp_path_factory):
    """A folder with the room as a one-scene set (maps/), a 4-episode held-out dataset
    (val.json.gz) and one of 3 episodes made for a robot of radius 0.25 m (wide.json.gz)."""
    folder = tmp_path_factory.mktemp("train")
    (folder / "maps").mkdir()
    (folder / "maps" / "room.map").write_text(PILLAR_ROOM)
    here = os.getcwd()
    os.chdir(folder)  # the scene ids ("movingai:maps/room.map") are relative to it
    try:
        for name, n, extra in (("val", 4, []), ("wide", 3, ["--robot-radius", "0.25"])):
            assert main(["dataset", "generate", "--scenes", "maps", "--split", "train", "--episodes", str(n),
                         "--max-geodesic", "3", "--out", f"{name}.json.gz", "--quiet", *extra]) == 0
    finally:
        os.chdir(here)
    return folder


@pytest.fixture(scope="module")
def scan_run(room):
    """``pointnav train`` of the scan with discrete actions: the run's folder."""
    here = os.getcwd()
    os.chdir(room)
    try:
        assert main(["train", "--config", _write(room / "scan.yaml", _train_config("scan_run", SCAN)), "--quiet"]) == 0
    finally:
        os.chdir(here)
    return room / "scan_run"


def _same_as_trainer_results(run, results) -> None:
    """``results`` are the trainer's held-out results of ``best.pt``, episode by episode."""
    ckpt = load_checkpoint(run / "best.pt")
    trainer = read_results(run / "heldout" / f"step_{ckpt.step:09d}.jsonl")
    assert list(results) == trainer and len(trainer) == 4


def _same_as_trainer(run, results_file) -> None:
    """``pointnav eval``'s results file holds the trainer's held-out results of ``best.pt``."""
    _same_as_trainer_results(run, read_results(results_file))


def test_train_then_eval_with_no_other_argument_scan_discrete(scan_run, room, monkeypatch, capsys) -> None:
    from pointnav_core.evaluation.report import read_run
    from pointnav_core.training.curve import read_curve

    rows = read_curve(scan_run / "curve.csv")
    assert [r["step"] for r in rows] == [256, 512] and all(r["heldout_episodes"] == 4 for r in rows)
    from PIL import Image

    with Image.open(scan_run / "curve.png") as png:  # the held-out success line is drawn in green
        assert png.format == "PNG" and (20, 150, 60) in {c for _, c in png.convert("RGB").getcolors(1 << 16)}
    assert load_checkpoint(scan_run / "latest.pt").step == 512
    best = load_checkpoint(scan_run / "best.pt")
    assert best.env_config.sensors == {"scan": {"n_rays": 8}} and best.training is None
    from pointnav_core.training.config import TrainConfig

    assert TrainConfig.load(scan_run / "train_config.yaml") == TrainConfig.load(room / "scan.yaml")
    monkeypatch.chdir(room)
    capsys.readouterr()
    assert main(["eval", "--policy", "scan_run/best.pt", "--dataset", "val.json.gz"]) == 0
    _same_as_trainer(scan_run, room / "val.eval.jsonl")
    run = read_run(room / "val.eval.jsonl")["pointnav_eval"]
    assert run["env_config"] == best.env_config.to_dict()
    assert run["policy_sha256"] == hashlib.sha256((scan_run / "best.pt").read_bytes()).hexdigest()


def test_train_then_eval_continuous_and_resume(room, monkeypatch, capsys) -> None:
    from pointnav_core.training.curve import read_curve

    monkeypatch.chdir(room)
    env = EnvConfig(task={"goal_in_polar": True, "reward_type": "geodesic"}, max_steps=80)  # continuous, blind
    config = _write(room / "cont.yaml", _train_config("cont_run", env, total_steps=256))
    assert main(["train", "--config", config, "--quiet"]) == 0
    assert main(["eval", "--policy", "cont_run/best.pt", "--dataset", "val.json.gz", "--results", "cont.jsonl",
                 "--quiet"]) == 0
    _same_as_trainer(room / "cont_run", room / "cont.jsonl")
    first = read_curve(room / "cont_run" / "curve.csv")
    assert main(["train", "--config", config, "--quiet"]) == 2  # a run is there: --resume, or another out
    config = _write(room / "cont.yaml", _train_config("cont_run", env, total_steps=768))
    assert main(["train", "--config", config, "--resume", "--quiet"]) == 0
    rows = read_curve(room / "cont_run" / "curve.csv")
    assert [r["step"] for r in rows] == [256, 512, 768] and rows[0] == first[0]
    assert rows[1]["wall_s"] >= rows[0]["wall_s"]
    assert load_checkpoint(room / "cont_run" / "latest.pt").step == 768
    other = _write(room / "other.yaml", _train_config("cont_run", SCAN, total_steps=1024))
    capsys.readouterr()
    assert main(["train", "--config", other, "--resume", "--quiet"]) == 2
    assert "was trained with another env config" in capsys.readouterr().err
    assert load_checkpoint(room / "cont_run" / "latest.pt").step == 768


@pytest.mark.parametrize("building", [False, True])
def test_refresh_every_starts_a_refresh_only_when_none_is_building(room, tmp_path, monkeypatch, building) -> None:
    """``engine.refresh_every: 256`` over 1,024 steps, 256 an update (16 worlds x 16 steps):
    a refresh after each of the 4 updates, or only the first while a build never finishes
    (the learner does not wait for it)."""
    from pointnav_core.vector.env import VectorPointNavEnv

    calls = []
    monkeypatch.setattr(VectorPointNavEnv, "refresh_pool", lambda self, wait=False: calls.append(wait))
    monkeypatch.setattr(VectorPointNavEnv, "refresh_pending", property(lambda self: building and bool(calls)))
    monkeypatch.chdir(room)
    config = _train_config(str(tmp_path / "run"), SCAN, total_steps=1024, eval_every=1024)
    config["engine"]["refresh_every"] = 256
    assert main(["train", "--config", _write(tmp_path / "r.yaml", config), "--quiet"]) == 0
    assert calls == ([False] if building else [False] * 4)


def test_a_run_with_sampled_actions_evaluates_the_same_with_no_other_argument(room, monkeypatch, capsys) -> None:
    """``eval_actions: sampled``: the checkpoints carry it, and ``pointnav eval`` of
    ``best.pt`` gives the trainer's held-out results to the episode, with 1 worker and 2."""
    monkeypatch.chdir(room)
    config = _train_config("sampled_run", SCAN, eval_actions="sampled")
    assert main(["train", "--config", _write(room / "sampled.yaml", config), "--quiet"]) == 0
    run = room / "sampled_run"
    assert load_checkpoint(run / "best.pt").actions == "sampled" == load_checkpoint(run / "latest.pt").actions
    for workers in ("1", "2"):
        out = f"sampled{workers}.jsonl"
        assert main(["eval", "--policy", "sampled_run/best.pt", "--dataset", "val.json.gz", "--workers", workers,
                     "--results", out, "--plot", f"sampled{workers}.png", "--quiet"]) == 0
        _same_as_trainer(run, room / out)
    capsys.readouterr()
    assert main(["eval", "--policy", "oracle", "--dataset", "val.json.gz", "--actions", "sampled", "--quiet"]) == 2
    assert "sets how a checkpoint .pt acts; policy 'oracle' is not one" in capsys.readouterr().err
    config["eval_actions"] = "random"
    assert main(["train", "--config", _write(room / "bad.yaml", config), "--quiet"]) == 2
    assert "eval_actions must be one of ['greedy', 'sampled'], got 'random'" in capsys.readouterr().err


def test_bad_input_is_refused_naming_what_is_wrong(scan_run, room, monkeypatch, capsys) -> None:
    monkeypatch.chdir(room)
    capsys.readouterr()

    def refused(*args: str) -> str:
        assert main([*args, "--quiet"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1, err  # one line, no traceback
        return err

    # A checkpoint made for a robot of another radius than the dataset's episodes.
    err = refused("eval", "--policy", "scan_run/best.pt", "--dataset", "wide.json.gz")
    assert "robot radius is 0.18 m" in err and "radius 0.25 m" in err
    # An env config whose observation the network cannot read: the message names the config to use.
    EnvConfig(sensors={"scan": {"n_rays": 16}}, action_space="discrete", discrete_actions={"stop": False},
              task={"goal_in_polar": True}, max_steps=30).save(room / "scan16.yaml")
    err = refused("eval", "--policy", "scan_run/best.pt", "--dataset", "val.json.gz", "--env-config", "scan16.yaml")
    assert "takes observations of shape (16,)" in err and "gives (24,)" in err
    assert "the env config it carries (sensors {'scan': {'n_rays': 8}}" in err
    assert "unknown policy 'scan_run/best'" in refused("eval", "--policy", "scan_run/best", "--dataset", "val.json.gz")
    assert "--limit must be an integer >= 1, got '0'" in refused(
        "eval", "--policy", "scan_run/best.pt", "--dataset", "val.json.gz", "--limit", "0")
    assert "--max-steps given beside the checkpoint" in refused(
        "eval", "--policy", "scan_run/best.pt", "--dataset", "val.json.gz", "--max-steps", "50")
    # Training refuses a held-out dataset made for another robot before it trains or writes anything.
    config = _write(room / "wide.yaml", _train_config("wide_run", SCAN, eval_dataset="wide.json.gz"))
    assert "radius 0.25 m" in refused("train", "--config", config)
    assert not (room / "wide_run").exists()
    config = _write(room / "typo.yaml", {**_train_config("typo_run", SCAN), "ppo": {"learning_rate": 0.1}})
    assert "ppo has an unknown key 'learning_rate'" in refused("train", "--config", config)
    assert "holds no latest.pt" in refused("train", "--config", _write(room / "none.yaml", _train_config("none", SCAN)),
                                           "--resume")


def test_evaluate_plays_a_checkpoint_with_its_own_config(scan_run, room) -> None:
    from pointnav_core.datasets import EpisodeDataset

    episodes = list(EpisodeDataset.load(room / "val.json.gz"))
    best = str(scan_run / "best.pt")
    results = evaluate(episodes, best, scenes_root=str(room))  # no env_config: the checkpoint's
    _same_as_trainer_results(scan_run, results)
    with pytest.raises(ValueError, match="max_steps given beside env_config"):
        evaluate(episodes, best, scenes_root=str(room), max_steps=50)


@pytest.mark.parametrize(("name", "memory", "scan"), [("train_scan.yaml", 0, {"n_rays": 64, "max_range": 12.0}),
                                                      ("train_scan_lstm.yaml", 128, {"n_rays": 64})])
def test_the_example_config_reads_and_fits_the_shipped_validation_set(monkeypatch, name, memory, scan) -> None:
    from pathlib import Path

    from pointnav_core.training.config import TrainConfig
    from pointnav_core.training.trainer import heldout_episodes

    root = Path(__file__).resolve().parents[1]
    monkeypatch.chdir(root)  # its paths are relative to the repository's root
    config = TrainConfig.load(root / "examples" / name)
    assert config.policy_config().sensors == {"scan": scan} and config.path_range == (1.0, 30.0)
    assert config.ppo.memory == memory
    assert len(heldout_episodes(config)) == 60  # every 5th of the 300, the robot radius checked
