"""How far a node of the tangent graph can see: strict bounds, and the nodes a point may see.

Every tangent edge, and every tangent from a point to a node, is a straight segment that
leaves (or, reversed, reaches) a point of a node's free arc and keeps the robot's disc clear
of the blocked set. :func:`node_sights` bounds the length of every such segment per node,
so that only nodes within that bound need an exact test. The bound is strict: a segment it
leaves out cannot be clear.

**Why it holds.** Directions are covered by rays, each owning a sector of half-width ``h``
around its own direction ``theta``. A ray starts at the arc point a segment of direction
``theta`` leaves from, and marches through the cells. A clear segment of direction
``theta'`` in the sector, leaving from its own arc point, stays within
``e(t) = (r + t) * h`` of the ray at every distance ``t`` (its start is within ``r * h``
of the ray's, its direction within ``h``), and every point of it is at least ``r`` from the
blocked set. So where the ray passes a point whose distance to the blocked set is surely
below ``r - e(t)`` (measured to the nearest blocked cell's square, an upper bound), no clear
segment of the sector reaches that far: the ray stops there, and its length bounds them
all. A ray that goes on past ``e(t) >= r`` can no longer prove anything; its sector is split
in two narrower ones. Marching skips ahead only by what the distance field leaves free, and
any skipped sample can only make a ray longer: the bound stays an upper bound.

The rays march in compiled code when numba is installed (the ``fast`` extra); the plain path
runs the same function as Python (:func:`sight_rays`), and a property test holds the two
equal. Lengths are in metres.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage
from scipy.spatial import cKDTree
from tqdm.auto import tqdm

from pointnav_core.floor.collision import TOUCH_TOL
from pointnav_core.geodesic.tangents import ANG_TOL
from pointnav_core.utils import compiled as _compiled

if TYPE_CHECKING:
    from pointnav_core.floor.collision import FloorCollision

__all__ = ["PROFILE_BINS", "NodeBalls", "blocked_by_profile", "mark_profile", "march_ray", "no_bound", "node_sights", "sight_rays"]

#: Half-width (rad) of the sectors rays start with: 64 rays over a grid corner's quarter arc.
FIRST_HALF_WIDTH = math.pi / 256
#: Narrowest sector (rad) before a ray gives up and bounds its node by the map's diagonal.
MIN_HALF_WIDTH = 1e-5
#: Direction bins of a node's sight profile.
PROFILE_BINS = 128
#: Most rays one node may cast before its bound gives up (the map's diagonal): a robot far
#: thinner than a cell in open space needs ever narrower sectors.
_RAY_BUDGET = 16384
#: Most sectors waiting at once per node and side (the first ones plus one per split level).
_STACK = 8192
#: Nodes whose sights a build finds before it shows a progress bar (about 2 s of work).
_PROGRESS_NODES = 20_000
#: Nodes marched per call (a progress bar's step).
_BATCH = 4096
#: Most (point, node) pairs a query measures one by one rather than through the trees.
_BRUTE = 2_000_000
#: The bound of a node that sees past the edge of a map whose outside is open (m).
_FAR = 1e300


def sight_rays(cx, cy, phi0, span, r, margin, edt, near_r, near_c, outside, h0, min_h, limit, out, profile):  # pragma: no cover
    """Per node, the longest ray (cells) over both winding sides: ``out[n]``.

    Everything is in padded grid units (the grid with one ring of blocked cells around it):
    node centres ``(cx, cy)``, radius ``r``, ``margin`` (the clearance test's touching
    tolerance, doubled), ``edt`` (distance from each cell centre to the nearest blocked cell
    centre) and the row and column of that blocked cell (``near_r``, ``near_c``); and
    whether everything off the grid is blocked (``outside``). ``profile[n, b]`` (zeros on
    entry) gets the longest ray of every sector that overlaps direction bin ``b`` (bins of
    ``2 pi / B`` from angle 0): no clear segment leaving the arc in a direction of bin ``b``
    is longer. Plain Python on scalars, so that numba compiles the very same function (and
    the helpers it calls, :func:`march_ray`, :func:`mark_profile` and :func:`no_bound`).
    """
    stack_t = np.empty(_STACK)
    stack_h = np.empty(_STACK)
    if r * (1.0 / min_h - 1.0) < 1.0:
        # Even the narrowest sector proves nothing a cell away (a point robot): no bound.
        for n in range(cx.shape[0]):
            no_bound(out, profile, n, limit)
        return
    for n in range(cx.shape[0]):
        best = 0.0
        gave_up = False
        cast = 0
        for side in (1.0, -1.0):
            n0 = max(1, int(math.ceil(span[n] / (2.0 * h0))))
            hw0 = span[n] / (2.0 * n0)
            top = 0
            for k in range(n0):
                stack_t[top] = phi0[n] + (2 * k + 1) * hw0 + side * (math.pi / 2)
                stack_h[top] = hw0
                top += 1
            while top > 0:
                top -= 1
                theta = stack_t[top]
                hw = stack_h[top]
                cast += 1
                reach = (hw + ANG_TOL)
                length = march_ray(cx[n], cy[n], theta, side, reach, r, margin, edt, near_r, near_c, outside, limit)
                if length >= 0.0:
                    best = max(best, length)
                    mark_profile(profile, n, theta, reach, length)
                elif hw <= min_h or top + 2 > _STACK or cast >= _RAY_BUDGET:
                    gave_up = True  # a robot this thin in so open a space: no useful bound
                    break
                else:
                    stack_t[top] = theta - hw / 2
                    stack_h[top] = hw / 2
                    stack_t[top + 1] = theta + hw / 2
                    stack_h[top + 1] = hw / 2
                    top += 2
            if gave_up:
                break
        if gave_up:
            no_bound(out, profile, n, limit)
        else:
            out[n] = best


def march_ray(cx, cy, theta, side, reach, r, margin, edt, near_r, near_c, outside, limit):  # pragma: no cover
    """The length (cells) of the ray of direction ``theta`` (rad) from the arc point of node
    centre ``(cx, cy)`` on winding ``side`` (+1.0 or -1.0), for a sector of half-width
    ``reach`` (rad, tolerance included); -1.0 where it proves nothing (its sector must split).

    Grid units and arguments as in :func:`sight_rays`.
    """
    n_rows, n_cols = edt.shape
    phi = theta - side * (math.pi / 2)
    tx = cx + r * math.cos(phi)
    ty = cy + r * math.sin(phi)
    ux = math.cos(theta)
    uy = math.sin(theta)
    t = 0.0
    while True:
        e = (r + t) * reach
        if e >= r - margin:
            return -1.0  # past this the ray proves nothing: split its sector
        x = tx + t * ux
        y = ty + t * uy
        col = math.floor(x)
        row = math.floor(y)
        if col < 0 or col >= n_cols or row < 0 or row >= n_rows:
            return t if outside else limit
        nr = near_r[row, col]
        nc = near_c[row, col]
        dx = max(nc - x, 0.0, x - (nc + 1))
        dy = max(nr - y, 0.0, y - (nr + 1))
        if math.sqrt(dx * dx + dy * dy) + e < r - margin:
            return t
        if t > limit:
            return limit
        t += max(edt[row, col] - math.sqrt(2.0) - r, 0.25)


def mark_profile(profile, n, theta, reach, length):  # pragma: no cover
    """Raise node ``n``'s ``profile`` to ``length`` (cells) in every direction bin that the
    sector of direction ``theta`` and half-width ``reach`` (rad) overlaps."""
    n_bins = profile.shape[1]
    bin_width = 2.0 * math.pi / n_bins
    b0 = math.floor((theta - reach) / bin_width)
    b1 = math.floor((theta + reach) / bin_width)
    for b in range(b0, b1 + 1):
        k = b % n_bins
        profile[n, k] = max(profile[n, k], length)


def no_bound(out, profile, n, limit):  # pragma: no cover
    """Node ``n`` gets no useful bound: ``limit`` (cells) overall and in every direction bin."""
    out[n] = limit
    for k in range(profile.shape[1]):
        profile[n, k] = limit


def node_sights(
    geo: FloorCollision, radius: float, cx: NDArray[np.float64], cy: NDArray[np.float64],
    phi0: NDArray[np.float64], span: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float32]]:
    """Strict bounds (m) on the length of a clear segment leaving each node's arc: overall,
    and per direction (:data:`PROFILE_BINS` bins of ``2 pi / PROFILE_BINS`` from angle 0,
    float32 rounded up: :func:`blocked_by_profile`).

    Parameters
    ----------
    geo : FloorCollision
        The blocked set; only its cells are marched (a subset of the blocked set gives a
        looser bound, never a wrong one).
    radius : float
        Robot radius (m), > 0.
    cx, cy, phi0, span : ndarray, shape (N,)
        Node centres (m) and free arcs (rad).
    """
    n = len(cx)
    if not n:
        return np.zeros(0), np.zeros((0, PROFILE_BINS), np.float32)
    res = geo.resolution
    pad = np.pad(np.asarray(geo.blocked, dtype=bool), 1, constant_values=geo.outside_blocked)
    if not pad.any():  # nothing to stop a ray: every node may see the whole map
        far = math.hypot(*pad.shape) * res + 2.0 * res if geo.outside_blocked else _FAR
        return np.full(n, far), np.full((n, PROFILE_BINS), far if far < _FAR else np.inf, np.float32)
    edt, (near_r, near_c) = ndimage.distance_transform_edt(~pad, return_indices=True)
    limit = math.hypot(*pad.shape) + 2.0
    out = np.empty(n)
    profile = np.zeros((n, PROFILE_BINS))
    kernel = _compiled.kernel("pointnav_core.geodesic._sight_kernel", "sight_rays")
    march = kernel if kernel is not None else sight_rays
    gx = (np.asarray(cx, dtype=np.float64) - geo.origin[0]) / res + 1.0
    gy = (np.asarray(cy, dtype=np.float64) - geo.origin[1]) / res + 1.0
    phi0 = np.asarray(phi0, dtype=np.float64)
    span = np.asarray(span, dtype=np.float64)
    edt = np.ascontiguousarray(edt, dtype=np.float64)
    near_r, near_c = near_r.astype(np.int64), near_c.astype(np.int64)
    # In batches, so that a large floor shows its progress (each node's rays are its own).
    with tqdm(total=n, desc="sight bounds", unit="node", leave=False, disable=n < _PROGRESS_NODES or None) as bar:
        for i in range(0, n, _BATCH):
            j = min(i + _BATCH, n)
            march(gx[i:j], gy[i:j], phi0[i:j], span[i:j], radius / res, 2.0 * TOUCH_TOL / res, edt, near_r, near_c,
                  bool(geo.outside_blocked), FIRST_HALF_WIDTH, MIN_HALF_WIDTH, limit, out[i:j], profile[i:j])
            bar.update(j - i)
    # One cell to spare for the rounding of grid coordinates; a ray that reached the limit on
    # an open map proves nothing.
    out = (out + 1.0) * res
    profile = (profile + 1.0) * res
    if not geo.outside_blocked:
        out[out >= limit * res] = _FAR
        profile[profile >= limit * res] = _FAR
    # float32, rounded up: a bound stays a bound (past float32's range: no bound).
    profile = np.where(profile >= _FAR, np.inf, profile).astype(np.float32)
    return out, np.nextafter(profile, np.float32(np.inf))


def blocked_by_profile(profile: NDArray[np.float32], node: Any, dx: Any, dy: Any) -> Any:
    """Whether a segment leaving ``node``'s arc along ``(dx, dy)`` (m) is surely not clear:
    longer than the node's sight profile allows in its direction bin."""
    bins = profile.shape[1]
    b = np.floor(np.mod(np.arctan2(dy, dx), 2 * np.pi) / (2 * np.pi / bins)).astype(np.int64) % bins
    return np.hypot(dx, dy) > profile[node, b]


