"""Cells whose centre the robot's disc fits at, and each cell's nearest such cell."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from pointnav_core.floor.collision import FloorCollision

__all__ = ["nearest_usable", "usable_cells"]


def usable_cells(geo: FloorCollision, radius: float) -> NDArray[np.bool_]:
    """``(H, W)`` read-only mask of the cells whose centre a disc of ``radius`` metres fits
    at, tested exactly against ``geo`` (the blocked cells are never usable)."""
    h, w = geo.shape
    rows, cols = np.mgrid[0:h, 0:w]
    centres = np.stack(
        [geo.origin[0] + (cols + 0.5) * geo.resolution, geo.origin[1] + (rows + 0.5) * geo.resolution],
        axis=-1,
    )
    mask = ~geo.blocked
    usable = np.zeros((h, w), dtype=bool)
    usable[mask] = geo.points_clear(centres[mask], radius)
    usable.flags.writeable = False
    return usable


def nearest_usable(usable: NDArray[np.bool_]) -> NDArray[np.int32]:
    """Flat index of each cell's nearest usable cell (Euclidean in cells; -1 everywhere
    when none is usable), int32 of shape ``(H * W,)``."""
    h, w = usable.shape
    if not usable.any():
        return np.full(h * w, -1, dtype=np.int32)
    _, (nr, nc) = ndimage.distance_transform_edt(~usable, return_indices=True)
    return (nr * w + nc).ravel().astype(np.int32)
