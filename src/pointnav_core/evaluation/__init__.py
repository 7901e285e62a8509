"""Evaluating a policy on an episode dataset: the run (workers, resumable log), the env it
plays from a saved config, per-episode results and their summary.
"""

from pointnav_core.evaluation.policy_specs import make_policy
from pointnav_core.evaluation.report import (
    EpisodeResult,
    read_results,
    summarize,
    write_results,
)
from pointnav_core.evaluation.run import evaluate

__all__ = [
    "EpisodeResult",
    "evaluate",
    "make_policy",
    "read_results",
    "summarize",
    "write_results",
]
