"""The point-goal navigation task: OmniGibson's ``PointNavigationTask`` as a state machine,
with its lifecycle, configuration, terms (rewards, terminations, observations), metrics,
episode sampling, markers and discrete actions; the social-navigation metrics of a
recorded episode (``social_metrics``).
"""

from pointnav_core.errors import TaskStateError
from pointnav_core.task.config import REWARD_TYPES, TaskConfig
from pointnav_core.task.lifecycle import TaskState
from pointnav_core.task.metrics import soft_spl, spl
from pointnav_core.task.observations import ObservationTerm
from pointnav_core.task.rewards import (
    CollisionReward,
    PointGoalReward,
    PotentialReward,
    RewardFunction,
    SlackReward,
)
from pointnav_core.task.social import (
    SOCIAL_METRIC_KEYS,
    recorded_social_metrics,
    social_metrics,
)
from pointnav_core.task.task import PointNavigationTask
from pointnav_core.task.task_env import TaskEnv
from pointnav_core.task.terminations import (
    Falling,
    MaxCollision,
    PedestrianCollision,
    PointGoal,
    TerminationCondition,
    Timeout,
)

__all__ = [
    "REWARD_TYPES",
    "SOCIAL_METRIC_KEYS",
    "CollisionReward",
    "Falling",
    "MaxCollision",
    "ObservationTerm",
    "PedestrianCollision",
    "PointGoal",
    "PointGoalReward",
    "PointNavigationTask",
    "PotentialReward",
    "RewardFunction",
    "SlackReward",
    "TaskConfig",
    "TaskEnv",
    "TaskState",
    "TaskStateError",
    "TerminationCondition",
    "Timeout",
    "recorded_social_metrics",
    "social_metrics",
    "soft_spl",
    "spl",
]
