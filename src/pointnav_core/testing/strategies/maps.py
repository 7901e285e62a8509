"""Hypothesis strategies for floors: floor plans, cell-code grids, traversable maps and points on them.
"""

from __future__ import annotations

import numpy as np
from hypothesis import note
from hypothesis import strategies as st

from pointnav_core import floorplans
from pointnav_core.errors import ArgumentError
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID, TraversableMap
from pointnav_core.floorplans import FloorPlan

__all__ = [
    "floor_plans",
    "code_grids",
    "traversable_maps",
    "maps_with_points",
]


def floor_plans(
    kinds: tuple[str, ...] = ("rooms", "maze", "clutter"),
) -> st.SearchStrategy[FloorPlan]:
    """Procedurally generated :class:`~pointnav_core.floorplans.FloorPlan` values.

    Draws a generator from ``kinds`` (``"rooms"``, ``"maze"``, ``"clutter"``), a seed and a
    modest size (8 to 20 m a side), keeping every other parameter at its default, so that the
    plans' connectivity guarantee holds: one connected free region for robots narrower than
    the 0.8 m clearance, less grid slack (a 0.2 m radius on a 0.1 m grid is safe). The call
    that rebuilds a failing plan is printed with the falsifying example. Shrinks towards the
    first kind, seed 0 and the smallest size.

    Parameters
    ----------
    kinds : tuple of str
        A non-empty subset of ``("rooms", "maze", "clutter")``.
    """
    valid = ("rooms", "maze", "clutter")
    kinds = tuple(kinds)
    unknown = [k for k in kinds if k not in valid]
    if not kinds or unknown:
        raise ArgumentError(f"kinds must be a non-empty subset of {valid}, got {kinds!r}")
    return _floor_plans(kinds)


@st.composite
def _floor_plans(draw: st.DrawFn, kinds: tuple[str, ...]) -> FloorPlan:
    kind = draw(st.sampled_from(kinds))
    seed = draw(st.integers(0, 2**32 - 1))
    width = draw(st.floats(8.0, 20.0))
    height = draw(st.floats(8.0, 20.0))
    note(f"pointnav_core.floorplans.{kind}({seed}, size=({width!r}, {height!r}))")
    return getattr(floorplans, kind)(seed, size=(width, height))


# ----------------------------------------------------------------------- transforms


@st.composite
def code_grids(draw: st.DrawFn, min_side: int = 2, max_side: int = 24) -> np.ndarray:
    """Cell-code grids (uint8, FREE/OBSTACLE/VOID) made of a free floor and a few rectangles.

    At least one cell is FREE. Shrinks towards a small, all-free grid.
    """
    h = draw(st.integers(min_side, max_side))
    w = draw(st.integers(min_side, max_side))
    grid = np.full((h, w), FREE, dtype=np.uint8)
    for _ in range(draw(st.integers(0, 6))):
        r0, c0 = draw(st.integers(0, h - 1)), draw(st.integers(0, w - 1))
        r1, c1 = draw(st.integers(r0, h - 1)), draw(st.integers(c0, w - 1))
        grid[r0 : r1 + 1, c0 : c1 + 1] = draw(st.sampled_from((OBSTACLE, VOID)))
    if not (grid == FREE).any():
        grid[draw(st.integers(0, h - 1)), draw(st.integers(0, w - 1))] = FREE
    return grid


@st.composite
def traversable_maps(draw: st.DrawFn, max_side: int = 24) -> TraversableMap:
    """Small :class:`~pointnav_core.floor.maps.TraversableMap` values with a random origin."""
    grid = draw(code_grids(max_side=max_side))
    resolution = draw(st.sampled_from((0.1, 0.05, 0.25, 1.0)))
    origin = (draw(st.floats(-50.0, 50.0)), draw(st.floats(-50.0, 50.0)))
    height = draw(st.floats(-5.0, 5.0))
    return TraversableMap(grid, resolution, origin, height)


@st.composite
def maps_with_points(
    draw: st.DrawFn, n_points: int = 2, max_side: int = 24, max_radius_cells: float = 2.5
) -> tuple[TraversableMap, float, np.ndarray]:
    """A map, a robot radius (m) and ``n_points`` usable world points (n, 2) on it.

    The radius is chosen so that some cell is usable; points lie anywhere inside usable
    cells (not only at centres) where the disc fits, else at the cell's centre.
    """
    tmap = draw(traversable_maps(max_side=max_side))
    radius = draw(st.floats(0.0, max_radius_cells)) * tmap.resolution
    if not tmap.usable(radius).any():
        radius = 0.0
    cells = np.argwhere(tmap.usable(radius))
    points = []
    for _ in range(n_points):
        r, c = cells[draw(st.integers(0, len(cells) - 1))]
        fr, fc = draw(st.floats(0.05, 0.95)), draw(st.floats(0.05, 0.95))
        point = tmap.grid_to_world(np.array([r + fr, c + fc]))
        if not tmap.is_usable(point, radius):
            point = tmap.cell_to_world(np.array([r, c]))
        points.append(point)
    return tmap, radius, np.array(points)


# ----------------------------------------------------------------------- navigation episodes
