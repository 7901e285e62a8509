"""``pointnav eval`` and ``pointnav dataset generate`` under faults: signals at random
moments, a full disk, a raising policy, hostile files.

The commands run as subprocesses where the fault is the process's own death (a signal, a
file-size limit); the rest call ``main`` in this process. Every run is a few short episodes
on one small MovingAI map, so the whole module takes a few tens of seconds.
"""

from __future__ import annotations

import base64
import contextlib
import json
import os
import random
import resource
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import pytest

import pointnav_core
from pointnav_core.cli import main
from pointnav_core.datasets import EpisodeDataset

SRC = str(Path(pointnav_core.__file__).resolve().parents[1])
TESTS = str(Path(__file__).resolve().parent)
# Two rooms joined by a door, 9 x 4 m at 0.5 m per character.
MAP = "type octile\nheight 8\nwidth 18\nmap\n" + "\n".join(
    [
        "@" * 18,
        "@........@.......@",
        "@........@.......@",
        "@...@@...........@",
        "@...@@...@.......@",
        "@........@.......@",
        "@........@.......@",
        "@" * 18,
    ]
)
EPISODES = 6


def _env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": os.pathsep.join([SRC, TESTS])}


def _cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "pointnav_core.cli", *args]


@pytest.fixture(scope="module")
def work(tmp_path_factory):
    """A map, a dataset of short episodes on it, and the results of an uninterrupted run."""
    folder = tmp_path_factory.mktemp("faults")
    (folder / "a.map").write_text(MAP)
    dataset = folder / "d.json.gz"
    gen = ["dataset", "generate", "--scenes", str(folder), "--split", "train"]
    assert main([*gen, "--episodes", str(EPISODES), "--max-geodesic", "4", "--out", str(dataset), "--quiet"]) == 0
    reference = folder / "reference.jsonl"
    assert main(_eval_args(folder, reference)) == 0
    return folder, dataset, reference.read_bytes()


def _eval_args(folder: Path, results: Path, *extra: str) -> list[str]:
    return [
        "eval", "--dataset", str(folder / "d.json.gz"), "--scenes-dir", str(folder),
        "--results", str(results), "--plot", str(results.with_suffix(".png")), "--quiet", *extra,
    ]


# ---------------------------------------------------------------------- processes
def _parents() -> dict[int, int]:
    """pid -> parent pid of every live (not zombie) process."""
    table = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                stat = Path(f"/proc/{entry}/stat").read_text()
            except OSError:
                continue
            fields = stat[stat.rindex(")") + 2 :].split()
            if fields[0] != "Z":
                table[int(entry)] = int(fields[1])
    return table


def _descendants(root: int) -> set[int]:
    table, found, todo = _parents(), set(), [root]
    while todo:
        pid = todo.pop()
        kids = [p for p, parent in table.items() if parent == pid]
        found.update(kids)
        todo.extend(kids)
    return found


def _valid_log(path: Path) -> int:
    """The number of results in a ``.partial`` log, after checking every line is JSON."""
    lines = path.read_text().splitlines()
    assert "pointnav_eval" in json.loads(lines[0])
    return sum(1 for line in lines[1:] if json.loads(line)["episode_id"] is not None)


