"""pointnav-core: physics-free point-goal navigation on 2D floor maps.

The core (maps, scenes, geodesics, transforms, the task, metrics, backends) imports neither
Gymnasium, PettingZoo nor Pillow. The envs ``PointNavEnv`` and ``MultiPointNavEnv`` load on
first use, and the ids ``pointnav_core/PointNav-v0`` (Gymnasium) and
``pointnav_core/MultiPointNav-v0`` (PettingZoo, parallel and AEC) are registered with each
library as soon as both it and this package are imported (see ``registration``).
"""

from pointnav_core.envs.registration import register_envs, register_when_imported
from pointnav_core.errors import (
    ArgumentError,
    ArgumentTypeError,
    BackendError,
    PointNavError,
    SamplingError,
)
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID, TraversableMap
from pointnav_core.scenes import Scene
from pointnav_core.task import PointNavigationTask, TaskState, TaskStateError
from pointnav_core.task.metrics import soft_spl, spl
from pointnav_core.task.social import SOCIAL_METRIC_KEYS, social_metrics
from pointnav_core.utils.lazy import lazy_exports

__version__ = "0.1.0"

__all__ = [
    "FREE",
    "OBSTACLE",
    "SOCIAL_METRIC_KEYS",
    "VOID",
    "ArgumentError",
    "ArgumentTypeError",
    "BackendError",
    "EnvConfig",
    "MultiPointNavEnv",
    "PointNavEnv",
    "PointNavError",
    "PointNavigationTask",
    "SamplingError",
    "Scene",
    "TaskState",
    "TaskStateError",
    "TraversableMap",
    "__version__",
    "register_envs",
    "social_metrics",
    "soft_spl",
    "spl",
]

#: Exports that load Gymnasium or PettingZoo (EnvConfig checks its fields with the envs' own
#: code), imported on first access.
__getattr__, __dir__ = lazy_exports(
    "pointnav_core",
    {
        "PointNavEnv": "pointnav_core.envs.pointnav",
        "MultiPointNavEnv": "pointnav_core.envs.multi_pointnav",
        "EnvConfig": "pointnav_core.envs.config",
    },
    globals(),
)

register_when_imported()
