"""docs/your-own-map.md runs: its Python blocks, in order, as one script from the repository root."""

from __future__ import annotations

import re
import runpy
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "your-own-map.md"


def test_every_block_of_your_own_map_runs_in_order(tmp_path, monkeypatch, capsys):
    blocks = re.findall(r"^```python\n(.*?)^```", PAGE.read_text(encoding="utf-8"), flags=re.DOTALL | re.MULTILINE)
    assert len(blocks) == 5  # load, floor plan, dataset, evaluation, training
    script = tmp_path / "your_own_map.py"
    script.write_text("\n".join(blocks), encoding="utf-8")
    monkeypatch.chdir(ROOT)
    namespace = runpy.run_path(str(script))
    out = capsys.readouterr().out
    assert "(384, 384) 0.05 (-10.0, -10.0)" in out and "\n4.0\n" in out and "\n1.0\n" in out
    assert namespace["agent"] is not None and len(namespace["dataset"]) == 6
