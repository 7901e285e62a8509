"""Policies for the ``pointnav eval --policy MODULE:CALLABLE`` tests."""

import numpy as np


def standstill(env):
    """A policy that never moves: every episode ends by timeout."""
    return lambda obs: np.zeros(env.action_space.shape, dtype=np.float32)
