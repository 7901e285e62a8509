"""Floor plans as shapely geometry: seeded procedural generators, and rasterisation to a grid.

A :class:`FloorPlan` is a floor outline (outside it there is no floor: VOID) and obstacle
polygons inside it (walls and furniture: OBSTACLE). :func:`rasterize` turns any outline and
obstacles into the cell codes of a :class:`~pointnav_core.floor.maps.TraversableMap`.

Three generators build house-like plans, deterministically for a seed:

==============  ==================================================================
:func:`rooms`   a house (rectangular or L-shaped) split into rooms by interior
                walls, one door per wall, furniture kept off the doors
:func:`maze`    a perfect maze (exactly one route between any two places)
:func:`clutter` an open hall with many boxes and discs
==============  ==================================================================

Every plan is centred on the world origin and its outline is the outer boundary of its outer
walls. The free space of every generated plan is one connected region for a robot narrower
than the plan's clearance (``clearance`` for :func:`rooms`, ``corridor`` for :func:`maze`,
``gap`` for :func:`clutter`; 0.8 m or more at the defaults). Each generator guarantees this
by construction; on a grid, allow about two cells of slack (a robot of radius 0.2 m on a
0.1 m grid is safe at the defaults), which the test suite checks on rasterised, eroded grids.

Modules: :mod:`~pointnav_core.floorplans.plan` (:class:`FloorPlan`, :func:`rasterize`), one
per generator (:mod:`~pointnav_core.floorplans.rooms`, :mod:`~pointnav_core.floorplans.maze`,
:mod:`~pointnav_core.floorplans.clutter`) and :mod:`~pointnav_core.floorplans.args` (their
argument checks).
"""

from pointnav_core.floorplans.clutter import clutter
from pointnav_core.floorplans.maze import maze
from pointnav_core.floorplans.plan import FloorPlan, rasterize
from pointnav_core.floorplans.rooms import rooms

__all__ = ["FloorPlan", "clutter", "maze", "rasterize", "rooms"]
