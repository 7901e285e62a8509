"""pointnav-core: physics-free point-goal navigation on 2D floor maps.

Importing the package registers the Gymnasium env ``pointnav_core/PointNav-v0`` and the
PettingZoo env ``pointnav_core/MultiPointNav-v0`` (parallel and AEC registries).
"""

from pointnav_core.env import PointNavEnv
from pointnav_core.errors import BackendError, PointNavError, SamplingError
from pointnav_core.maps import FREE, OBSTACLE, VOID, TraversableMap
from pointnav_core.metrics import soft_spl, spl
from pointnav_core.parallel import MultiPointNavEnv
from pointnav_core.registration import register_envs
from pointnav_core.scenes import Scene
from pointnav_core.task import PointNavigationTask, TaskState, TaskStateError

__version__ = "0.1.0"

__all__ = [
    "FREE",
    "MultiPointNavEnv",
    "OBSTACLE",
    "VOID",
    "BackendError",
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
    "soft_spl",
    "spl",
]

register_envs()
