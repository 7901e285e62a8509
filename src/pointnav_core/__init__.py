"""pointnav-core: physics-free point-goal navigation on 2D floor maps."""

from pointnav_core.errors import BackendError, PointNavError, SamplingError
from pointnav_core.maps import FREE, OBSTACLE, VOID, TraversableMap

__version__ = "0.1.0"

__all__ = [
    "FREE",
    "OBSTACLE",
    "VOID",
    "BackendError",
    "PointNavError",
    "SamplingError",
    "TraversableMap",
    "__version__",
]
