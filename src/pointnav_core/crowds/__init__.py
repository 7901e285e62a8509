"""Crowds: pedestrians that walk a scene's geodesic paths and avoid each other.

- :func:`~pointnav_core.crowds.orca.orca_step`: one step of ORCA (van den Berg et al. 2011)
  as the RVO2 Library computes it, in its float32, for one crowd or a batch of worlds.
- :class:`~pointnav_core.crowds.config.PedestrianConfig` and
  :func:`~pointnav_core.crowds.config.make_pedestrians`: an env's ``pedestrians={...}``.
- :class:`~pointnav_core.crowds.crowd.Crowd`: the pedestrians of one env, placed, planned
  and stepped.
"""

from pointnav_core.crowds.config import (
    BEHAVIOURS,
    CrowdView,
    PedestrianConfig,
    make_pedestrians,
)
from pointnav_core.crowds.crowd import Crowd
from pointnav_core.crowds.orca import orca_step

__all__ = ["BEHAVIOURS", "Crowd", "CrowdView", "PedestrianConfig", "make_pedestrians", "orca_step"]