@pytest.mark.long
@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc")
def test_signals_at_random_moments_lose_nothing(work, tmp_path):
    """SIGINT (to the process group, as Ctrl-C), SIGTERM and SIGKILL, with 1 and 2 workers,
    all runs at once: no worker outlives its parent by 5 s, the log is valid JSON lines, and
    --resume ends with the uninterrupted run's bytes. ``dataset generate`` killed the same
    way leaves an existing dataset whole."""
    folder, dataset, reference = work
    rng = random.Random(29)
    runs = []
    try:
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGKILL):
            for workers in (1, 2):
                results = tmp_path / f"{sig.name}-{workers}.jsonl"
                args = _eval_args(folder, results, "--workers", str(workers))
                proc = subprocess.Popen(
                    _cli(*args), env=_env(), start_new_session=True,
                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                )
                ready = Path(str(results) + ".partial")
                runs.append({"proc": proc, "sig": sig, "results": results, "ready": ready, "delay": rng.uniform(0.0, 1.0)})
            old = tmp_path / f"old-{sig.name}.json.gz"
            old.write_bytes(dataset.read_bytes())
            gen = ["dataset", "generate", "--scenes", str(folder), "--split", "train", "--seed", "1",
                   "--episodes", "20", "--out", str(old)]
            progress = tmp_path / f"progress-{sig.name}.txt"  # the progress bar: it has started
            with open(progress, "w") as bar:
                proc = subprocess.Popen(_cli(*gen), env=_env(), start_new_session=True,
                                        stdout=subprocess.DEVNULL, stderr=bar, text=True)
            runs.append({"proc": proc, "sig": sig, "old": old, "ready": progress, "delay": rng.uniform(0.0, 1.5)})
        start, seen = time.monotonic(), {id(r): set() for r in runs}
        while any("killed" not in r for r in runs):
            for r in runs:
                if "killed" in r:
                    continue
                seen[id(r)] |= _descendants(r["proc"].pid)
                if "since" not in r and r["ready"].exists() and r["ready"].stat().st_size > 0:
                    r["since"] = time.monotonic()
                if "since" in r and time.monotonic() - r["since"] >= r["delay"]:
                    if r["sig"] == signal.SIGINT:  # Ctrl-C reaches the whole foreground group
                        os.killpg(r["proc"].pid, signal.SIGINT)
                    else:
                        r["proc"].send_signal(r["sig"])
                    r["killed"] = time.monotonic()
            assert time.monotonic() - start < 60, "a run never started"
            time.sleep(0.02)
        for r in runs:  # every death first: the checks below take seconds each
            r["rc"], r["died"] = r["proc"].wait(timeout=20), time.monotonic()
            left = seen[id(r)]
            while left and time.monotonic() - r["died"] < 5.0:
                left = left & set(_parents())
                time.sleep(0.05)
            assert not left, f"{r['sig'].name}: processes {left} outlived their parent by 5 s"
        for r in runs:
            rc, died = r["rc"], r["died"]
            assert died - r["killed"] < 10, "the run went on after the signal"
            if r["proc"].stderr is not None:
                with r["proc"].stderr as pipe:
                    err = pipe.read()
            # A signal in the interpreter's last moments, after the work is done and Python has
            # put the default handlers back, ends it by that signal (-sig), not by 130.
            if "old" in r:  # dataset generate: the old file, or the whole new one
                assert rc in (0, 130, -9, -r["sig"]), r["ready"].read_text()
                EpisodeDataset.load(r["old"])
                if rc == 130:
                    assert r["old"].read_bytes() == dataset.read_bytes()
                continue
            assert rc in ((-9,) if r["sig"] == signal.SIGKILL else (130, -r["sig"])) or rc == 0, err
            if rc == 130 and r["ready"].exists():  # else the signal came after the results were written
                assert err.count("\n") == 1 and f"interrupted by {r['sig'].name}" in err and "--resume" in err
            if r["ready"].exists():
                _valid_log(r["ready"])
            assert main(_eval_args(folder, r["results"], "--resume")) == 0
            assert r["results"].read_bytes() == reference
            assert not r["ready"].exists()
    finally:  # a failed check leaves no run behind (nor its pipe) to trouble later tests
        for r in runs:
            if r["proc"].poll() is None:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(r["proc"].pid, signal.SIGKILL)
            r["proc"].wait()
            if r["proc"].stderr is not None:
                r["proc"].stderr.close()


def _limit_file_size(limit: int):
    return lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))


def test_full_disk_keeps_finished_episodes_and_old_files(work, tmp_path):
    folder, dataset, reference = work
    results = tmp_path / "r.jsonl"
    results.write_text("old results\n")
    limit = len(reference) * 2 // 3  # the log's first line, then about three results
    run = subprocess.run(
        _cli(*_eval_args(folder, results)), env=_env(), capture_output=True, text=True,
        preexec_fn=_limit_file_size(limit), timeout=60, check=False,
    )
    assert run.returncode == 1, run.stderr
    assert "cannot write" in run.stderr and "r.jsonl.partial" in run.stderr and "Traceback" not in run.stderr
    assert results.read_text() == "old results\n"  # never touched
    log = Path(str(results) + ".partial")
    assert 1 <= _valid_log(log) < EPISODES
    assert main(_eval_args(folder, results, "--resume")) == 0
    assert results.read_bytes() == reference
    # A dataset written over an existing one on a full disk leaves the old one whole.
    old = tmp_path / "old.json.gz"
    old.write_bytes(dataset.read_bytes())
    gen = ["dataset", "generate", "--scenes", str(folder), "--split", "train", "--seed", "3",
           "--episodes", "15", "--out", str(old), "--quiet"]
    run = subprocess.run(_cli(*gen), env=_env(), capture_output=True, text=True,
                         preexec_fn=_limit_file_size(len(dataset.read_bytes()) // 2), timeout=60, check=False)
    assert run.returncode == 2 and "Traceback" not in run.stderr, run.stderr
    assert old.read_bytes() == dataset.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".old")) == []


