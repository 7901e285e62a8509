"""Crowds: pedestrians that walk a scene's geodesic paths and avoid each other.

- :func:`~pointnav_core.crowds.orca.orca_step`: one step of ORCA (van den Berg et al. 2011)
  as the RVO2 Library computes it, in its float32, for one crowd or a batch of worlds.
- :class:`~pointnav_core.crowds.config.PedestrianConfig` and
  :func:`~pointnav_core.crowds.config.make_pedestrians`: an env's ``pedestrians={...}``.
- :class:`~pointnav_core.crowds.crowd.Crowd`: the pedestrians of one env, placed, planned
  and stepped.
- :mod:`~pointnav_core.crowds.record`: a crowd as placed, one record per pedestrian (start,
  goals, own seed, radius, speed), which a dataset episode stores and a spawn replays.
- :mod:`~pointnav_core.crowds.presets`: standard scenarios (CrowdNav's circle crossing, a
  corridor, a doorway, iGibson's density) with fixed starts and goals.
- :func:`~pointnav_core.crowds.social_force.social_force_step`: one step of the social force
  model (Helbing and Molnár 1995; Moussaïd et al. 2009's repulsion by default) as
  pysocialforce computes it, with its parameters (:class:`SocialForceParams`), walls optional.
"""

from pointnav_core.crowds.config import (
    BEHAVIOURS,
    CrowdView,
    PedestrianConfig,
    make_pedestrians,
)
from pointnav_core.crowds.crowd import Crowd
from pointnav_core.crowds.orca import orca_step
from pointnav_core.crowds.social_force import SocialForceParams, social_force_step

__all__ = [
    "BEHAVIOURS", "Crowd", "CrowdView", "PedestrianConfig", "SocialForceParams", "make_pedestrians", "orca_step",
    "social_force_step",
]
