"""``pointnav dataset generate`` and ``pointnav eval``: reproducible files, oracle results
that do not depend on the order or the number of processes, and clear errors."""

from __future__ import annotations

import csv
import dataclasses
import hashlib
import itertools
import json
import math

import numpy as np
import pytest
from PIL import Image

import pointnav_core
from pointnav_core.cli import main
from pointnav_core.datasets import EpisodeDataset
from pointnav_core.evaluation.report import (
    bootstrap_interval,
    read_results,
    read_run,
    summarize,
    write_results,
)
from pointnav_core.evaluation.policy_specs import make_policy
from pointnav_core.evaluation.run import evaluate, select_episodes

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
        ("no_colon", "unknown policy 'no_colon': expected 'oracle', 'orca_robot', 'dwa', MODULE:CALLABLE"),
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
    from pointnav_core.envs.pointnav import PointNavEnv

    model = sb3.PPO(
        "MlpPolicy", PointNavEnv(flatten_obs=True), n_steps=16, batch_size=16, device="cpu", seed=0
    )
    model.save(tmp_path / "ppo.zip")
    data = list(EpisodeDataset.load(dataset_file))[:2]
    first = evaluate(data, str(tmp_path / "ppo.zip"), max_steps=10, trust_policy_file=True)
    assert [r.steps for r in first] == [10, 10] and all(r.path_length > 0 for r in first)
    assert evaluate(data[::-1], str(tmp_path / "ppo.zip"), max_steps=10, trust_policy_file=True)[::-1] == first


# ---------------------------------------------------------------------- intervals
def test_bootstrap_interval_of_constant_outcomes_is_that_constant():
    assert bootstrap_interval([1.0] * 9).tolist() == [1.0, 1.0]  # all successes
    assert bootstrap_interval([0.0] * 4).tolist() == [0.0, 0.0]
    assert bootstrap_interval([[1.0, 0.5]] * 3).tolist() == [[1.0, 0.5], [1.0, 0.5]]


def _exact_quantile(atoms: dict[float, float], p: float) -> tuple[float, float]:
    """The ``p`` quantile of a discrete distribution (the smallest atom whose CDF reaches
    ``p``), and how far ``p`` is from the nearest CDF step."""
    cdf, gap = 0.0, 1.0
    for value in sorted(atoms):
        before, cdf = cdf, cdf + atoms[value]
        gap = min(gap, abs(cdf - p))
        if cdf >= p and before < p:
            found = value
    return found, gap


@pytest.mark.parametrize("values", [[0.0, 1.0, 1.0, 1.0, 1.0], [0.0, 0.25, 0.5, 0.9], [0.1, 0.7, 0.8]])
def test_bootstrap_interval_matches_the_exact_bootstrap_distribution(values):
    """For a tiny list every resample can be enumerated (n ** n equally likely index
    tuples), which gives the exact distribution of the resample mean; 10,000 resamples put
    the 2.5 % and 97.5 % points on its quantiles when no CDF step is near them."""
    n = len(values)
    atoms: dict[float, float] = {}
    for picks in itertools.product(values, repeat=n):
        mean = round(math.fsum(picks) / n, 12)
        atoms[mean] = atoms.get(mean, 0.0) + 1.0 / n**n
    (lo, gap_lo), (hi, gap_hi) = _exact_quantile(atoms, 0.025), _exact_quantile(atoms, 0.975)
    assert min(gap_lo, gap_hi) > 0.005  # > 3 standard errors of a 10,000-resample CDF
    assert bootstrap_interval(values) == pytest.approx([lo, hi], abs=1e-9)


