"""The default pointnav-core backend: kinematic discs on 2D floor maps, no physics engine.

Registered as ``"kinematic"`` in the entry-point group ``pointnav_core.backends``:

>>> from pointnav_core.backends.protocol import get_backend
>>> get_backend("kinematic") is KinematicBackend
True
"""

from pointnav_kinematic.kinematic import COLLISION_MODES, KinematicBackend

__all__ = ["COLLISION_MODES", "KinematicBackend"]
