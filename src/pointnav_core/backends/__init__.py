"""The Backend protocol (the only door between the task and the world it drives), the
registry of backends by name, what a backend knows of a robot (:class:`RobotSpec`), and the
author's kit in :mod:`pointnav_core.backends.kit`.
"""

from pointnav_core.backends.protocol import (
    ENTRY_POINT_GROUP,
    Backend,
    FloatTwinBackend,
    UnknownBackendError,
    available_backends,
    check_backend,
    float_twin,
    get_backend,
)
from pointnav_core.backends.robot_spec import DRIVES, RobotSpec

__all__ = [
    "DRIVES",
    "ENTRY_POINT_GROUP",
    "Backend",
    "FloatTwinBackend",
    "RobotSpec",
    "UnknownBackendError",
    "available_backends",
    "check_backend",
    "float_twin",
    "get_backend",
]
