"""The compiled candidate search of :mod:`pointnav_core.geodesic.edges` (imports numba).

Imported only through :func:`pointnav_core.utils.compiled.kernel` when numba is installed (the
``fast`` extra), so the package imports without it. :func:`edge_pairs` finds the node pairs
that ``edges._candidates`` finds with the KD-tree (the same test, ``dx * dx + dy * dy <= reach
* reach``, in the same order: sources in the given order, destinations ascending) without a
Python list per node, and says per pair which of the four winding pairs may give an edge: a
loose form of ``edges._tangents``'s arc tests and of ``edges._clear``'s sight profile test,
with :data:`_SLACK` to spare, so that it never leaves out a tangent the exact numpy tests
keep (on the 1000 x 1000 clutter map it keeps 229 thousand of 24 million pair windings, and
every one of the 167 thousand edges). Angles are in radians, lengths in metres.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from pointnav_core.geodesic.tangents import ANG_TOL, TWO_PI

__all__ = ["edge_pairs"]

#: Extra room (rad, and relative on lengths) of the loose tests: far above the few ulps by
#: which numba's and numpy's trigonometry may differ, far below anything geometric.
_SLACK = 1e-6

_jit = numba.njit(cache=True, nogil=True, error_model="numpy")


@_jit
def _buckets(cx, cy, x0, y0, cell, nx, ny):  # pragma: no cover
    # Nodes by grid bucket of side cell (m) from (x0, y0): members[start[k]:start[k + 1]] are
    # bucket k's (k = row * nx + col), ascending (a counting sort, stable by node).
    n = cx.shape[0]
    key = np.empty(n, np.int64)
    start = np.zeros(nx * ny + 1, np.int64)
    for i in range(n):
        col = min(int((cx[i] - x0) / cell), nx - 1)
        row = min(int((cy[i] - y0) / cell), ny - 1)
        key[i] = row * nx + col
        start[key[i] + 1] += 1
    for k in range(nx * ny):
        start[k + 1] += start[k]
    fill = start[:-1].copy()
    members = np.empty(n, np.int64)
    for i in range(n):
        members[fill[key[i]]] = i
        fill[key[i]] += 1
    return start, members


@_jit
def _span(lo, hi, n):  # pragma: no cover
    # The bucket indices covering grid coordinates [lo, hi], one bucket to spare each side
    # (a node on a bucket's edge may round into its neighbour), clipped to [0, n - 1].
    a = max(min(math.floor(lo) - 1.0, n - 1.0), 0.0)
    b = max(min(math.floor(hi) + 1.0, n - 1.0), 0.0)
    return int(a), int(b)


@_jit
def _near(i, cx, cy, reach, x0, y0, cell, nx, ny, start, members, buf):  # pragma: no cover
    # Node i's KD-tree ball: every node j with dx * dx + dy * dy <= reach[i] ** 2 (the very
    # test and rounding of scipy's query_ball_point), in bucket order in buf[:count] (buf
    # grown as needed). Returns (count, buf).
    x, y, rad = cx[i], cy[i], reach[i]
    c0, c1 = _span((x - rad - x0) / cell, (x + rad - x0) / cell, nx)
    r0, r1 = _span((y - rad - y0) / cell, (y + rad - y0) / cell, ny)
    bound = rad * rad
    count = 0
    for row in range(r0, r1 + 1):
        for k in range(start[row * nx + c0], start[row * nx + c1 + 1]):
            j = members[k]
            dx = cx[j] - x
            dy = cy[j] - y
            if dx * dx + dy * dy <= bound:
                if count == buf.shape[0]:
                    buf = np.concatenate((buf, np.empty_like(buf)))
                buf[count] = j
                count += 1
    return count, buf


@_jit
def _on_arc(ang, phi0, span):  # pragma: no cover
    # Loose ``tangents.ccw_pos`` validity: True wherever the exact one is. Angles here lie
    # within a few turns of each other: a turn added or taken is cheaper than a modulo.
    c = ang - phi0
    if abs(c) > 8.0 * TWO_PI:
        c %= TWO_PI
    while c < 0.0:
        c += TWO_PI
    while c >= TWO_PI:
        c -= TWO_PI
    return c <= span + ANG_TOL + _SLACK or c >= TWO_PI - ANG_TOL - _SLACK


@_jit
def _within_sight(profile, n, heading, length, tol):  # pragma: no cover
    # Loose ``sight.blocked_by_profile`` (negated): False only where a segment of direction
    # heading (rad) and length (m), both known to tol (m) at its ends, leaving node n, is
    # surely longer than n's profile allows. Its direction is then known to far less than a
    # bin: the bins either side count too.
    if length <= tol:
        return True  # too short to know its direction
    bins = profile.shape[1]
    b = math.floor((heading % TWO_PI) / (TWO_PI / bins))
    most = max(profile[n, (b - 1) % bins], profile[n, b % bins], profile[n, (b + 1) % bins])
    return length <= most * (1.0 + _SLACK) + tol


@_jit
def _windings(i, j, cx, cy, phi0, span, profile, r):  # pragma: no cover
    # Which common tangents of nodes i's and j's circles (radius r) may leave i's arc, arrive
    # on j's and pass both sight profiles: bit k for ``edges.WINDINGS[k]``, each of
    # ``edges._tangents``'s and ``_clear``'s tests loosened by _SLACK (0: none can). A
    # tangent runs along its heading for ``seg`` (m): numpy's segment between its computed
    # ends differs by roundings of the coordinates, far below tol.
    dx = cx[j] - cx[i]
    dy = cy[j] - cy[i]
    length = math.hypot(dx, dy)
    if length <= 0.0:
        return 0
    tol = _SLACK * (abs(cx[i]) + abs(cy[i]) + abs(cx[j]) + abs(cy[j]) + r)
    base = math.atan2(dy, dx)
    # Crossing tangents (sb = -s) only where the circles do not overlap.
    cross = length > 2.0 * r * (1.0 - _SLACK)
    tilt = math.asin(min(2.0 * r / length, 1.0)) if cross else 0.0
    seg = math.sqrt(max(length * length - 4.0 * r * r, 0.0))
    bits = 0
    for k in range(2):
        s = 1.0 - 2.0 * k
        # Outer tangent (sb = s): it leaves and arrives at the same angle.
        ang = base - s * (math.pi / 2)
        if (_on_arc(ang, phi0[i], span[i]) and _on_arc(ang, phi0[j], span[j])
                and _within_sight(profile, i, base, length, tol) and _within_sight(profile, j, base + math.pi, length, tol)):
            bits |= 1 << (2 * k)
        # Crossing tangent: it arrives half a turn from where it leaves.
        heading = base + s * tilt
        ang = heading - s * (math.pi / 2)
        if (cross and _on_arc(ang, phi0[i], span[i]) and _on_arc(ang + s * math.pi, phi0[j], span[j])
                and _within_sight(profile, i, heading, seg, tol) and _within_sight(profile, j, heading + math.pi, seg, tol)):
            bits |= 1 << (2 * k + 1)
    return bits


@_jit
def _grid(cx, cy):  # pragma: no cover
    # Bucket side (m) and counts for about 8 nodes a bucket: (x0, y0, cell, nx, ny).
    x0, y0 = cx.min(), cy.min()
    extent = max(cx.max() - x0, cy.max() - y0)
    per_side = max(int(math.sqrt(cx.shape[0] / 8.0)), 1)
    cell = extent / per_side if extent > 0.0 else 1.0
    nx = min(int((cx.max() - x0) / cell), per_side - 1) + 1
    ny = min(int((cy.max() - y0) / cell), per_side - 1) + 1
    return x0, y0, cell, nx, ny


@_jit
def edge_pairs(nodes, cx, cy, reach, phi0, span, profile, r):  # pragma: no cover
    """The candidate pairs of ``edges._candidates``, found in one compiled pass.

    Parameters
    ----------
    nodes : ndarray of int64, shape (K,)
        The source nodes.
    cx, cy, reach : ndarray of float64, shape (N,)
        Every node's centre (m) and its sight plus two radii (m).
    phi0, span : ndarray of float64, shape (N,)
        Every node's free arc (rad).
    profile : ndarray of float32, shape (N, B)
        Every node's sight profile (m; ``geodesic.sight``).
    r : float
        Robot radius (m).

    Returns
    -------
    src, dst : ndarray of int64
        The pairs ``(i, j)`` with ``j != i``, ``j`` in ``i``'s ball (``dx * dx + dy * dy <=
        reach[i] ** 2``, as the KD-tree tests), ``i`` about within ``reach[j]`` (loosely:
        ``edges._candidates`` decides exactly) and some common tangent that may leave ``i``'s
        arc and arrive on ``j``'s (loosely: ``edges._tangents`` decides). Sources in
        ``nodes`` order, each one's destinations ascending (the KD-tree's order).
    windings : ndarray of uint8
        Per pair, bit ``k`` set where the tangent of winding pair ``edges.WINDINGS[k]`` may
        leave and arrive on the arcs and pass both sight profiles (loosely again: the
        exact tests of ``edges._tangents`` and ``_clear`` decide).
    """
    x0, y0, cell, nx, ny = _grid(cx, cy)
    start, members = _buckets(cx, cy, x0, y0, cell, nx, ny)
    buf = np.empty(1024, np.int64)
    src = np.empty(4096, np.int64)
    dst = np.empty(4096, np.int64)
    wind = np.empty(4096, np.uint8)
    n_out = 0
    for i in nodes:
        count, buf = _near(i, cx, cy, reach, x0, y0, cell, nx, ny, start, members, buf)
        kept = 0
        for k in range(count):
            j = buf[k]
            dx = cx[j] - cx[i]
            dy = cy[j] - cy[i]
            loose = reach[j] * (1.0 + _SLACK)
            if j == i or dx * dx + dy * dy > loose * loose:
                continue
            bits = _windings(i, j, cx, cy, phi0, span, profile, r)
            if bits:
                buf[kept] = j * 16 + bits  # sorts by j: bits < 16
                kept += 1
        buf[:kept].sort()  # the KD-tree's order, which ties in _store keep
        if n_out + kept > src.shape[0]:
            grow = max(src.shape[0], kept)
            src = np.concatenate((src, np.empty(grow, np.int64)))
            dst = np.concatenate((dst, np.empty(grow, np.int64)))
            wind = np.concatenate((wind, np.empty(grow, np.uint8)))
        for k in range(kept):
            src[n_out] = i
            dst[n_out] = buf[k] >> 4
            wind[n_out] = buf[k] & 15
            n_out += 1
    return src[:n_out].copy(), dst[:n_out].copy(), wind[:n_out].copy()