def test_bootstrap_interval_matches_a_plain_python_loop():
    """The documented recipe written out: resample b is the b-th
    ``rng.integers(0, n, size=n)``; the bounds interpolate the sorted means linearly."""
    table = [(1.0, 0.81, 0.9), (0.0, 0.0, 0.35), (1.0, 0.97, 0.98), (1.0, 0.5, 0.72),
             (0.0, 0.0, 0.1), (1.0, 0.66, 0.8), (1.0, 1.0, 0.95)]
    n, resamples, seed, confidence = len(table), 2000, 7, 0.9
    rng = np.random.default_rng(seed)
    means: list[list[float]] = [[], [], []]
    for _ in range(resamples):
        rows = [table[int(i)] for i in rng.integers(0, n, size=n)]
        for k in range(3):
            means[k].append(sum(row[k] for row in rows) / n)

    def percentile(sample: list[float], p: float) -> float:
        s = sorted(sample)
        pos = p * (len(s) - 1)
        i = int(pos)
        return s[i] + (pos - i) * (s[min(i + 1, len(s) - 1)] - s[i])

    expected = np.array([[percentile(m, p) for m in means] for p in (0.05, 0.95)])
    got = bootstrap_interval(table, confidence=confidence, resamples=resamples, seed=seed)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)
    assert expected[0, 0] < expected[1, 0]  # not a degenerate case
    again = bootstrap_interval(table, confidence=confidence, resamples=resamples, seed=seed)
    assert again.tolist() == got.tolist()  # seeded: the same results give the same bounds
    # A column alone draws the same resamples as the three together.
    alone = bootstrap_interval([row[1] for row in table], confidence=confidence, resamples=resamples, seed=seed)
    np.testing.assert_allclose(alone, expected[:, 1], rtol=0, atol=1e-12)


def test_bootstrap_interval_of_many_episodes_draws_the_documented_resamples():
    """2,000 episodes: the library draws its index matrix in blocks of rows, which must be
    the resamples drawn one by one."""
    outcomes = (np.arange(2000) % 7 < 5).astype(float)
    rng = np.random.default_rng(3)
    means = [outcomes[rng.integers(0, 2000, size=2000)].sum() / 2000 for _ in range(1200)]
    got = bootstrap_interval(outcomes, resamples=1200, seed=3)
    np.testing.assert_allclose(got, np.quantile(means, [0.025, 0.975]), rtol=0, atol=1e-12)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"values": []}, "values must be a non-empty"),
        ({"values": [1.0, float("nan")]}, "values must be a non-empty"),
        ({"values": [1.0], "confidence": 0.0}, "confidence must be"),
        ({"values": [1.0], "confidence": "0.9"}, "confidence must be"),
        ({"values": [1.0], "resamples": 0}, "resamples must be an integer >= 1"),
        ({"values": [1.0], "resamples": True}, "resamples must be an integer >= 1"),
        ({"values": [1.0], "seed": -1}, "seed must be an integer >= 0"),
    ],
)
def test_bootstrap_interval_refuses_bad_arguments(kwargs, match):
    with pytest.raises(ValueError, match=match):
        bootstrap_interval(**kwargs)


# ---------------------------------------------------------------------- subsets and records
def test_select_episodes_strides_then_limits():
    ten = list(range(10))
    assert select_episodes(ten, stride=3) == [0, 3, 6, 9]
    assert select_episodes(ten, limit=2, stride=3) == [0, 3]
    assert select_episodes(ten, limit=20) == ten
    for kwargs, match in (
        ({"limit": 0}, "limit must be an integer >= 1, got 0"),
        ({"stride": 0}, "stride must be an integer >= 1, got 0"),
        ({"limit": 1.0}, "limit must be an integer"),
        ({"stride": True}, "stride must be an integer"),
    ):
        with pytest.raises(ValueError, match=match):
            select_episodes(ten, **kwargs)


def test_evaluate_takes_limit_and_stride(dataset_file):
    data = EpisodeDataset.load(dataset_file)
    results = evaluate(data, "eval_policies:standstill", max_steps=2, stride=2, limit=2)
    assert [r.episode_id for r in results] == ["0", "2"]


