"""The batched engine: many point-navigation worlds stepped as arrays (numpy or torch)."""

from pointnav_core.vector.env import VectorPointNavEnv
from pointnav_core.vector.refresh import PoolRefreshWarning

__all__ = ["PoolRefreshWarning", "VectorPointNavEnv"]
