"""Hypothesis settings profiles for the whole suite.

``dev`` is fast for local runs; ``ci`` draws more examples and has no deadline (CI machines
are shared and slow). Choose with ``HYPOTHESIS_PROFILE``; the default is ``ci`` when the
``CI`` environment variable is set, else ``dev``.
"""

import os

from hypothesis import HealthCheck, settings

settings.register_profile("dev", max_examples=25, deadline=None)
settings.register_profile(
    "ci",
    max_examples=200,
    deadline=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile(
    os.environ.get("HYPOTHESIS_PROFILE", "ci" if os.environ.get("CI") else "dev")
)
