"""Hypothesis settings profiles for the whole suite.

``dev`` is fast for local runs and draws new examples each time; ``ci`` draws more examples,
has no deadline (CI machines are shared and slow) and is derandomised, so a CI verdict is
reproducible (a red CI is a real, replayable failure, not a flake). Choose with
``HYPOTHESIS_PROFILE``; the default is ``ci`` when the ``CI`` environment variable is set,
else ``dev``.
"""

import os
import tempfile

import pytest
from hypothesis import HealthCheck, settings

# The suite's geometry cache is its own, fresh each run: never a user's, never a stale one.
os.environ["POINTNAV_CACHE_DIR"] = tempfile.mkdtemp(prefix="pointnav-cache-")

settings.register_profile("dev", max_examples=25, deadline=None)
settings.register_profile(
    "ci",
    max_examples=200,
    deadline=None,
    derandomize=True,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile(
    os.environ.get("HYPOTHESIS_PROFILE", "ci" if os.environ.get("CI") else "dev")
)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Tests marked ``long`` run first: queued late, one of them ran alone on one worker for
    minutes at the end of the run while the other core idled (stable sort: the rest keep
    their order)."""
    items.sort(key=lambda item: item.get_closest_marker("long") is None)
