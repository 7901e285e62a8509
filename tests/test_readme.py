"""Every ```python block of README.md runs as written, each on its own (a reader copies one)."""

from __future__ import annotations

import re
import runpy
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"
BLOCKS = re.findall(r"^```python\n(.*?)^```", README.read_text(encoding="utf-8"), flags=re.DOTALL | re.MULTILINE)


def test_the_readme_has_python_blocks():
    assert len(BLOCKS) >= 5


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_python_block_runs(index, tmp_path):
    script = tmp_path / f"readme_block_{index + 1}.py"
    script.write_text(BLOCKS[index], encoding="utf-8")
    namespace = runpy.run_path(str(script))
    env = namespace.get("env") or namespace.get("envs")
    if env is not None and hasattr(env, "close"):
        env.close()
