"""The batched engine: many point-navigation worlds stepped as arrays (numpy or torch)."""

from pointnav_core.vector.env import VectorPointNavEnv

__all__ = ["VectorPointNavEnv"]