def test_cli_subset_records_the_run_and_the_intervals(dataset_file, tmp_path, capsys):
    results = tmp_path / "r.jsonl"
    args = ["eval", "--dataset", str(dataset_file), "--scenes-dir", str(dataset_file.parent),
            "--results", str(results), "--plot", str(tmp_path / "r.png"), "--quiet",
            "--policy", "eval_policies:standstill", "--max-steps", "3"]
    assert main([*args, "--stride", "2", "--limit", "2"]) == 0
    out = capsys.readouterr().out
    lines = [json.loads(line) for line in results.read_text().splitlines()]
    assert [line.get("episode_id") for line in lines] == [None, "0", "2", None]
    run, summary = lines[0]["pointnav_eval"], lines[-1]["summary"]
    assert run["dataset_sha256"] == hashlib.sha256(dataset_file.read_bytes()).hexdigest()
    assert run["version"] == pointnav_core.__version__
    assert {k: run[k] for k in ("backend", "drive", "max_steps", "policy", "limit", "stride")} == {
        "backend": "kinematic", "drive": "differential", "max_steps": 3,
        "policy": "eval_policies:standstill", "limit": 2, "stride": 2,
    }
    soft = [line["soft_spl"] for line in lines[1:3]]
    assert summary["episodes"] == 2 and summary["soft_spl"] == pytest.approx(sum(soft) / 2)
    # Two episodes: the bootstrap means are the two values and their midpoint.
    ci = summary["intervals"]
    assert ci["success"] == [0.0, 0.0] and ci["resamples"] == 10_000 and ci["confidence"] == 0.95
    assert ci["soft_spl"] == pytest.approx([min(soft), max(soft)])
    assert read_run(results) == {"pointnav_eval": run, "summary": summary}
    assert [r.episode_id for r in read_results(results)] == ["0", "2"]
    assert "episodes          2 of 6" in out and "--stride 2, --limit 2" in out
    assert f"SoftSPL           {summary['soft_spl']:.4f}  [{min(soft):.4f}, {max(soft):.4f}]" in out
    csv_path = tmp_path / "r.csv"
    assert main([*args[:5], "--results", str(csv_path), *args[7:], "--limit", "1"]) == 0
    with open(csv_path) as fh:
        assert [row["episode_id"] for row in csv.DictReader(fh)] == ["0"]
    assert read_run(csv_path)["pointnav_eval"]["limit"] == 1
    assert "r.summary.json" in capsys.readouterr().out


def test_cli_refuses_bad_subsets_and_unknown_policies(dataset_file, tmp_path, capsys):
    results = tmp_path / "r.jsonl"
    base = ["eval", "--dataset", str(dataset_file), "--scenes-dir", str(dataset_file.parent),
            "--results", str(results), "--quiet"]
    for extra, match in (
        (["--limit", "0"], "--limit must be an integer >= 1, got '0'"),
        (["--limit", "-3"], "--limit must be an integer >= 1, got '-3'"),
        (["--limit", "two"], "--limit must be an integer >= 1, got 'two'"),
        (["--stride", "0"], "--stride must be an integer >= 1, got '0'"),
        (["--policy", "nonsense"], "unknown policy 'nonsense': expected 'oracle', 'orca_robot', 'dwa', MODULE:CALLABLE"),
    ):
        assert main([*base, *extra]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("pointnav eval: error: ") and match in err, err
        assert "Stable-Baselines3 .zip" in err or "--policy" not in extra
        assert not results.exists() and not (tmp_path / "r.jsonl.partial").exists()  # before any episode


def test_resume_with_another_subset_is_refused(dataset_file, tmp_path, monkeypatch, capsys):
    data = EpisodeDataset.load(dataset_file)
    second = data[2]  # the second episode of --stride 2
    monkeypatch.setenv("POINTNAV_TEST_RAISE", ",".join(
        str(float(v)) for v in (*second.start_position[:2], *second.goal_position[:2])))
    results = tmp_path / "r.jsonl"
    args = ["eval", "--dataset", str(dataset_file), "--scenes-dir", str(dataset_file.parent),
            "--results", str(results), "--plot", str(tmp_path / "r.png"), "--quiet",
            "--policy", "eval_policies:raise_on_episode", "--stride", "2"]
    assert main(args) == 1
    assert "1 of 3 episodes finished" in capsys.readouterr().err
    for other in (["--limit", "2"], ["--stride", "3"]):
        assert main([*args[:-2], *other, "--resume"]) == 2
        assert "other arguments" in capsys.readouterr().err
    monkeypatch.delenv("POINTNAV_TEST_RAISE")
    assert main([*args, "--resume"]) == 0
    assert [r.episode_id for r in read_results(results)] == ["0", "2", "4"]
    whole = tmp_path / "whole.jsonl"
    assert main([*args[:5], "--results", str(whole), *args[7:]]) == 0
    assert results.read_bytes() == whole.read_bytes()  # the run record and summary too
