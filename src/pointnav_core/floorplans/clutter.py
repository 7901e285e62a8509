"""The ``clutter`` generator: an open hall with many boxes and discs."""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely import affinity
from shapely.geometry import Point, Polygon, box

from pointnav_core.errors import ArgumentError
from pointnav_core.floorplans.args import (
    Seed,
    check_pair,
    check_positive,
    check_probability,
    check_range,
    rng_from,
)
from pointnav_core.floorplans.plan import FloorPlan, walled_box

__all__ = ["clutter"]


def clutter(
    seed: Seed = None,
    size: tuple[float, float] = (20.0, 20.0),
    *,
    n_obstacles: int | None = None,
    obstacle_size: tuple[float, float] = (0.3, 1.5),
    discs: float = 0.3,
    grouped: float = 0.3,
    gap: float = 0.8,
    wall: float = 0.2,
) -> FloorPlan:
    """Generate an open hall cluttered with boxes (randomly rotated) and discs.

    Shapes stand at least ``gap`` from the walls and from each other, except that some
    (a fraction ``grouped`` of the tries) are laid across an existing group of shapes: through
    the point its first shape is centred on, and at least half outside it. A group becomes one
    obstacle polygon: the union of its shapes, closed with a disc of diameter ``gap`` so that
    the narrow wedges between shapes are filled. Groups have no holes or pockets and stand
    ``gap`` apart, so the free space stays one connected region for every robot narrower than
    ``gap``.

    Parameters
    ----------
    seed : int, numpy SeedSequence or Generator, or None
        Seed of ``np.random.default_rng``; the same seed gives the same plan.
    size : (float, float), default (20.0, 20.0)
        Outer width (x) and height (y), in metres.
    n_obstacles : int or None, default None
        How many shapes to place, >= 0; None places one per 8 m² of floor (50 at the default
        size). Up to ``20 * n_obstacles`` positions are tried; when the hall fills up first,
        fewer are placed.
    obstacle_size : (float, float), default (0.3, 1.5)
        Range of box sides and disc diameters (m).
    discs : float, default 0.3
        Probability that an obstacle is a disc rather than a box.
    grouped : float, default 0.3
        Probability that an obstacle is laid across an existing group.
    gap : float, default 0.8
        Smallest passage between groups, and between a group and the walls (m).
    wall : float, default 0.2
        Outer wall thickness (m).

    Returns
    -------
    FloorPlan
        Outline: the hall's outer boundary, centred on the origin. Obstacles: the outer wall
        ring, then one polygon per group of shapes (a single box or disc for most).

    Raises
    ------
    ValueError
        When a parameter is out of range; the message names it.

    Examples
    --------
    >>> plan = clutter(seed=3, n_obstacles=10, grouped=0.0)
    >>> len(plan.obstacles)  # the wall ring and 10 shapes
    11
    >>> len(clutter(seed=3, n_obstacles=10, grouped=1.0).obstacles)  # all in one group
    2
    """
    rng = rng_from(seed)
    width, height = check_pair(size, "size", "(width, height) in metres")
    n_obstacles = _check_count(n_obstacles, width, height)
    size_lo, size_hi = check_range(obstacle_size, "obstacle_size")
    discs = check_probability(discs, "discs")
    grouped = check_probability(grouped, "grouped")
    gap = check_positive(gap, "gap")
    wall = check_positive(wall, "wall")
    margin = wall + gap  # shapes keep ``gap`` from the wall
    hall = (-width / 2 + margin, -height / 2 + margin, width / 2 - margin, height / 2 - margin)
    if hall[2] - hall[0] < size_hi or hall[3] - hall[1] < size_hi:
        raise ArgumentError(
            f"size must leave room for the largest obstacle: at least "
            f"obstacle_size[1] + 2 * (wall + gap) = {size_hi + 2 * (wall + gap)} m a side, got {size!r}"
        )
    outline, ring = walled_box(width, height, wall)
    groups = _place_groups(rng, n_obstacles, hall, (size_lo, size_hi), discs, grouped, gap)
    return FloorPlan(outline=outline, obstacles=(ring, *groups))


