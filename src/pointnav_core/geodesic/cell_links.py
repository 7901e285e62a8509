"""Every cell centre's visible links, found once per floor and shared by every goal.

A cell's exact root (:func:`pointnav_core.geodesic.roots.cell_roots`) is the smallest
``(total, order)`` over the direct segment to the goal and the cell centre's *links*: the
tangents from the centre that land on a node's arc and are clear for the robot's disc.
Which links are clear does not depend on the goal; only their totals do (the Dijkstra costs
of the labels on their arcs). :class:`CellLinks` keeps, per usable cell, its clear links as
flat arrays (node, winding, arrival position, tangent length), so that a goal's roots cost
one segment test per cell (the direct segment) plus a small min over its links, instead of
the segment tests of every candidate link.

It is built once per floor and robot radius, in compiled code, where it is small
(:data:`MAX_PAIRS` candidate pairs of cells and nodes: houses and rooms, not thousands of
obstacles in the open), and kept in the disk cache with the rest of the floor's build
(:mod:`pointnav_core.geodesic.cache`). A floor without it settles its roots as before
(:func:`pointnav_core.geodesic.roots.compiled_roots`); both make the same decision (a
property test holds the roots equal).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from tqdm.auto import tqdm

from pointnav_core.floor.collision import TOUCH_TOL
from pointnav_core.geodesic.tangents import ANG_TOL
from pointnav_core.utils import compiled as _compiled

if TYPE_CHECKING:
    from pointnav_core.geodesic.planner import Planner

__all__ = ["BUILD_SECONDS_PER_PAIR", "MAX_PAIRS", "CellLinks", "cell_centres", "centre_cell"]

#: Most (usable cell, node) pairs a floor may have for its links to be built: each pair is a
#: sight-ball test, and the pairs in sight a segment test (about 1 s for the default house's
#: 3.6 million).
MAX_PAIRS = 8_000_000
#: Build time (s) per (usable cell, node) pair, measured on the default house (2.5-3.5 s for
#: 3.6 million pairs on a shared 2-core machine): what a floor's links are estimated to cost.
BUILD_SECONDS_PER_PAIR = 1e-6
#: Cells whose links one compiled call finds (bounds its output arrays).
_CHUNK = 2048
#: Pairs after which the build shows a progress bar (about 2 s of work).
_PROGRESS_PAIRS = 6_000_000
#: The arrays a :class:`CellLinks` is made of, as the disk cache stores them.
FIELDS = ("link_first", "link_count", "link_node", "link_side", "link_pos", "link_length")


class CellLinks:
    """The clear links of every usable cell centre of one floor for one robot radius.

    Attributes
    ----------
    first, count : ndarray of int64 / int32, shape (height * width,)
        Cell ``i``'s links are ``[first[i], first[i] + count[i])`` of the link arrays (count 0
        where the cell is not usable or sees no node).
    node : ndarray of int32
        The node each link lands on.
    side : ndarray of int8
        0 where the path from the cell winds +1 around the node, 1 where it winds -1.
    pos : ndarray of float64
        Where the link lands on the node's arc (rad), as the roots read it.
    length : ndarray of float64
        The tangent's length (m).
    """

    def __init__(self, arrays: dict[str, NDArray]) -> None:
        self.first = np.ascontiguousarray(arrays["link_first"], dtype=np.int64)
        self.count = np.ascontiguousarray(arrays["link_count"], dtype=np.int32)
        self.node = np.ascontiguousarray(arrays["link_node"], dtype=np.int32)
        self.side = np.ascontiguousarray(arrays["link_side"], dtype=np.int8)
        self.pos = np.ascontiguousarray(arrays["link_pos"], dtype=np.float64)
        self.length = np.ascontiguousarray(arrays["link_length"], dtype=np.float64)

    @property
    def nbytes(self) -> int:
        """Memory held (bytes)."""
        return sum(getattr(self, f.removeprefix("link_")).nbytes for f in FIELDS)

    def arrays(self) -> dict[str, NDArray]:
        """The arrays by their disk-cache names (:data:`FIELDS`)."""
        return {f: getattr(self, f.removeprefix("link_")) for f in FIELDS}

    @classmethod
    def fits(cls, planner: Planner) -> bool:
        """Whether ``planner``'s floor gets links: numba, nodes, a compiled floor, and at most
        :data:`MAX_PAIRS` (usable cell, node) pairs."""
        if not planner.n_nodes or not planner.geo.compiled_polygons:
            return False
        if int(planner.usable.sum()) * planner.n_nodes > MAX_PAIRS:
            return False
        return _compiled.kernel("pointnav_core.geodesic._roots_kernel", "cell_links") is not None

    @staticmethod
    def build_estimate(planner: Planner) -> float:
        """Estimated build time (s) of ``planner``'s links (inf where it gets none)."""
        if not CellLinks.fits(planner):
            return math.inf
        return int(planner.usable.sum()) * planner.n_nodes * BUILD_SECONDS_PER_PAIR

    @classmethod
    def build(cls, planner: Planner) -> CellLinks:
        """Find every usable cell centre's clear links (compiled; see :meth:`fits`)."""
        kernel = _compiled.kernel("pointnav_core.geodesic._roots_kernel", "cell_links")
        p = planner
        geo = p.geo
        h, w = geo.shape
        cells = np.flatnonzero(p.usable.ravel())
        xs, ys = cell_centres(p, cells)
        n = p.n_nodes
        every = np.arange(n, dtype=np.int64)
        first = np.zeros(h * w, dtype=np.int64)
        count = np.zeros(h * w, dtype=np.int32)
        parts: list[tuple[NDArray, ...]] = []
        total = 0
        with tqdm(total=len(cells), desc="cell links", unit="cell", leave=False,
                  disable=len(cells) * n < _PROGRESS_PAIRS or None) as bar:
            for i in range(0, len(cells), _CHUNK):
                sub = cells[i : i + _CHUNK]
                k = len(sub)
                lo = np.zeros(k, np.int64)
                hi = np.full(k, n, np.int64)
                cap = 8 * k
                while True:
                    out = (np.empty(cap, np.int32), np.empty(cap, np.int8), np.empty(cap), np.empty(cap))
                    got = np.zeros(k, np.int32)
                    m = kernel(xs[i : i + k], ys[i : i + k], every, lo, hi, p.cx, p.cy, p.phi0, p.span, p.radius,
                               ANG_TOL, TOUCH_TOL, p.sight_reach, p.sight_profile, *geo.kernel_geometry(), *out, got)
                    if m >= 0:
                        break
                    cap = 2 * k * n  # every node, both sides: always enough
                count[sub] = got
                first[sub] = total + np.cumsum(got) - got
                parts.append(tuple(a[:m] for a in out))
                total += m
                bar.update(k)
        node, side, pos, length = (np.concatenate(v) if v else np.empty(0) for v in zip(*parts))
        return cls({"link_first": first, "link_count": count, "link_node": node, "link_side": side,
                    "link_pos": pos, "link_length": length})

    @staticmethod
    def stored(arrays: dict[str, NDArray], n_cells: int, n_nodes: int) -> CellLinks | None:
        """The links kept in a disk-cache entry, or None where it holds none or they do not
        fit the floor (``n_cells`` cells, ``n_nodes`` nodes): the compiled roots index with
        them unchecked, so a damaged entry must not reach them."""
        if not all(f in arrays for f in FIELDS):
            return None
        links = CellLinks(arrays)
        n = len(links.node)
        if not (len(links.first) == len(links.count) == n_cells and len(links.side) == len(links.pos) == len(links.length) == n):
            return None
        if n_cells and (links.first.min() < 0 or links.count.min() < 0 or (links.first + links.count).max() > n):
            return None
        if n and (links.node.min() < 0 or links.node.max() >= n_nodes or not np.isin(links.side, (0, 1)).all()):
            return None
        return links


def cell_centres(planner: Planner, cells: NDArray[np.int64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """World centres (m) of flat cell indices, as the roots compute them."""
    geo = planner.geo
    rows, cols = np.divmod(cells, geo.shape[1])
    return geo.origin[0] + (cols + 0.5) * geo.resolution, geo.origin[1] + (rows + 0.5) * geo.resolution



def centre_cell(planner: Planner, x: float, y: float) -> int:
    """The flat index of the cell whose centre (as :func:`cell_centres` computes it) is
    exactly ``(x, y)`` (m), or -1."""
    geo = planner.geo
    res, (ox, oy) = geo.resolution, geo.origin
    col, row = math.floor((x - ox) / res), math.floor((y - oy) / res)
    h, w = geo.shape
    if not (0 <= row < h and 0 <= col < w):
        return -1
    if ox + (col + 0.5) * res != x or oy + (row + 0.5) * res != y:
        return -1
    return row * w + col
