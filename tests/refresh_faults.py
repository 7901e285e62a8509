"""Pool builds that misbehave, for tests/test_vector_refresh_faults.py.

A module of its own: the refresh worker is a spawned process, which imports what it runs by
name (the tests folder is on the path, ``pythonpath`` in pyproject.toml).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from pointnav_core.errors import SamplingError


class StalledBuild:
    """A pool build that writes ``marker`` once it has started, then sleeps (to be killed)."""

    def __init__(self, marker: Path) -> None:
        self.marker = marker

    def __call__(self, samplers: Any, pool_size: int, seeds: Any, arrays: Any) -> Any:
        self.marker.write_text("building")
        time.sleep(120.0)
        raise AssertionError("the stalled build was not killed")


def failing_build(samplers: Any, pool_size: int, seeds: Any, arrays: Any) -> Any:
    """A pool build that raises, as a sampler that finds no episode would."""
    raise SamplingError("no goal within path_range after 3 trials (injected)")
