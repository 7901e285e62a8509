"""No module reads another object's private attribute: ruff's SLF001 rule over ``src/``.

A package names an internal function or a public attribute for what others need, so that
its private state can change without breaking a reader elsewhere (docs/architecture.md).
"""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def slf001(*paths: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "ruff", "check", "--isolated", "--select", "SLF001", "--output-format", "concise",
         *map(str, paths)],
        capture_output=True,
        text=True,
    )


def test_src_reads_no_private_attribute_of_another_object():
    run = slf001(ROOT / "src")
    assert run.returncode == 0, run.stdout + run.stderr


def test_the_rule_catches_a_private_read(tmp_path):
    bad = tmp_path / "reader.py"
    bad.write_text("def peek(planner):\n    return planner._edges\n")
    run = slf001(bad)
    assert run.returncode == 1 and "SLF001" in run.stdout, run.stdout + run.stderr
