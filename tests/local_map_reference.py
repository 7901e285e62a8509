"""An independent reference for the local map, and the ties it may differ on.

:func:`reference_map` draws a robot's local map from first principles: the cell centres
laid out as the single env's docstring says (row 0 ahead, column 0 on the left), each
located with shapely in the floor cell's square that covers it (VOID off the map), the
other robots' discs as shapely discs. A centre on the common edge of two squares (or on a
disc's rim) is a tie: the reference reports it in ``ties`` and the maps may differ there.
:func:`obs_ties` marks such cells in a flat observation, so that the differential
tests compare the map columns exactly except at ties.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import shapely
from shapely import STRtree

from pointnav_core.floor.maps import VOID
from pointnav_core.sensors import LocalMap

TIE = 1e-9  # m: a centre this close to a square's edge or a disc's rim may read either side


def cell_centres(x: float, y: float, yaw: float, size: float, cells: int) -> list[tuple[float, float]]:
    """World centres of the map's cells, row by row: row i is ``(cells/2 - i - 1/2)`` cells
    ahead, column j that many to the left."""
    cs = size / cells
    c, s = math.cos(yaw), math.sin(yaw)
    out = []
    for i in range(cells):
        for j in range(cells):
            u, v = (cells / 2 - i - 0.5) * cs, (cells / 2 - j - 0.5) * cs
            out.append((x + c * u - s * v, y + s * u + c * v))
    return out


_TREES: dict[int, tuple[Any, STRtree]] = {}


def _squares(scene: Any) -> STRtree:
    """The floor's cell squares (row-major, as ``codes.flat``) in a shapely tree, per scene."""
    key = id(scene)
    if key not in _TREES or _TREES[key][0] is not scene:
        tmap = scene.floors[0]
        rows, cols = np.asarray(tmap.codes).shape
        res, (ox, oy) = float(tmap.resolution), (float(tmap.origin[0]), float(tmap.origin[1]))
        r, c = np.divmod(np.arange(rows * cols), cols)
        _TREES[key] = (scene, STRtree(shapely.box(ox + c * res, oy + r * res, ox + (c + 1) * res, oy + (r + 1) * res)))
    return _TREES[key][1]


def reference_map(
    scene: Any, x: float, y: float, yaw: float, discs: list[tuple[float, float, float]], size: float, cells: int
) -> tuple[np.ndarray, np.ndarray]:
    """The local map ``(cells * cells,)`` uint8 and its tie mask, by shapely.

    ``discs`` are the other present robots ``(x, y, radius)`` (m).
    """
    codes = np.asarray(scene.floors[0].codes).ravel()
    centres = np.array(cell_centres(x, y, yaw, size, cells))
    # Every square within TIE of each centre: one square (or none: off the map) unless on an edge.
    near = shapely.buffer(shapely.points(centres), TIE, quad_segs=2)
    which, square = _squares(scene).query(near, predicate="intersects")
    n = cells * cells
    hits = np.bincount(which, minlength=n)
    out = np.full(n, VOID, np.uint8)
    out[which] = codes[square]
    # Two squares of different codes, or a square and off the map (a centre on the map's
    # outer edge, or on a corner shared with fewer than four squares inside it).
    lo = np.full(n, 255)
    hi = np.full(n, -1)
    np.minimum.at(lo, which, codes[square])
    np.maximum.at(hi, which, codes[square])
    on_edge = _near_outer_edge(scene, centres)
    ties = (hits > 0) & ((lo != hi) | on_edge)
    inside_disc = np.zeros(n, bool)
    for dx, dy, r in discs:
        d = np.hypot(centres[:, 0] - dx, centres[:, 1] - dy)
        inside_disc |= d <= r - TIE
        ties |= np.abs(d - r) < TIE
    out[inside_disc] = 3
    ties &= ~inside_disc  # inside a disc: 3 whatever lies under it
    return out, ties


def _near_outer_edge(scene: Any, centres: np.ndarray) -> np.ndarray:
    """Centres within TIE of the map's outer boundary (inside or out)."""
    tmap = scene.floors[0]
    rows, cols = np.asarray(tmap.codes).shape
    res, (ox, oy) = float(tmap.resolution), (float(tmap.origin[0]), float(tmap.origin[1]))
    outline = shapely.box(ox, oy, ox + cols * res, oy + rows * res).boundary
    return shapely.distance(shapely.points(centres), outline) < TIE


def obs_ties(env: Any, robot: int, sensors: dict | None, dim: int) -> np.ndarray:
    """Where a flat observation of ``robot`` in ``env`` (a PointNavEnv or a parallel env) may
    differ at a tie: its local map cells whose centre lies on an edge or a rim."""
    ties = np.zeros(dim, bool)
    args = (sensors or {}).get("local_map", False)
    if args is False:
        return ties
    term = args if isinstance(args, LocalMap) else LocalMap(**(args or {}))
    backend = env.backend
    pos, quat = backend.get_pose(robot)
    yaw = 2.0 * math.atan2(float(quat[2]), float(quat[3]))
    robots = getattr(env, "robots", None) or [env.robot]
    discs = [
        (float(backend.get_pose(j)[0][0]), float(backend.get_pose(j)[0][1]), float(robots[j].radius))
        for j in range(len(robots))
        if j != robot and backend.is_present(j)
    ]
    _, tie = reference_map(env.scene, float(pos[0]), float(pos[1]), yaw, discs, term.extent, term.cells)
    ties[dim - term.size:] = tie
    return ties


def assert_obs(got: np.ndarray, want: np.ndarray, ties: np.ndarray, atol: float, msg: str) -> int:
    """Observations within ``atol`` except at local map ties; returns how many ties differed."""
    off = np.abs(got.astype(np.float64) - want.astype(np.float64)) > atol
    bad = off & ~ties
    if bad.any():
        where = tuple(int(i[0]) for i in np.nonzero(bad))
        raise AssertionError(f"{msg}: {got[where]} vs {want[where]} at {where} ({int(bad.sum())} values)")
    return int((off & ties).sum())
