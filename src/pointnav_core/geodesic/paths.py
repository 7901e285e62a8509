"""Polyline helpers shared by planners and controllers: length and even resampling.

Points are ``(N, 2)`` arrays in any consistent unit (world metres everywhere in the
library). OmniGibson returns waypoints spaced evenly along the shortest path and padded with
the target; :func:`resample_path` is that convention.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["path_length", "resample_path"]


def path_length(points: ArrayLike) -> float:
    """Length of a polyline, shape (N, 2), in its own units."""
    pts = np.asarray(points, dtype=np.float64)
    if len(pts) < 2:
        return 0.0
    return float(np.hypot(*np.diff(pts, axis=0).T).sum())


def resample_path(points: ArrayLike, spacing: float, count: int) -> NDArray[np.float64]:
    """First ``count`` points spaced ``spacing`` apart along a polyline, padded with its end.

    Parameters
    ----------
    points : array_like, shape (N, 2)
        The polyline, N >= 1.
    spacing : float
        Arc-length spacing (same units as ``points``), > 0.
    count : int
        Number of points returned, >= 1.

    Returns
    -------
    ndarray, shape (count, 2)
        Points at arc lengths 0, spacing, 2*spacing, ...; past the end of the polyline the
        last point repeats (as OmniGibson pads its waypoints with the target).

    Examples
    --------
    >>> resample_path([[0.0, 0.0], [1.0, 0.0]], 0.4, 4).tolist()
    [[0.0, 0.0], [0.4, 0.0], [0.8, 0.0], [1.0, 0.0]]
    """
    pts = np.asarray(points, dtype=np.float64)
    seg = np.hypot(*np.diff(pts, axis=0).T) if len(pts) > 1 else np.zeros(0)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    s = np.minimum(np.arange(count) * float(spacing), arc[-1])
    x = np.interp(s, arc, pts[:, 0])
    y = np.interp(s, arc, pts[:, 1])
    return np.stack([x, y], axis=1)
