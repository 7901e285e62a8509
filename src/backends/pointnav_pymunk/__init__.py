"""A pymunk backend for pointnav-core: robots as rigid discs with real contacts.

Registered as ``"pymunk"`` in the entry-point group ``pointnav_core.backends``:

>>> from pointnav_core.backends.protocol import get_backend
>>> get_backend("pymunk") is PymunkBackend
True
"""

from pointnav_pymunk.backend import OVERLAP_TOLERANCE, PymunkBackend
from pointnav_pymunk.floor import CONTACT_SLOP, TOUCH_TOLERANCE

__all__ = ["CONTACT_SLOP", "OVERLAP_TOLERANCE", "TOUCH_TOLERANCE", "PymunkBackend"]
