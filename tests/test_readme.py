"""Every ```python block of README.md runs as written, each on its own (a reader copies one)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"
BLOCKS = re.findall(r"^```python\n(.*?)^```", README.read_text(encoding="utf-8"), flags=re.S | re.M)


def test_the_readme_has_python_blocks():
    assert len(BLOCKS) >= 5


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_python_block_runs(index):
    code = compile(BLOCKS[index], f"README.md python block {index + 1}", "exec")
    namespace: dict = {"__name__": f"readme_block_{index + 1}"}
    exec(code, namespace)
    env = namespace.get("env") or namespace.get("envs")
    if env is not None and hasattr(env, "close"):
        env.close()