def _check_count(n_obstacles: int | None, width: float, height: float) -> int:
    """``n_obstacles``, or one per 8 m² of the ``width x height`` m floor when None."""
    if n_obstacles is None:
        n_obstacles = round(width * height / 8.0)
    if (
        isinstance(n_obstacles, bool)
        or not isinstance(n_obstacles, (int, np.integer))
        or n_obstacles < 0
    ):
        raise ArgumentError(f"n_obstacles must be an integer >= 0 or None, got {n_obstacles!r}")
    return n_obstacles


def _place_groups(
    rng: np.random.Generator,
    n_obstacles: int,
    hall: tuple[float, float, float, float],
    extents: tuple[float, float],
    discs: float,
    grouped: float,
    gap: float,
) -> list[Polygon]:
    """Place up to ``n_obstacles`` shapes in ``hall`` (m), in up to 20 tries each.

    Returns one polygon per group: a single shape, or the closed union of several.
    """
    groups: list[Polygon] = []
    anchors: list[tuple[float, float]] = []  # the point every shape of a group contains
    placed = 0
    for _ in range(20 * int(n_obstacles)):
        if placed == n_obstacles:
            break
        g, shape, centre = _draw_shape(rng, groups, anchors, hall, extents, discs, grouped)
        xmin, ymin, xmax, ymax = shape.bounds
        if xmin < hall[0] or ymin < hall[1] or xmax > hall[2] or ymax > hall[3]:
            continue
        if g >= 0:
            candidate = _joined(groups[g], anchors[g], shape, gap)
            if candidate is None:
                continue
        else:
            candidate = shape
        others = [group for k, group in enumerate(groups) if k != g]
        if others and (shapely.distance(np.array(others, dtype=object), candidate) < gap).any():
            continue
        placed += 1
        if g >= 0:
            groups[g] = candidate
        else:
            groups.append(candidate)
            anchors.append(centre)
    return groups


def _draw_shape(
    rng: np.random.Generator,
    groups: list[Polygon],
    anchors: list[tuple[float, float]],
    hall: tuple[float, float, float, float],
    extents: tuple[float, float],
    discs: float,
    grouped: float,
) -> tuple[int, Polygon, tuple[float, float]]:
    """Draw one shape: ``(group, shape, centre)``, group -1 for a shape standing alone.

    A shape laid across group ``g`` contains that group's anchor.
    """
    join = groups and rng.random() < grouped
    is_disc = rng.random() < discs
    extent, other = rng.uniform(extents[0], extents[1], size=2)
    angle = rng.uniform(0.0, math.pi)
    if join:
        g = int(rng.integers(len(groups)))
        # Put the anchor at a random point well inside the new shape (in its own frame).
        u, v = rng.uniform(-0.8, 0.8, size=2)
        if is_disc:
            v = 0.0  # a point on the diameter at ``angle``
        du, dv = u * extent / 2, v * other / 2
        ax, ay = anchors[g]
        cx = ax - (du * math.cos(angle) - dv * math.sin(angle))
        cy = ay - (du * math.sin(angle) + dv * math.cos(angle))
    else:
        g = -1
        cx, cy = rng.uniform(hall[0], hall[2]), rng.uniform(hall[1], hall[3])
    if is_disc:
        shape = Point(cx, cy).buffer(extent / 2, quad_segs=8)
    else:
        shape = affinity.rotate(
            box(cx - extent / 2, cy - other / 2, cx + extent / 2, cy + other / 2),
            angle,
            origin=(cx, cy),
            use_radians=True,
        )
    return g, shape, (cx, cy)


def _joined(
    group: Polygon, anchor: tuple[float, float], shape: Polygon, gap: float
) -> Polygon | None:
    """The group with ``shape`` laid across it, or None when the shape does not hold the
    group's anchor or is mostly inside the group (a pile, not a new part)."""
    if not shape.contains(Point(anchor)):
        return None
    if shape.difference(group).area < 0.5 * shape.area:  # mostly new, not a pile
        return None
    # Close the union with a disc of radius gap / 2: this fills the narrow wedges
    # between shapes, whose tips a robot could enter but not turn round in (on a grid
    # they leave isolated usable cells). The closing stays in the convex hull.
    union = shapely.union(group, shape)
    closed = union.buffer(gap / 2, quad_segs=8).buffer(-gap / 2, quad_segs=8)
    # Rounding in the buffers can leave specks beside the body, or pinholes in it.
    body = max(shapely.get_parts(shapely.union(closed, union)), key=lambda p: p.area)
    return Polygon(body.exterior)