class NodeBalls:
    """Which nodes a point may see: those whose sight ball (sight plus radius) holds it.

    The nodes are grouped by the power of two above their ball's radius, one kd-tree per
    group, so a query looks only as far as each group needs.

    Parameters
    ----------
    cx, cy : ndarray, shape (N,)
        Node centres (m).
    reach : ndarray, shape (N,)
        Each node's ball radius (m).
    """

    def __init__(self, cx: NDArray[np.float64], cy: NDArray[np.float64], reach: NDArray[np.float64]) -> None:
        self.reach = np.asarray(reach, dtype=np.float64)
        self.xy = np.stack([cx, cy], axis=1) if len(cx) else np.zeros((0, 2))
        level = np.ceil(np.log2(np.maximum(self.reach, 1e-9))).astype(np.int64) if len(cx) else np.zeros(0, np.int64)
        self.groups = []
        for lv in np.unique(level).tolist():
            ids = np.flatnonzero(level == lv)
            self.groups.append((ids, cKDTree(self.xy[ids]), 2.0 ** lv))

    def query(self, xs: NDArray[np.float64], ys: NDArray[np.float64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Per point, the nodes whose ball holds it: ``(owner, node)`` pairs sorted by owner, then node."""
        pts = np.stack([np.asarray(xs, dtype=np.float64), np.asarray(ys, dtype=np.float64)], axis=1).reshape(-1, 2)
        n_nodes = len(self.reach)
        if len(pts) * n_nodes <= _BRUTE:
            # Few enough pairs to measure them all: faster than walking trees.
            d = np.hypot(pts[:, 0, None] - self.xy[None, :, 0], pts[:, 1, None] - self.xy[None, :, 1])
            owner, node = np.nonzero(d <= self.reach[None, :])
            return owner.astype(np.int64), node.astype(np.int64)
        owners, nodes = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)]
        queries = cKDTree(pts)
        for ids, tree, radius in self.groups:
            # The pairs within the group's radius, found in C (no per-point lists).
            pairs = tree.sparse_distance_matrix(queries, radius, output_type="ndarray")
            ok = pairs["v"] <= self.reach[ids[pairs["i"]]]
            owners.append(pairs["j"][ok].astype(np.int64))
            nodes.append(ids[pairs["i"][ok]])
        owner, node = np.concatenate(owners), np.concatenate(nodes)
        order = np.lexsort((node, owner))
        return owner[order], node[order]