def test_raising_policy_names_its_episode(work, tmp_path, monkeypatch, capsys):
    folder, dataset, reference = work
    episodes = EpisodeDataset.load(dataset)
    bad = episodes[2]
    where = ",".join(repr(v) for v in (*bad.start_xy, *bad.goal_xy))
    assert sum(ep.start_xy == bad.start_xy and ep.goal_xy == bad.goal_xy for ep in episodes) == 1
    monkeypatch.setenv("POINTNAV_TEST_RAISE", where)
    results = tmp_path / "r.jsonl"
    results.write_text("old results\n")
    policy = ["--policy", "eval_policies:raise_on_episode"]
    assert main(_eval_args(folder, results, *policy)) == 1
    err = capsys.readouterr().err
    assert f"episode {bad.episode_id!r}" in err and "RuntimeError: boom" in err
    assert "2 of 6 episodes finished" in err
    assert results.read_text() == "old results\n"
    # A rerun without --resume would throw the log away: it is refused.
    assert main(_eval_args(folder, results, *policy)) == 2
    assert "--resume" in capsys.readouterr().err
    monkeypatch.delenv("POINTNAV_TEST_RAISE")
    assert main(_eval_args(folder, results, *policy, "--resume")) == 0
    # The oracle's results, under a run record that names this policy.
    assert results.read_bytes().split(b"\n")[1:] == reference.split(b"\n")[1:]
    # With two workers and --on-error skip, the other five episodes are kept.
    monkeypatch.setenv("POINTNAV_TEST_RAISE", where)
    skipped = tmp_path / "s.jsonl"
    assert main(_eval_args(folder, skipped, *policy, "--workers", "2", "--on-error", "skip")) == 1
    err = capsys.readouterr().err
    assert f"skipped: episode {bad.episode_id!r}" in err and "RuntimeError: boom" in err
    episode_lines = [line for line in reference.decode().splitlines(keepends=True) if '"episode_id"' in line]
    kept = [line for line in episode_lines if json.loads(line)["episode_id"] != bad.episode_id]
    got = skipped.read_text().splitlines(keepends=True)[1:-1]  # between the run and the summary
    assert [json.loads(line) for line in got] == [json.loads(line) for line in kept]
    assert got == kept


def test_outputs_are_checked_before_any_episode(work, tmp_path, capsys):
    folder, dataset, _ = work
    before = dataset.read_bytes()
    for results, match in (
        (dataset, "is an input of this run"),
        (tmp_path / "missing" / "r.jsonl", "does not exist"),
        (tmp_path, "is a folder"),
    ):
        started = time.monotonic()
        assert main(_eval_args(folder, Path(results))) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "--results" in err and match in err
        assert time.monotonic() - started < 1.0  # refused before playing
    assert dataset.read_bytes() == before


def test_workers_are_capped_by_episodes_and_cores(work, monkeypatch):
    from pointnav_core.evaluation import run as evaluation

    made = []

    class Pool:
        def __init__(self, workers, *args):
            made.append(workers)
            raise KeyboardInterrupt

    monkeypatch.setattr(evaluation, "WorkerPool", Pool)
    monkeypatch.setattr(evaluation, "usable_cores", lambda: 3)
    episodes = list(EpisodeDataset.load(work[1]))
    for n, expected in ((6, 3), (2, 2)):
        with pytest.raises(KeyboardInterrupt):
            evaluation.evaluate(episodes[:n], workers=1000)
    assert made == [3, 2]


# ---------------------------------------------------------------------- hostile files
def _sb3_zip(path: Path, marker: Path) -> None:
    """An SB3 model file whose ``policy_class`` unpickles to ``os.mkdir(marker)``."""
    import pickle

    class Payload:
        def __reduce__(self):
            return (os.mkdir, (str(marker),))

    blob = base64.b64encode(pickle.dumps(Payload())).decode()
    data = {"policy_class": {":type:": "<class 'abc.ABCMeta'>", ":serialized:": blob}}
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("data", json.dumps(data))
        zf.writestr("_stable_baselines3_version", "2.9.2")


def test_sb3_zip_runs_no_code_without_trust(work, tmp_path, capsys):
    pytest.importorskip("stable_baselines3")
    folder = work[0]
    model, marker = tmp_path / "model.zip", tmp_path / "marker"
    _sb3_zip(model, marker)
    assert main(_eval_args(folder, tmp_path / "r.jsonl", "--policy", str(model))) == 2
    assert "--trust-policy-file" in capsys.readouterr().err
    assert not marker.exists()
    # The payload is real: trusting the file runs it.
    main(_eval_args(folder, tmp_path / "t.jsonl", "--policy", str(model), "--trust-policy-file"))
    capsys.readouterr()
    assert marker.exists()


def test_scene_paths_stay_under_the_scenes_folder(work, tmp_path, capsys):
    dataset = work[1]
    secret = tmp_path / "secret.map"
    secret.write_text("hunter2 is the password\n")
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    (scenes / "link.map").symlink_to(secret)
    raw = EpisodeDataset.load(dataset).to_json()
    raw["episodes"] = raw["episodes"][:1]
    for scene_id in ("movingai:../secret.map", f"movingai:{secret}", "movingai:link.map", "../secret.map"):
        raw["episodes"][0]["scene_id"] = scene_id
        bad = tmp_path / "bad.json"
        bad.write_text(json.dumps(raw))
        args = ["eval", "--dataset", str(bad), "--scenes-dir", str(scenes), "--results", str(tmp_path / "r.jsonl"), "--quiet"]
        assert main(args) == 2
        err = capsys.readouterr().err
        assert "leaves the scenes folder" in err and "hunter2" not in err, err
    # A file inside the folder that is not a map is refused without echoing it either.
    (scenes / "notes.map").write_text("hunter2 is the password\n")
    raw["episodes"][0]["scene_id"] = "movingai:notes.map"
    bad.write_text(json.dumps(raw))
    assert main(["eval", "--dataset", str(bad), "--scenes-dir", str(scenes), "--results", str(tmp_path / "r.jsonl"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "bad MovingAI header at line 1" in err and "hunter2" not in err
