"""Hypothesis strategies for pointnav-core values, exported for users' own property tests.

Strategies build valid values directly (rather than filtering) and put the simplest choice
first, so that failures shrink to something readable.
"""

from __future__ import annotations

from hypothesis import strategies as st

__all__: list[str] = []
