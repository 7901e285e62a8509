"""Crowds: agents that avoid each other.

- :func:`~pointnav_core.crowds.orca.orca_step`: one step of ORCA (van den Berg et al. 2011)
  as the RVO2 Library computes it, in its float32, for one crowd or a batch of worlds.
"""

from pointnav_core.crowds.orca import orca_step

__all__ = ["orca_step"]
