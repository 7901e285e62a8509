"""Cheap exact bounds on a geodesic before its goal field is built (ALT landmarks).

A sampler that wants geodesics in a range (``path_range``) draws a start and a goal and
keeps the pair when its exact geodesic lies in the range. A goal field costs a graph
search, so a rejected goal used to cost as much as a kept one: on the default house a third
of the goals drawn were rejected, a fifth of a reset. :class:`Landmarks` rejects most of them
first, from the triangle inequality (A* with landmarks, Goldberg and Harrelson, 2005): for
any point ``L``,

    |d(L, a) - d(L, b)|  <=  d(a, b)  <=  d(L, a) + d(L, b).

The landmarks are a few usable cell centres spread over the floor (farthest-point order,
straight-line, so that no randomness is drawn); their goal fields are built once per floor
and radius, and a bound costs one compiled exact query per landmark for the two points (a
few tens of microseconds). Both bounds are widened by :data:`SLACK` against rounding, so that
a pair is never rejected that the exact geodesic would keep: the episodes drawn do not
change, only the fields built for goals that could never pass.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from pointnav_core.geodesic.cell_links import centre_cell
from pointnav_core.geodesic.field import GoalField, compiled_distances
from pointnav_core.geodesic.roots import TableRoots

if TYPE_CHECKING:
    from pointnav_core.geodesic.planner import Planner

__all__ = ["COUNT", "SLACK", "Landmarks"]

#: Landmarks per floor and radius (4 catch three quarters of the rejected goals on the
#: default house; 16 catch 85 %, at four times the cost per bound).
COUNT = 4
#: Widening (m, and relative) of both bounds, far above the exact values' rounding.
SLACK = 1e-6


class Landmarks:
    """Lower and upper bounds (m) on the geodesic between two points of one floor.

    Parameters
    ----------
    planner : Planner
        The floor's tangent graph for the robot's radius.
    count : int
        How many landmarks (default :data:`COUNT`).
    """

    def __init__(self, planner: Planner, count: int = COUNT) -> None:
        self.planner = planner
        self.count = count
        self._fields: list[GoalField] | None = None
        self._queries: list[TableRoots] | None = None

    @property
    def available(self) -> bool:
        """Whether bounds cost little: the exact point queries run compiled (numba).

        Without numba a bound would cost about as much as the field it spares, so
        :meth:`bounds` then answers ``(0, inf)`` without any work."""
        return GoalField.queries_compiled(self.planner)

    @property
    def fields(self) -> list[GoalField]:
        """The landmarks' goal fields (built on first use, outside the planner's cache)."""
        if self._fields is None:
            fields = [GoalField(self.planner, xy) for xy in spread_points(self.planner, self.count)]
            self._fields = [f for f in fields if f.goal_usable]
        return self._fields

    def distances(self, xs: NDArray[np.float64], ys: NDArray[np.float64]) -> NDArray[np.float64]:
        """Exact distances (m), ``(landmarks, points)``, from the landmarks to clear points."""
        p = self.planner
        links = p.cell_links(build=False)
        if links is None:
            return compiled_distances(self.fields, xs, ys)
        cells = np.array([centre_cell(p, x, y) for x, y in zip(xs.tolist(), ys.tolist())], dtype=np.int64)
        if (cells < 0).any():
            return compiled_distances(self.fields, xs, ys)
        if self._queries is None or self._queries[0].links is not links:
            self._queries = [TableRoots(f, f.arc_tables(), links) for f in self.fields]
        return np.stack([query(cells, xs, ys)[2] for query in self._queries])

    def bounds(self, a: tuple[float, float], b: tuple[float, float]) -> tuple[float, float]:
        """``(lower, upper)`` bounds (m) on the exact geodesic between world points ``a``
        and ``b``.

        ``(inf, inf)`` when a landmark reaches one point and not the other (no path joins
        them); ``(0, inf)`` when nothing is known (no numba, or a point where the robot
        does not fit).
        """
        if not self.available or not self.fields:
            return 0.0, math.inf
        p = self.planner
        if not (p.is_clear(a[0], a[1]) and p.is_clear(b[0], b[1])):
            return 0.0, math.inf
        xs = np.array([a[0], b[0]], dtype=np.float64)
        ys = np.array([a[1], b[1]], dtype=np.float64)
        lower, upper, scale = 0.0, math.inf, 0.0
        for da, db in self.distances(xs, ys).tolist():
            fa, fb = math.isfinite(da), math.isfinite(db)
            if fa != fb:
                return math.inf, math.inf
            if fa:
                lower = max(lower, abs(da - db))
                upper = min(upper, da + db)
                scale = max(scale, da, db)
        slack = SLACK * (1.0 + scale)
        return max(lower - slack, 0.0), upper + slack


def spread_points(planner: Planner, count: int) -> NDArray[np.float64]:
    """Up to ``count`` usable cell centres (m, ``(k, 2)``) spread over the floor:
    the one with the least ``x + y`` first, then each farthest (straight-line) from those
    already taken."""
    usable = np.flatnonzero(planner.usable.ravel())
    if not len(usable):
        return np.zeros((0, 2))
    geo = planner.geo
    rows, cols = np.divmod(usable, geo.shape[1])
    xs = geo.origin[0] + (cols + 0.5) * geo.resolution
    ys = geo.origin[1] + (rows + 0.5) * geo.resolution
    chosen = [int(np.argmin(xs + ys))]
    gap = np.hypot(xs - xs[chosen[0]], ys - ys[chosen[0]])
    for _ in range(min(count, len(usable)) - 1):
        far = int(np.argmax(gap))
        if gap[far] == 0.0:
            break
        chosen.append(far)
        np.minimum(gap, np.hypot(xs - xs[far], ys - ys[far]), out=gap)
    return np.stack([xs[chosen], ys[chosen]], axis=-1)
