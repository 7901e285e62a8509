"""The ``maze`` generator: a perfect maze of corridors."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from shapely.geometry import Polygon, box

from pointnav_core.errors import ArgumentError
from pointnav_core.floorplans.args import (
    Seed,
    check_pair,
    check_positive,
    rng_from,
)
from pointnav_core.floorplans.plan import SNAP_TOL, FloorPlan, walled_box

__all__ = ["maze"]


def maze(
    seed: Seed = None,
    size: tuple[float, float] = (16.0, 16.0),
    *,
    corridor: float = 1.2,
    wall: float = 0.15,
) -> FloorPlan:
    """Generate a perfect maze: exactly one route between any two places, no loops.

    The plan is a grid of ``nx x ny`` cells, as many as fit ``corridor + wall`` metres apart;
    corridors are widened so that the maze fills ``size`` exactly. The passages are a random
    spanning tree of the cell grid (recursive backtracker, so long winding corridors), and the
    walls are drawn as rectangles, merged along straight runs.

    Parameters
    ----------
    seed : int, numpy SeedSequence or Generator, or None
        Seed of ``np.random.default_rng``; the same seed gives the same maze.
    size : (float, float), default (16.0, 16.0)
        Outer width (x) and height (y), in metres.
    corridor : float, default 1.2
        Smallest corridor width (m).
    wall : float, default 0.15
        Wall thickness (m), outer walls included.

    Returns
    -------
    FloorPlan
        Outline: the maze's outer boundary, centred on the origin. Obstacles: the outer wall
        ring, then the interior walls.

    Raises
    ------
    ValueError
        When a parameter is out of range, or ``size`` leaves room for fewer than 2 cells.

    Examples
    --------
    >>> plan = maze(seed=1, size=(4.2, 2.2), corridor=0.8, wall=0.2)  # 4 x 2 cells of 1 m
    >>> codes, origin = plan.rasterize(0.1)
    >>> codes.shape, origin
    ((22, 42), (-2.1, -1.1))
    >>> len(plan.obstacles)  # the outer ring and the merged runs of interior wall
    4
    >>> plan == maze(seed=1, size=(4.2, 2.2), corridor=0.8, wall=0.2)
    True
    """
    rng = rng_from(seed)
    width, height = check_pair(size, "size", "(width, height) in metres")
    corridor = check_positive(corridor, "corridor")
    wall = check_positive(wall, "wall")
    pitch = corridor + wall
    nx = math.floor((width - wall) / pitch + SNAP_TOL)
    ny = math.floor((height - wall) / pitch + SNAP_TOL)
    if nx < 1 or ny < 1 or nx * ny < 2:
        raise ArgumentError(
            f"size must fit at least 2 cells of corridor + wall = {pitch} m (plus one wall), "
            f"got {size!r}"
        )
    x0, y0 = -width / 2, -height / 2
    px, py = (width - wall) / nx, (height - wall) / ny
    xs = x0 + px * np.arange(nx + 1)  # left edge of each vertical wall line
    ys = y0 + py * np.arange(ny + 1)  # bottom edge of each horizontal wall line

    open_x, open_y = _spanning_tree(rng, nx, ny)
    walls = _interior_walls(xs, ys, wall, (-x0, -y0), open_x, open_y)
    outline, ring = walled_box(width, height, wall)
    return FloorPlan(outline=outline, obstacles=(ring, *walls))


def _spanning_tree(
    rng: np.random.Generator, nx: int, ny: int
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """A random spanning tree of the ``ny x nx`` cell grid, by recursive backtracking.

    Returns ``(open_x, open_y)``: ``open_x[j, i]`` when cells ``(j, i)`` and ``(j, i + 1)``
    are joined, ``open_y[j, i]`` when ``(j, i)`` and ``(j + 1, i)`` are.
    """
    open_x = np.zeros((ny, nx - 1), dtype=bool)
    open_y = np.zeros((ny - 1, nx), dtype=bool)
    visited = np.zeros((ny, nx), dtype=bool)
    start = (int(rng.integers(ny)), int(rng.integers(nx)))
    visited[start] = True
    stack = [start]
    while stack:
        j, i = stack[-1]
        steps = [
            (dj, di)
            for dj, di in ((0, 1), (0, -1), (1, 0), (-1, 0))
            if 0 <= j + dj < ny and 0 <= i + di < nx and not visited[j + dj, i + di]
        ]
        if not steps:
            stack.pop()
            continue
        dj, di = steps[int(rng.integers(len(steps)))]
        if di:
            open_x[j, min(i, i + di)] = True
        else:
            open_y[min(j, j + dj), i] = True
        visited[j + dj, i + di] = True
        stack.append((j + dj, i + di))
    return open_x, open_y


def _interior_walls(
    xs: NDArray[np.float64],
    ys: NDArray[np.float64],
    wall: float,
    far: tuple[float, float],
    open_x: NDArray[np.bool_],
    open_y: NDArray[np.bool_],
) -> list[Polygon]:
    """The interior walls (m) where cells are not joined, merged along straight runs.

    ``xs``, ``ys``: near edges of the wall lines; ``far``: the outer wall's far faces.
    """
    nx, ny = len(xs) - 1, len(ys) - 1
    # Far edge of each wall line; clipped, as x0 + px * nx + wall can round past -x0.
    xe, ye = np.minimum(xs + wall, far[0]), np.minimum(ys + wall, far[1])
    walls: list[Polygon] = []
    # Vertical wall line k (1 .. nx-1) between columns k-1 and k: closed where not open.
    for k in range(1, nx):
        for j0, j1 in _runs(~open_x[:, k - 1]):
            walls.append(box(xs[k], ys[j0], xe[k], ye[j1]))
    for k in range(1, ny):
        for i0, i1 in _runs(~open_y[k - 1, :]):
            walls.append(box(xs[i0], ys[k], xe[i1], ye[k]))
    return walls


def _runs(closed: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """``(first, end)`` of each run of True in ``closed``, ``end`` exclusive."""
    edges = np.diff(np.concatenate([[0], closed.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()))
