"""The edges of a floor plan's obstacle polygons, indexed for the kinematic backend's hot path.

A floor built from shapely geometry blocks its obstacle polygons exactly, not only their
raster (a wall thinner than a cell covers no cell centre). A disc approaching a polygon from
outside meets its boundary first, so the backend collides with the boundary segments alone.
They are bucketed on a coarse square grid, so that one step's swept box looks at a handful
of buckets instead of every edge of the floor.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray

from pointnav_core.errors import ArgumentError

__all__ = ["EdgeIndex", "Segment"]

#: A polygon edge as stored for the hot path: ``(ax, ay, bx, by, ux, uy, length)``, the
#: ends in metres, the unit direction from a to b and the length in metres.
Segment = tuple[float, float, float, float, float, float, float]


class EdgeIndex:
    """Boundary segments of obstacle polygons, bucketed for axis-aligned box queries.

    Parameters
    ----------
    polygons : sequence of shapely.Polygon
        The floor plan's obstacle polygons, in metres (holes included).
    bucket : float
        Side of a bucket in metres, > 0. About one step's search box is a good size.

    Examples
    --------
    >>> index = EdgeIndex([shapely.box(2.99, 0.0, 3.02, 3.0)], bucket=0.5)
    >>> len(index), len(index.near(1.0, 1.0, 1.4, 1.2))  # buckets away from the wall
    (4, 0)
    >>> sorted(round(s[0], 2) for s in index.near(2.5, 1.0, 3.0, 1.2))  # the two long sides
    [2.99, 3.02]
    """

    def __init__(self, polygons: Sequence[Any], bucket: float) -> None:
        if not (math.isfinite(bucket) and bucket > 0.0):
            raise ArgumentError(f"bucket must be a finite number > 0 (m), got {bucket!r}")
        self.polygons = tuple(polygons)
        self.bucket = float(bucket)
        segments: list[Segment] = []
        for poly in self.polygons:
            for ring in shapely.get_rings(poly):
                xy = shapely.get_coordinates(ring)
                for (ax, ay), (bx, by) in zip(xy[:-1].tolist(), xy[1:].tolist()):
                    length = math.hypot(bx - ax, by - ay)
                    if length > 0.0:  # a repeated vertex adds nothing the neighbours lack
                        segments.append(
                            (ax, ay, bx, by, (bx - ax) / length, (by - ay) / length, length)
                        )
        self.segments = segments
        buckets: dict[tuple[int, int], list[int]] = {}
        inv = 1.0 / self.bucket
        for i, (ax, ay, bx, by, _, _, length) in enumerate(segments):
            # Pieces no longer than a bucket: the buckets under their boxes cover the edge.
            pieces = max(1, math.ceil(length * inv))
            for k in range(pieces):
                x0 = ax + (bx - ax) * k / pieces
                y0 = ay + (by - ay) * k / pieces
                x1 = ax + (bx - ax) * (k + 1) / pieces
                y1 = ay + (by - ay) * (k + 1) / pieces
                gxs = range(math.floor(min(x0, x1) * inv), math.floor(max(x0, x1) * inv) + 1)
                gys = range(math.floor(min(y0, y1) * inv), math.floor(max(y0, y1) * inv) + 1)
                for gx in gxs:
                    for gy in gys:
                        ids = buckets.setdefault((gx, gy), [])
                        if not ids or ids[-1] != i:
                            ids.append(i)
        self._buckets = buckets

    def __len__(self) -> int:
        return len(self.segments)

    def near(self, xmin: float, ymin: float, xmax: float, ymax: float) -> list[Segment]:
        """Segments that may meet the box ``[xmin, xmax] x [ymin, ymax]``, in a fixed order."""
        if not self._buckets:
            return []
        inv = 1.0 / self.bucket
        gx0, gx1 = math.floor(xmin * inv), math.floor(xmax * inv)
        gy0, gy1 = math.floor(ymin * inv), math.floor(ymax * inv)
        buckets = self._buckets
        if gx0 == gx1 and gy0 == gy1:
            ids: Any = buckets.get((gx0, gy0), ())
        else:
            found: set[int] = set()
            for gx in range(gx0, gx1 + 1):
                for gy in range(gy0, gy1 + 1):
                    hit = buckets.get((gx, gy))
                    if hit:
                        found.update(hit)
            ids = sorted(found)  # deterministic order, whatever the set's
        segments = self.segments
        return [segments[i] for i in ids]

    def touched_cells(
        self, shape: tuple[int, int], resolution: float, origin: tuple[float, float]
    ) -> NDArray[np.bool_]:
        """Grid cells (row grows with +y) that any polygon meets, interior included."""
        rows, cols = shape
        mask = np.zeros(shape, dtype=bool)
        ox, oy = origin
        for poly in self.polygons:
            x0, y0, x1, y1 = poly.bounds
            c0 = max(math.floor((x0 - ox) / resolution), 0)
            c1 = min(math.floor((x1 - ox) / resolution), cols - 1)
            r0 = max(math.floor((y0 - oy) / resolution), 0)
            r1 = min(math.floor((y1 - oy) / resolution), rows - 1)
            if c0 > c1 or r0 > r1:
                continue
            rr, cc = np.mgrid[r0 : r1 + 1, c0 : c1 + 1]
            boxes = shapely.box(
                ox + cc * resolution,
                oy + rr * resolution,
                ox + (cc + 1) * resolution,
                oy + (rr + 1) * resolution,
            )
            mask[r0 : r1 + 1, c0 : c1 + 1] |= shapely.intersects(boxes, poly)
        return mask
