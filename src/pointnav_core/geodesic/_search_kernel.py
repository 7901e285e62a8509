"""The compiled goal-field search of :mod:`pointnav_core.geodesic.arc_graph` (imports numba).

Imported only through :func:`pointnav_core.utils.compiled.kernel` when numba is installed (the
``fast`` extra). :func:`seeded_dijkstra` is ``arc_graph.seeded_dijkstra`` itself, compiled:
a binary-heap Dijkstra on the graph built once per floor, seeded with the goal's tangents,
so that a new goal builds no matrix. :func:`seeded_astar` is ``arc_search.seeded_astar``
itself, compiled: one point-to-point search on the same graph.
"""

from __future__ import annotations

import numba
from numba.extending import register_jitable

from pointnav_core.geodesic import arc_graph, arc_search

__all__ = ["seeded_astar", "seeded_dijkstra"]

seeded_dijkstra = numba.njit(cache=True, nogil=True)(arc_graph.seeded_dijkstra)
register_jitable(cache=True, nogil=True)(arc_search.relax)
seeded_astar = numba.njit(cache=True, nogil=True)(arc_search.seeded_astar)
