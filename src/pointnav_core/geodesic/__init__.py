"""Exact geodesics of a disc robot on a floor: the tangent graph, goal fields and lookups.

The API (the model, its accuracy and cost: ``docs/geodesic.md``):

- :class:`Planner` (one per floor and robot radius, :func:`planner_for` caches it on the
  floor): exact shortest paths between two points, and the goal fields it caches;
- :class:`GoalField`: exact distances and paths from any point to one goal, and the
  per-step lookup (:meth:`GoalField.distance`) within :data:`LOOKUP_BOUND`;
- :data:`MIN_RADIUS`, :data:`FIELD_CACHE_BYTES`, :data:`GEOMETRY_BYTES`, :data:`BLOCK`: the
  planner's smallest radius, the default byte budgets of the goal-field cache and of a
  floor's geometry (set ``Planner.field_cache_bytes`` and ``Planner.geometry_bytes`` to
  change them), the lookup table's block side.

Inside, one module per step: ``tangents`` (the shared constructions and tolerances),
``sight`` (strict sight bounds), ``edges`` (common tangents), ``edge_store`` (a node's edges
as lists, made from the disk cache's arrays when first read), ``cell_links`` (each cell's
clear links, once per floor), ``arcs`` (drawing arcs),
``arc_graph`` (the graph solved by Dijkstra), ``roots`` (exact cell roots), ``field``,
``point_search`` (one exact path between two points: lazily, tile by tile) and
``arc_search`` (the same on the whole graph, compiled), ``cache`` (the disk cache) and
``planner``.
"""

from pointnav_core.geodesic.field import BLOCK, LOOKUP_BOUND, GoalField
from pointnav_core.geodesic.planner import (
    FIELD_CACHE_BYTES,
    GEOMETRY_BYTES,
    MIN_RADIUS,
    Planner,
    planner_for,
)

__all__ = [
    "BLOCK", "FIELD_CACHE_BYTES", "GEOMETRY_BYTES", "LOOKUP_BOUND", "MIN_RADIUS", "GoalField", "Planner", "planner_for",
]
