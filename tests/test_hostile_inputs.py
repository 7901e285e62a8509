"""Unclear failures made clear: corrupt and oversized inputs, the demo's bad input, a user
policy module in the working folder, and compiled kernels on a read-only install."""

from __future__ import annotations

import gzip
import json
import os
import shutil
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

import pointnav_core
from pointnav_core.cli import main
from pointnav_core.datasets import EpisodeDataset
from pointnav_core.floor.loaders import read_movingai, read_trav_png
from pointnav_core.scenes import Scene
from pointnav_core.utils import validation

SRC = Path(pointnav_core.__file__).resolve().parents[1]
MAP = "type octile\nheight 6\nwidth 10\nmap\n" + "@" * 10 + "\n" + "@........@\n" * 4 + "@" * 10 + "\n"


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """A folder with a small map and a dataset of one episode on it."""
    folder = tmp_path_factory.mktemp("hostile")
    (folder / "a.map").write_text(MAP)
    out = folder / "d.json.gz"
    args = ["dataset", "generate", "--scenes", str(folder), "--split", "train", "--episodes", "1",
            "--island-radius", "0.5", "--max-geodesic", "2", "--out", str(out), "--quiet"]
    assert main(args) == 0
    return folder, out


def test_truncated_or_corrupt_gzip_dataset_is_a_value_error(small, tmp_path, capsys):
    _, dataset = small
    raw = dataset.read_bytes()
    truncated, corrupt = tmp_path / "t.json.gz", tmp_path / "c.json.gz"
    truncated.write_bytes(raw[: len(raw) // 2])
    corrupt.write_bytes(raw[:12] + bytes(b ^ 0x5A for b in raw[12:40]) + raw[40:])
    for path, match in ((truncated, "truncated gzip"), (corrupt, "corrupt gzip")):
        with pytest.raises(ValueError, match=match) as info:
            EpisodeDataset.load(path)
        assert str(path) in str(info.value)
        assert main(["eval", "--dataset", str(path), "--results", str(tmp_path / "r.jsonl"), "--quiet"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("pointnav eval: error:") and match in err


def test_gzip_bomb_is_refused_at_its_budget(tmp_path):
    # 2 MB of gzip members that inflate to 2 GiB of zeros: refused after 256 MiB.
    pack = zlib.compressobj(9, zlib.DEFLATED, 31)
    member = pack.compress(bytes(1 << 20)) + pack.flush()
    bomb = tmp_path / "bomb.json.gz"
    bomb.write_bytes(member * 2048)
    with pytest.raises(ValueError, match=r"inflates past the dataset budget of 268435456 bytes"):
        EpisodeDataset.load(bomb)
    small = tmp_path / "small.json.gz"
    small.write_bytes(gzip.compress(b'{"episodes": []}' + b" " * 5000))
    assert len(EpisodeDataset.load(small)) == 0
    with pytest.raises(ValueError, match="max_bytes"):
        EpisodeDataset.load(small, max_bytes=1000)


def test_demo_answers_bad_input_in_one_line(small, tmp_path, capsys):
    folder, _ = small
    for args, match in (
        (["--scene", str(folder / "missing.map")], "no such file"),
        (["--backend", "warp-drive"], "warp-drive"),
        (["--gif", str(tmp_path / "no" / "x.gif")], "--gif"),
        (["--scene", str(folder / "d.json.gz")], "scene"),
    ):
        assert main(["demo", "--episodes", "1", "--quiet", *args]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("pointnav demo: error:") and match in err, err
    with pytest.raises(SystemExit) as info:  # argparse's own one-line usage error
        main(["demo", "--episodes", "0"])
    assert info.value.code == 2
    assert "--episodes: must be an integer >= 1" in capsys.readouterr().err


def _png_header(path: Path, width: int, height: int) -> None:
    """A PNG that declares ``width x height`` 8-bit grey pixels (only the header is real)."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(b"")) + chunk(b"IEND", b""))


def test_one_cell_budget_for_every_grid_and_image(tmp_path):
    budget = r"over the cell budget of 100000000 \(pointnav_core.utils.validation.MAX_CELLS\)"
    png = tmp_path / "floor_trav_0.png"
    _png_header(png, 20000, 20000)  # Pillow's own bomb limit: DecompressionBombError before
    with pytest.raises(ValueError, match=budget):
        read_trav_png(png)
    _png_header(png, 10001, 10000)  # under Pillow's limit, over the budget: not decoded
    with pytest.raises(ValueError, match=r"is 10000 x 10001 = 100010000 cells, " + budget):
        Scene.from_png(png)
    with pytest.raises(ValueError, match=r"grid is 10001 x 10000 = 100010000 cells, " + budget):
        Scene.from_array(np.broadcast_to(np.True_, (10001, 10000)), resolution=0.1)
    big = tmp_path / "big.map"
    big.write_text("type octile\nheight 20000\nwidth 20000\nmap\n")
    with pytest.raises(ValueError, match=r"is 20000 x 20000 = 400000000 cells, " + budget):
        read_movingai(big)
    assert validation.MAX_CELLS == 100_000_000


def test_from_movingai_resolution_must_be_a_number(small):
    folder, _ = small
    for bad in ("0.5", True, 0.0, float("nan")):
        with pytest.raises(ValueError, match=r"^resolution must be a finite number > 0"):
            Scene.from_movingai(folder / "a.map", resolution=bad)


def test_policy_module_in_the_working_folder(small, tmp_path, monkeypatch, capsys):
    """The README's ``--policy my_module:make_policy`` from the folder holding my_module.py,
    as the ``pointnav`` script runs it: without the working folder on sys.path."""
    folder, dataset = small
    (tmp_path / "my_policy_29.py").write_text(
        "import numpy as np\n\ndef make_policy(env):\n"
        "    return lambda obs: np.zeros(env.action_space.shape, dtype=np.float32)\n"
    )
    monkeypatch.chdir(tmp_path)
    here = {"", ".", str(tmp_path), os.path.realpath(tmp_path)}
    monkeypatch.setattr(sys, "path", [p for p in sys.path if p not in here])
    monkeypatch.delitem(sys.modules, "my_policy_29", raising=False)
    args = ["eval", "--dataset", str(dataset), "--scenes-dir", str(folder), "--policy",
            "my_policy_29:make_policy", "--max-steps", "3", "--results", "r.jsonl", "--quiet"]
    assert main(args) == 0, capsys.readouterr().err
    records = [json.loads(line) for line in (tmp_path / "r.jsonl").read_text().splitlines()]
    played = [r for r in records if "episode_id" in r]
    assert len(played) == 1 and played[0]["steps"] == 3  # the policy ran: 3 zero actions
    sys.modules.pop("my_policy_29", None)


def test_compiled_kernels_on_a_read_only_install(tmp_path):
    """No writable ``__pycache__`` next to the package and no writable home: numba's cache
    goes to a private folder in the temporary folder instead of refusing to compile."""
    pytest.importorskip("numba")
    install = tmp_path / "install"
    shutil.copytree(SRC / "pointnav_core", install / "pointnav_core",
                    ignore=shutil.ignore_patterns("__pycache__", "*.json.gz"))
    for folder in [install / "pointnav_core", *(install / "pointnav_core").rglob("*")]:
        if folder.is_dir():
            (folder / "__pycache__").write_text("")  # no cache folder can be made here
    temp = tmp_path / "temp"
    temp.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME")}
    env.update(HOME="/dev/null", TMPDIR=str(temp), PYTHONPATH=str(install), PYTHONDONTWRITEBYTECODE="1")
    code = (
        "from pointnav_core.utils import compiled as _compiled\n"
        "from pointnav_core.sensors import raycast_jit\n"
        "row = _compiled.kernel('pointnav_core.floor._collision_kernel', 'stadium_row')\n"
        "lo, hi = row(0.0, 0.0, 2.0, 0.0, 0.5, 0.25)\n"
        "print(lo, hi, raycast_jit.available())\n"
    )
    run = subprocess.run([sys.executable, "-W", "error", "-c", code], env=env, cwd=tmp_path,
                         capture_output=True, text=True, timeout=120, check=False)
    assert run.returncode == 0, run.stderr
    lo, hi, available = run.stdout.split()
    # A segment along y = 0 swept by a disc of radius 0.5, cut at y = 0.25: the end caps.
    half = (0.5**2 - 0.25**2) ** 0.5
    assert (float(lo), float(hi), available) == (pytest.approx(-half), pytest.approx(2 + half), "True")
    cached = list(temp.glob(f"pointnav_core-numba-{os.getuid()}/**/*.nbi"))
    assert cached, "the compiled kernel was not cached in the private folder"
