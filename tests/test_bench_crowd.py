"""``benchmarks/bench_crowd.py --quick`` runs end to end and prints every row of its table.

A smoke test only: the rates of a 16-world, one-round run say nothing; the full run's
figures are in docs/decisions.md (## Crowds).
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("torch")

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_crowd.py"


def test_the_quick_run_prints_every_row() -> None:
    # The child imports pointnav_core from where this process does.
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    run = subprocess.run([sys.executable, str(SCRIPT), "--quick"], check=False, capture_output=True, text=True, env=env,
                         timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    rows = [line for line in run.stdout.splitlines() if line.startswith("| ")]
    expected = [
        "batched engine, 12-ray scan (16 x 4) |",
        "batched engine, 12-ray scan, 10 pedestrians per world (16 x 4) | ",
        "single env, no pedestrians |",
        "single env, 10 ORCA pedestrians |",
        "single env, 10 social-force pedestrians |",
    ]
    if importlib.util.find_spec("vmas") is not None:
        expected += ["VMAS navigation, 12-ray lidar (16 x 4) |", "VMAS navigation + 10 pedestrians (no lidar)"]
    for text in expected:
        assert any(text in row for row in rows), f"no row with {text!r} in:\n{run.stdout}"
    assert all(" ms |" in row for row in rows if row.startswith("| single env")), run.stdout
