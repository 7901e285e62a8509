"""docs/extending.md runs: its Python blocks, in order, as one script."""

import re
from pathlib import Path

PAGE = Path(__file__).resolve().parents[1] / "docs" / "extending.md"


def python_blocks(text: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_every_block_of_extending_md_runs_in_order():
    blocks = python_blocks(PAGE.read_text())
    assert len(blocks) >= 6  # reward, termination, observation, multi-robot, backend, its checks
    namespace: dict = {"__name__": "extending_md"}
    for i, block in enumerate(blocks):
        try:
            exec(compile(block, f"{PAGE.name}[block {i}]", "exec"), namespace)
        except Exception as err:  # pragma: no cover - the message is the point
            raise AssertionError(f"block {i} of {PAGE.name} failed: {err!r}\n{block}") from err
