"""Proofs that two points are not connected, at the cost of one label lookup each.

:meth:`TraversableMap.components` under-connects (a passage no row of cell centres runs
through may split a component, and the planner still finds the way), so differing labels
there prove nothing. Here the components *over*-connect: a cell is kept when its square
may hold a point where the robot's disc fits, and kept cells are joined across sides and
corners. Every collision-free path of the disc's centre runs through kept squares, from one
to a neighbour, so two points whose squares are in different components cannot be joined.

A cell's square holds such a point only if its centre is within ``res / sqrt(2)`` of it, and
clearance is 1-Lipschitz, so the cell is kept when the centre's clearance from the grid's
blocked cells (non-FREE squares and off the map) is at least ``radius - res / sqrt(2)``. The
centre's clearance is at most ``D - res / 2`` for ``D`` the distance to the nearest blocked
cell's centre, which is what is compared. Polygon obstacles only shrink the free space
further, so ignoring them keeps the proof sound. The labels are built once per floor and
radius (a 1024 x 1024 floor: about 0.1 s) and live as long as the map.
"""

from __future__ import annotations

import math
import weakref
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from pointnav_core.floor.maps import FREE, TraversableMap

__all__ = ["disconnected", "reach_labels"]

_LABELS: weakref.WeakKeyDictionary[TraversableMap, dict[float, NDArray[np.int32]]] = weakref.WeakKeyDictionary()


def reach_labels(tmap: TraversableMap, radius: float) -> NDArray[np.int32]:
    """Over-connected components of ``tmap`` for a disc of ``radius`` m (0: no cell kept)."""
    key = round(float(radius), 12)
    per_map = _LABELS.setdefault(tmap, {})
    if key not in per_map:
        free = np.pad(tmap.codes == FREE, 1, constant_values=False)
        centre_gap = np.asarray(ndimage.distance_transform_edt(free))[1:-1, 1:-1]  # cells
        reach = (centre_gap - 0.5) + math.sqrt(0.5) >= key / tmap.resolution - 1e-9
        labels, _ = ndimage.label(reach & (tmap.codes == FREE), structure=np.ones((3, 3), bool))
        labels = labels.astype(np.int32)
        labels.flags.writeable = False
        per_map[key] = labels
    return per_map[key]


def _labels_at(tmap: TraversableMap, labels: NDArray[np.int32], xy: Any) -> set[int]:
    """Labels of the cells whose closed square holds ``xy`` (up to four on a corner)."""
    # (col, row) in cells, on floats: the numbers numpy's arrays give, without their set-up.
    gx = (float(xy[0]) - tmap.origin[0]) / tmap.resolution
    gy = (float(xy[1]) - tmap.origin[1]) / tmap.resolution
    cols = {math.floor(gx), math.ceil(gx) - 1}
    rows = {math.floor(gy), math.ceil(gy) - 1}
    h, w = labels.shape
    return {int(labels[r, c]) for r in rows for c in cols if 0 <= r < h and 0 <= c < w} - {0}


def disconnected(tmap: TraversableMap, radius: float, a: Any, b: Any) -> bool:
    """True only when no collision-free path of the disc's centre joins ``a`` and ``b``
    (world (x, y), m); False when they may be connected (or either point is not on a kept
    cell: then the caller's own checks decide)."""
    labels = reach_labels(tmap, radius)
    la, lb = _labels_at(tmap, labels, a), _labels_at(tmap, labels, b)
    return bool(la) and bool(lb) and not (la & lb)
