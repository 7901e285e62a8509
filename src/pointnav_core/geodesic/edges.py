"""Batched construction of the tangent graph's edges (sight bounds and common tangents).

:class:`~pointnav_core.geodesic.planner.Planner` finds the edges of a node lazily, but one
node at a time is dominated by numpy call overhead: a sight bound marched ray by ray and a
clearance test of a handful of segments. The functions here do the same work for many
nodes at once (a tile of the map for a lazy search, every node for a goal field), so the
overhead is paid once per batch. The results are identical to the per-node construction.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from pointnav_core.geodesic.sight import blocked_by_profile
from pointnav_core.geodesic.tangents import ccw_pos
from pointnav_core.utils import compiled as _compiled

if TYPE_CHECKING:
    from pointnav_core.geodesic.planner import Planner

__all__ = ["WINDINGS", "build_edges"]

#: Segments tested for clearance per call (bounds the temporary arrays).
_SEG_CHUNK = 200_000
#: The winding pairs ``(s, sb)`` of a tangent (leaving side, arriving side), in the order
#: their edges are found (which orders edges that leave at one position).
WINDINGS = ((1, 1), (1, -1), (-1, -1), (-1, 1))


#: Per winding pair: sources, source side, destinations, destination side, departure and
#: arrival positions on the arcs (rad) and segment lengths (m).
Found = tuple[NDArray[np.int64], int, NDArray[np.int64], int, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]


def build_edges(p: Planner, nodes: NDArray[np.int64]) -> None:
    """Find the tangent edges leaving ``nodes`` on both winding sides and store them in ``p``.

    Candidates are the nodes within each node's sight bound; for each winding pair the
    common tangent must leave and arrive on the two arcs, and its segment must be clear
    for the robot's disc (one exact test for the whole batch). Stores, per ``(node, side)``,
    the edges sorted by departure position in ``p.edge_store``.
    """
    nodes = np.asarray(nodes, dtype=np.int64)
    if not len(nodes):
        return
    src, dst, windings = _candidates(p, nodes)
    found, seg_a, seg_b = _tangents(p, src, dst, windings)
    if found:
        clear = _clear(p, np.concatenate(seg_a), np.concatenate(seg_b), found)
        e_src = np.concatenate([f[0] for f in found])[clear]
        e_s = np.concatenate([np.full(len(f[0]), f[1], np.int8) for f in found])[clear]
        e_dst = np.concatenate([f[2] for f in found])[clear]
        e_sb = np.concatenate([np.full(len(f[0]), f[3], np.int8) for f in found])[clear]
        e_dep = np.concatenate([f[4] for f in found])[clear]
        e_arr = np.concatenate([f[5] for f in found])[clear]
        e_len = np.concatenate([f[6] for f in found])[clear]
    else:
        e_src = e_dst = np.zeros(0, np.int64)
        e_s = e_sb = np.zeros(0, np.int8)
        e_dep = e_arr = e_len = np.zeros(0)
    _store(p, nodes, e_src, e_s, e_dst, e_sb, e_dep, e_arr, e_len)


def _candidates(
    p: Planner, nodes: NDArray[np.int64]
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.uint8] | None]:
    """The ``(source, destination)`` node pairs close enough for an edge, sources in ``nodes`` order.

    An edge is a clear segment leaving both nodes' arcs, so the centres are at most either
    node's sight plus two radii (m) apart (geodesic.sight). Destinations come in ascending
    order per source (the KD-tree's order): the stable sort of :func:`_store` keeps it
    among edges that leave at the same position. With numba the pairs come from
    :mod:`pointnav_core.geodesic._edges_kernel`, which also says which winding pairs may give
    an edge (bit ``k`` for ``WINDINGS[k]``; None without numba: all) and leaves out the pairs
    with none, by loose forms of the tests of :func:`_tangents` and of :func:`_clear`'s sight
    profiles that never leave out a tangent they keep: the numpy work after it runs on a
    hundredth of the pair windings of a large map.
    """
    r = p.radius
    reach = p.sights + 2 * r
    kernel = _compiled.kernel("pointnav_core.geodesic._edges_kernel", "edge_pairs")
    windings = None
    if kernel is not None:
        src, dst, windings = kernel(nodes, p.cx, p.cy, reach, p.phi0, p.span, p.sight_profile, float(r))
    else:
        pts = np.stack([p.cx[nodes], p.cy[nodes]], axis=1)
        lists = p.tree.query_ball_point(pts, reach[nodes])
        counts = np.fromiter((len(v) for v in lists), dtype=np.int64, count=len(lists))
        src = np.repeat(nodes, counts)
        dst = np.fromiter((j for v in lists for j in v), dtype=np.int64, count=int(counts.sum()))
    keep = (src != dst) & (np.hypot(p.cx[src] - p.cx[dst], p.cy[src] - p.cy[dst]) <= reach[dst])
    return src[keep], dst[keep], None if windings is None else windings[keep]


def _tangents(
    p: Planner, src: NDArray[np.int64], dst: NDArray[np.int64], windings: NDArray[np.uint8] | None = None
) -> tuple[list[Found], list[NDArray[np.float64]], list[NDArray[np.float64]]]:
    """The common tangents of every pair that leave and arrive on the two nodes' arcs.

    ``windings`` (bit ``k`` for ``WINDINGS[k]``) limits each winding pair's tests to the
    pairs with its bit set (None: every pair); the same numpy expressions on fewer elements
    give the same numbers.

    Returns
    -------
    found : list of Found
        One entry per winding pair ``(s, sb)`` with any tangent, in the order of
        :data:`WINDINGS`.
    seg_a, seg_b : list of ndarray, shape (n, 2)
        The tangents' end points (m) on the source and destination arcs, per entry.
    """
    r = p.radius
    ax, ay, bx, by = p.cx[src], p.cy[src], p.cx[dst], p.cy[dst]
    dx, dy = bx - ax, by - ay
    L = np.hypot(dx, dy)
    base = np.arctan2(dy, dx)
    found: list[Found] = []
    seg_a: list[NDArray[np.float64]] = []
    seg_b: list[NDArray[np.float64]] = []
    for k, (s, sb) in enumerate(WINDINGS):
        w = np.arange(len(src)) if windings is None else np.flatnonzero(windings & (1 << k))
        w_src, w_dst, w_L = src[w], dst[w], L[w]
        if sb == s:
            ok = w_L > 0
            heading = base[w]
            seg = w_L
        else:
            ok = w_L > 2 * r * (1 + 1e-12) if r > 0 else w_L > 0
            heading = base[w] + s * np.arcsin(np.clip(2 * r / np.where(ok, w_L, 1.0), -1.0, 1.0))
            seg = np.sqrt(np.maximum(w_L * w_L - 4 * r * r, 0.0))
        dep_ang = heading - s * (math.pi / 2)
        arr_ang = heading - sb * (math.pi / 2)
        dep_ccw, ok_a = ccw_pos(dep_ang, p.phi0[w_src], p.span[w_src])
        arr_ccw, ok_b = ccw_pos(arr_ang, p.phi0[w_dst], p.span[w_dst])
        idx = np.flatnonzero(ok & ok_a & ok_b)
        if not len(idx):
            continue
        da, aa, i_src, i_dst = dep_ang[idx], arr_ang[idx], w_src[idx], w_dst[idx]
        seg_a.append(np.stack([ax[w[idx]] + r * np.cos(da), ay[w[idx]] + r * np.sin(da)], axis=1))
        seg_b.append(np.stack([bx[w[idx]] + r * np.cos(aa), by[w[idx]] + r * np.sin(aa)], axis=1))
        dep = dep_ccw[idx] if s > 0 else p.span[i_src] - dep_ccw[idx]
        arr = arr_ccw[idx] if sb > 0 else p.span[i_dst] - arr_ccw[idx]
        found.append((i_src, s, i_dst, sb, dep, arr, seg[idx]))
    return found, seg_a, seg_b


def _clear(p: Planner, pa: NDArray[np.float64], pb: NDArray[np.float64], found: list[Found]) -> NDArray[np.bool_]:
    """Which candidate segments ``pa -> pb`` (m; ``found``'s, end to end) are clear for the robot's disc.

    Cheap rejections first. A clear edge is no longer than either node's sight in its
    direction (geodesic.sight), and never enters a cell no disc point can use: coarse
    samples reject most candidates at a fraction of the fine pass's cost. The survivors
    get the exact test.
    """
    e_a = np.concatenate([f[0] for f in found])
    e_b = np.concatenate([f[2] for f in found])
    d = pb - pa
    sub = np.flatnonzero(~blocked_by_profile(p.sight_profile, e_a, d[:, 0], d[:, 1])
                         & ~blocked_by_profile(p.sight_profile, e_b, -d[:, 0], -d[:, 1]))
    for step in (2.0, 0.5):
        ok = np.concatenate(
            [_misses_full(p, pa[sub[i : i + _SEG_CHUNK]], pb[sub[i : i + _SEG_CHUNK]], step) for i in range(0, len(sub), _SEG_CHUNK)]
            + [np.zeros(0, dtype=bool)]
        )
        sub = sub[ok]
    n_cand = len(pa)
    pa, pb = pa[sub], pb[sub]
    clear = np.zeros(n_cand, dtype=bool)
    clear[sub] = np.concatenate(
        [p.geo.segments_clear(pa[i : i + _SEG_CHUNK], pb[i : i + _SEG_CHUNK], p.radius) for i in range(0, len(pa), _SEG_CHUNK)]
        + [np.zeros(0, dtype=bool)]
    )
    return clear


def _store(
    p: Planner, nodes: NDArray[np.int64], e_src: NDArray[np.int64], e_s: NDArray[np.int8], e_dst: NDArray[np.int64],
    e_sb: NDArray[np.int8], e_dep: NDArray[np.float64], e_arr: NDArray[np.float64], e_len: NDArray[np.float64],
) -> None:
    """Store the edges in ``p.edge_store``: per ``(node, side)``, lists of departure
    position (rad), destination, its side, arrival position (rad) and length (m), sorted
    by departure (stable); an empty entry for every node in ``nodes`` without edges."""
    key = e_src * 2 + (e_s < 0)
    order = np.lexsort((e_dep, key))
    key = key[order]
    bounds = np.flatnonzero(np.diff(key)) + 1
    starts = np.concatenate([[0], bounds]).astype(np.int64)
    ends = np.concatenate([bounds, [len(key)]]).astype(np.int64)
    dep_l = e_dep[order].tolist()
    to_l = e_dst[order].tolist()
    sb_l = e_sb[order].tolist()
    arr_l = e_arr[order].tolist()
    len_l = e_len[order].tolist()
    store = p.edge_store
    empty: tuple[list[float], list[int], list[int], list[float], list[float]] = ([], [], [], [], [])
    for a in nodes.tolist():
        store.setdefault((a, 1), empty)
        store.setdefault((a, -1), empty)
    if len(key):
        for k, i, j in zip(key[starts].tolist(), starts.tolist(), ends.tolist()):
            node, s = k >> 1, (-1 if k & 1 else 1)
            store[(node, s)] = (dep_l[i:j], to_l[i:j], sb_l[i:j], arr_l[i:j], len_l[i:j])


def _misses_full(p: Planner, a: NDArray[np.float64], b: NDArray[np.float64], step: float) -> NDArray[np.bool_]:
    """False where segment ``a -> b`` surely is not clear: a sample on it lies in a fully blocked cell.

    Every point of a clear segment is clear, so its cell is not fully blocked; samples
    every ``step`` cells therefore never reject a clear segment (they may miss a blocked one,
    which the exact test then rejects). With numba (the ``fast`` extra) the samples are
    taken in compiled code (:mod:`pointnav_core.geodesic._sight_kernel`), with the same expressions,
    and a segment stops at its first bad sample.
    """
    geo = p.geo
    full = p.fully_blocked_mask()  # padded by one ring
    h, w = full.shape
    res = geo.resolution
    kernel = _compiled.kernel("pointnav_core.geodesic._sight_kernel", "misses_full")
    if kernel is not None:  # the same samples, each segment stopping at its first bad one
        out = np.empty(len(a), dtype=np.bool_)
        kernel(np.ascontiguousarray(a[:, 0]), np.ascontiguousarray(a[:, 1]), np.ascontiguousarray(b[:, 0]),
               np.ascontiguousarray(b[:, 1]), np.ascontiguousarray(full).ravel(), h, w, float(geo.origin[0]),
               float(geo.origin[1]), float(res), float(step), bool(geo.outside_blocked), out)
        return out
    n = np.maximum(np.ceil(np.hypot(*(b - a).T) / (step * res)).astype(np.int64), 1) + 1
    seg = np.repeat(np.arange(len(a)), n)
    start = np.repeat(np.cumsum(n) - n, n)
    t = (np.arange(len(seg)) - start) / (n[seg] - 1)
    x = a[seg, 0] + t * (b[seg, 0] - a[seg, 0])
    y = a[seg, 1] + t * (b[seg, 1] - a[seg, 1])
    col = np.floor((x - geo.origin[0]) / res).astype(np.int64) + 1
    row = np.floor((y - geo.origin[1]) / res).astype(np.int64) + 1
    inside = (col >= 0) & (col < w) & (row >= 0) & (row < h)
    bad = np.where(inside, full[np.clip(row, 0, h - 1), np.clip(col, 0, w - 1)], geo.outside_blocked)
    return np.bincount(seg[bad], minlength=len(a)) == 0
