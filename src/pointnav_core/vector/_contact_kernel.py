"""The compiled path of the batched contacts (imports numba); see :mod:`~pointnav_core.vector.contacts_jit`.

Imported only when the compiled path runs, so the package imports without numba. One loop
over worlds; inside a world, the kinematic backend's :func:`pointnav_kinematic.contacts.advance`
one robot and one wall at a time, with the array path's expressions (:mod:`~pointnav_core.vector.sweep`,
:func:`~pointnav_core.vector.robots.advance_robots`), so that both paths take the same
decisions on the same floats.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["advance_worlds"]

_jit = numba.njit(cache=True, nogil=True, error_model="numpy")
# advance_worlds' steps. They allocate nothing, so they run without numba's reference
# counting (_nrt=False; numba refuses to compile one that would need it): counting the
# arrays they are handed, call by call, made the kernel twice as slow.
_step = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
_INF = math.inf
# The backend's tolerances (m), as in vector.contacts and vector.robots.
_HIT = 0.5e-9
_PLACE = 1.0e-9
_ACTIVE = 2.0e-9
_EVENTS_PER_ROBOT = 8


@_jit
def enter_box(px, py, dx, dy, x0, y0, x1, y1):  # pragma: no cover
    # sweep.enter_box for one pair: first t >= 0 in the open box, inf if never.
    lo = -_INF
    hi = _INF
    if dx != 0.0:
        a = (x0 - px) / dx
        b = (x1 - px) / dx
        lo = min(a, b)
        hi = max(a, b)
    elif not x0 < px < x1:
        return _INF
    if dy != 0.0:
        a = (y0 - py) / dy
        b = (y1 - py) / dy
        lo = max(lo, min(a, b))
        hi = min(hi, max(a, b))
    elif not y0 < py < y1:
        return _INF
    if lo < hi and hi > 0.0:
        return max(lo, 0.0)
    return _INF


@_jit
def enter_disc(px, py, dx, dy, cx, cy, radius):  # pragma: no cover
    # sweep.enter_disc for one pair.
    fx = px - cx
    fy = py - cy
    c = fx * fx + fy * fy - radius * radius
    if c < 0.0:
        return 0.0
    b = fx * dx + fy * dy
    a = dx * dx + dy * dy
    disc = b * b - a * c
    if b >= 0.0 or disc <= 0.0:
        return _INF
    denom = -b + math.sqrt(disc)
    return c / (denom if denom != 0.0 else 1.0)


@_jit
def enter_rounded_square(px, py, dx, dy, x0, y0, x1, y1, radius):  # pragma: no cover
    # sweep.enter_rounded_square for one pair.
    t = min(enter_box(px, py, dx, dy, x0 - radius, y0, x1 + radius, y1),
            enter_box(px, py, dx, dy, x0, y0 - radius, x1, y1 + radius))
    if radius > 0.0 and t > 0.0:
        t = min(t, enter_disc(px, py, dx, dy, x0, y0, radius))
        t = min(t, enter_disc(px, py, dx, dy, x1, y0, radius))
        t = min(t, enter_disc(px, py, dx, dy, x0, y1, radius))
        t = min(t, enter_disc(px, py, dx, dy, x1, y1, radius))
    return t


@_jit
def square_distance(px, py, x0, y0, x1, y1):  # pragma: no cover
    # sweep.square_distance for one pair: signed distance (m) and outward unit normal;
    # inside, the nearest face, the first of a tie in the order -x, +x, -y, +y.
    qx = min(max(px, x0), x1)
    qy = min(max(py, y0), y1)
    vx = px - qx
    vy = py - qy
    dist = math.sqrt(vx * vx + vy * vy)
    if dist > 0.0:
        return dist, vx / dist, vy / dist
    depth = px - x0
    nx = -1.0
    ny = 0.0
    if x1 - px < depth:
        depth, nx, ny = x1 - px, 1.0, 0.0
    if py - y0 < depth:
        depth, nx, ny = py - y0, 0.0, -1.0
    if y1 - py < depth:
        depth, nx, ny = y1 - py, 0.0, 1.0
    return -depth, nx, ny


@_jit
def _hit(radius):  # pragma: no cover
    # A point robot is a disc of _HIT (the backend's _hit_radius).
    return max(radius - _HIT, _HIT)


@_jit
def segment_distance(px, py, ax, ay, ux, uy, length):  # pragma: no cover
    # The backend's segment_distance: distance (m) to the segment and the unit normal from
    # its nearest point towards p; on the segment itself, its left normal.
    s = (px - ax) * ux + (py - ay) * uy
    s = 0.0 if s < 0.0 else min(s, length)
    vx = px - (ax + s * ux)
    vy = py - (ay + s * uy)
    dist = math.sqrt(vx * vx + vy * vy)
    if dist > 0.0:
        return dist, vx / dist, vy / dist
    return 0.0, -uy, ux


@_jit
def enter_capsule(px, py, dx, dy, ax, ay, bx, by, ux, uy, length, radius):  # pragma: no cover
    # The backend's enter_capsule: the rectangle part in the segment's frame, then its ends.
    rx = px - ax
    ry = py - ay
    t = enter_box(rx * ux + ry * uy, ry * ux - rx * uy, dx * ux + dy * uy, dy * ux - dx * uy, 0.0, -radius, length, radius)
    if t > 0.0 and radius > 0.0:
        t = min(t, enter_disc(px, py, dx, dy, ax, ay, radius))
        t = min(t, enter_disc(px, py, dx, dy, bx, by, radius))
    return t


@_jit
def _wall_distance(wall, k, j, px, py):  # pragma: no cover
    # Robot k's wall j: a cell square (column 7 is 0) or a polygon edge (1), as the backend's wall_distance.
    if wall[k, j, 7] == 0.0:
        return square_distance(px, py, wall[k, j, 0], wall[k, j, 1], wall[k, j, 2], wall[k, j, 3])
    return segment_distance(px, py, wall[k, j, 0], wall[k, j, 1], wall[k, j, 4], wall[k, j, 5], wall[k, j, 6])


@_jit
def _enter_wall(wall, k, j, px, py, dx, dy, radius):  # pragma: no cover
    # The backend's enter_wall on robot k's wall j.
    if wall[k, j, 7] == 0.0:
        return enter_rounded_square(px, py, dx, dy, wall[k, j, 0], wall[k, j, 1], wall[k, j, 2], wall[k, j, 3], radius)
    return enter_capsule(px, py, dx, dy, wall[k, j, 0], wall[k, j, 1], wall[k, j, 2], wall[k, j, 3],
                         wall[k, j, 4], wall[k, j, 5], wall[k, j, 6], radius)


@_jit
def _blocks(k, c, tx, ty, left, px, py, rad, cnx, cny, ckind, cforced, wall):  # pragma: no cover
    # Whether motion (tx, ty) of robot k, for ``left`` of the step, goes into its contact c
    # (the backend's _blocks): towards it, and forced or deeper than _HIT before ``left``.
    if tx * cnx[c] + ty * cny[c] >= 0.0:
        return False
    if cforced[c]:
        return True
    j = ckind[c]
    if j >= 0:
        t = _enter_wall(wall, k, j, px[k], py[k], tx, ty, _hit(rad[k]))
    else:
        m = -j - 1
        t = enter_disc(px[k], py[k], tx, ty, px[m], py[m], _hit(rad[k] + rad[m]))
    return t <= left


@_jit
def _resolve(n, px, py, mx, my, left, nwall, wall, pair, ev_k, ev_j, ev_m, rad, flag,
             cnx, cny, ckind, cforced):  # pragma: no cover
    # Every moving robot whose motion goes into a contact it touches (within _ACTIVE)
    # slides along the longest contact tangent that goes into no contact, else stops
    # (the backend's _resolve and _slide). Contacts: its walls, then the other robots.
    # The event just reached (robot ev_k against wall ev_j, or robots ev_k and ev_m)
    # blocks however shallow. Robots count as standing still: positions do not change here.
    for k in range(n):
        if mx[k] == 0.0 and my[k] == 0.0:
            continue
        nc = 0
        for j in range(nwall[k]):
            d, nx, ny = _wall_distance(wall, k, j, px[k], py[k])
            if d <= rad[k] + _ACTIVE:
                cnx[nc] = nx
                cny[nc] = ny
                ckind[nc] = j
                cforced[nc] = ev_k == k and ev_j == j
                nc += 1
        for m in range(n):
            if not pair[k, m]:
                continue
            ex = px[k] - px[m]
            ey = py[k] - py[m]
            dist = math.sqrt(ex * ex + ey * ey)
            if dist <= rad[k] + rad[m] + _ACTIVE:
                cnx[nc] = ex / dist if dist > 0.0 else 1.0
                cny[nc] = ey / dist if dist > 0.0 else 0.0
                ckind[nc] = -m - 1
                cforced[nc] = ev_m >= 0 and ((ev_k == k and ev_m == m) or (ev_k == m and ev_m == k))
                nc += 1
        tx0 = mx[k]
        ty0 = my[k]
        blocked = False
        for c in range(nc):
            if _blocks(k, c, tx0, ty0, left, px, py, rad, cnx, cny, ckind, cforced, wall):
                blocked = True
                if ckind[c] < 0:
                    flag[-ckind[c] - 1] = True  # the robot it ran into
        if not blocked:
            continue
        flag[k] = True
        best_x = 0.0
        best_y = 0.0
        best_len = 0.0
        for along in range(nc):
            dot = tx0 * cnx[along] + ty0 * cny[along]
            tx = tx0 - dot * cnx[along]
            ty = ty0 - dot * cny[along]
            length = tx * tx + ty * ty
            if length <= best_len:
                continue
            clear = True
            for c in range(nc):
                if c != along and _blocks(k, c, tx, ty, left, px, py, rad, cnx, cny, ckind, cforced, wall):
                    clear = False
                    break
            if clear:
                best_x = tx
                best_y = ty
                best_len = length
        mx[k] = best_x
        my[k] = best_y


@_jit
def advance_worlds(x, y, mx, my, slow, scene, radius, meta, edge, dr, dc, ok, seg, seg_off, x_out, y_out, contact):  # pragma: no cover
    """Move the ``slow`` robots of every world by their chords with contacts (the backend's advance).

    ``x, y, mx, my`` (W, R) float64 start positions and chords (m); ``slow`` (W, R) the
    robots resolved here (the others neither move nor block: they are out of reach);
    ``radius`` (W, R) float64 each robot's radius (m; two robots touch at the sum);
    ``scene`` (W, R) int64; ``meta`` (S, 7) per scene: flat offset, rows, width, ox, oy,
    cell size, 1 / cell size; ``edge`` (all cells) bool the edge obstacle flags;
    ``dr, dc, ok`` (S, P) per scene the row-major cell stencil of the longest chord
    (``FloorTables.stencil``); ``seg`` (N, 7) the floors' polygon edges ``(ax, ay, bx, by,
    ux, uy, length)``, scene ``s``'s at rows ``seg_off[s]:seg_off[s + 1]``. Writes the slow robots' end positions to ``x_out, y_out`` and their contact flags
    to ``contact``.
    """
    n_worlds, n_robots = x.shape
    n_table = dr.shape[1]
    # One world's slow robots, k = 0 .. n - 1: robot index, radius (m), position (m), start
    # (m), chord (m), its length (m), contact flag.
    ids = np.empty(n_robots, np.int64)
    rad = np.empty(n_robots)
    px = np.empty(n_robots)
    py = np.empty(n_robots)
    sx = np.empty(n_robots)
    sy = np.empty(n_robots)
    vx = np.empty(n_robots)
    vy = np.empty(n_robots)
    span = np.empty(n_robots)
    flag = np.zeros(n_robots, np.bool_)
    nwall = np.zeros(n_robots, np.int64)
    most_seg = 0
    for q in range(seg_off.shape[0] - 1):
        most_seg = max(most_seg, seg_off[q + 1] - seg_off[q])
    # Per wall: a square's corners (0-3), or an edge's ends, direction and length (0-6);
    # column 7 says which (0 square, 1 edge).
    wall = np.empty((n_robots, max(n_table, 1) + most_seg, 8))
    pair = np.zeros((n_robots, n_robots), np.bool_)
    n_contacts = max(n_table, 1) + most_seg + n_robots
    cnx = np.empty(n_contacts)
    cny = np.empty(n_contacts)
    ckind = np.empty(n_contacts, np.int64)
    cforced = np.empty(n_contacts, np.bool_)
    for w in range(n_worlds):
        n = 0
        for i in range(n_robots):
            if slow[w, i]:
                ids[n] = i
                n += 1
        if n == 0:
            continue
        n_moving = 0
        for k in range(n):
            i = ids[k]
            px[k] = sx[k] = x[w, i]
            py[k] = sy[k] = y[w, i]
            vx[k] = mx[w, i]
            vy[k] = my[w, i]
            rad[k] = radius[w, i]
            span[k] = math.sqrt(vx[k] * vx[k] + vy[k] * vy[k])
            flag[k] = False
            nwall[k] = 0
            if span[k] > 0.0:
                n_moving += 1
            # Its walls within reach of the whole chord: edge squares, then polygon edges.
            reach = rad[k] + span[k] + 4.0 * _ACTIVE
            _square_walls(k, px[k], py[k], reach, scene[w, i], meta, edge, dr, dc, ok, wall, nwall)
            _segment_walls(k, px[k], py[k], reach, scene[w, i], seg, seg_off, wall, nwall)
        if n_moving == 0:
            for k in range(n):
                x_out[w, ids[k]] = px[k]
                y_out[w, ids[k]] = py[k]
                contact[w, ids[k]] = False
            continue
        _pair_list(n, px, py, rad, span, pair)
        _events(n, n_moving, px, py, vx, vy, rad, nwall, wall, pair, flag, cnx, cny, ckind, cforced)
        _finish(w, n, ids, px, py, sx, sy, rad, flag, nwall, wall, x_out, y_out, contact)


@_step
def _square_walls(k, px, py, reach, s, meta, edge, dr, dc, ok, wall, nwall):  # pragma: no cover
    # Robot k's edge squares of scene s within reach (m) of (px, py) (m), in row-major
    # order, appended to its walls (wall[k], nwall[k]); meta, edge, dr, dc, ok as in
    # advance_worlds. Off the map: none (its polygon edges, if any, still count).
    off = int(meta[s, 0])
    rows = int(meta[s, 1])
    width = int(meta[s, 2])
    ox = meta[s, 3]
    oy = meta[s, 4]
    res = meta[s, 5]
    inv = meta[s, 6]
    col = math.floor((px - ox) * inv)
    row = math.floor((py - oy) * inv)
    for j in range(dr.shape[1] if 0 <= col < width and 0 <= row < rows else 0):
        if not ok[s, j]:
            break
        wr = int(row) + dr[s, j]
        wc = int(col) + dc[s, j]
        if not (0 <= wr < rows and 0 <= wc < width) or not edge[off + wr * width + wc]:
            continue
        wx0 = ox + wc * res
        wy0 = oy + wr * res
        if square_distance(px, py, wx0, wy0, wx0 + res, wy0 + res)[0] <= reach:
            m = nwall[k]
            wall[k, m, 0] = wx0
            wall[k, m, 1] = wy0
            wall[k, m, 2] = wx0 + res
            wall[k, m, 3] = wy0 + res
            wall[k, m, 7] = 0.0
            nwall[k] = m + 1


@_step
def _segment_walls(k, px, py, reach, s, seg, seg_off, wall, nwall):  # pragma: no cover
    # Robot k's polygon edges of scene s within reach (m) of (px, py) (m), in their order
    # (the backend's walls()), appended to its walls.
    for q in range(seg_off[s], seg_off[s + 1]):
        if segment_distance(px, py, seg[q, 0], seg[q, 1], seg[q, 4], seg[q, 5], seg[q, 6])[0] <= reach:
            m = nwall[k]
            for c in range(7):
                wall[k, m, c] = seg[q, c]
            wall[k, m, 7] = 1.0
            nwall[k] = m + 1


@_step
def _pair_list(n, px, py, rad, span, pair):  # pragma: no cover
    # The backend's pair list into pair (n, n): two robots, not both still, within reach
    # (m) of each other over the whole chord (span, m).
    for k in range(n):
        pair[k, k] = False
        for m in range(k + 1, n):
            near = False
            if span[k] > 0.0 or span[m] > 0.0:
                reach = rad[k] + rad[m] + span[k] + span[m] + 4.0 * _ACTIVE
                near = (px[k] - px[m]) ** 2 + (py[k] - py[m]) ** 2 < reach * reach
            pair[k, m] = near
            pair[m, k] = near


@_step
def _first_event(n, px, py, vx, vy, rad, nwall, wall, pair, left):  # pragma: no cover
    # The first hit within ``left`` of the step: walls robot by robot, then pairs; the
    # first wins a tie. (t, k, j, m): robot k against its wall j (m = -1) or robot m
    # (j = -1); k = -1 and t = left when none.
    t_first = left
    ev_k = -1
    ev_j = -1
    ev_m = -1
    for k in range(n):
        if vx[k] == 0.0 and vy[k] == 0.0:
            continue
        speed = math.sqrt(vx[k] * vx[k] + vy[k] * vy[k])
        hit_w = _hit(rad[k])
        for j in range(nwall[k]):
            d, nx, ny = _wall_distance(wall, k, j, px[k], py[k])
            if vx[k] * nx + vy[k] * ny >= 0.0 or d - hit_w > speed * left:
                continue
            t = _enter_wall(wall, k, j, px[k], py[k], vx[k], vy[k], hit_w)
            if t < t_first:
                t_first = t
                ev_k = k
                ev_j = j
                ev_m = -1
    for k in range(n):
        for m in range(k + 1, n):
            if not pair[k, m]:
                continue
            rvx = vx[k] - vx[m]
            rvy = vy[k] - vy[m]
            if rvx == 0.0 and rvy == 0.0:
                continue
            t = enter_disc(px[k], py[k], rvx, rvy, px[m], py[m], _hit(rad[k] + rad[m]))
            if t < t_first:
                if t == 0.0 and (px[k] - px[m]) * rvx + (py[k] - py[m]) * rvy >= 0.0:
                    continue
                t_first = t
                ev_k = k
                ev_j = -1
                ev_m = m
    return t_first, ev_k, ev_j, ev_m


@_step
def _events(n, n_moving, px, py, vx, vy, rad, nwall, wall, pair, flag, cnx, cny, ckind, cforced):  # pragma: no cover
    # One world's step: every robot follows its chord (vx, vy, m) at once; at each event
    # the world moves to _PLACE short of touching and resolves its contacts (_resolve),
    # for at most _EVENTS_PER_ROBOT events per moving robot. Moves px, py (m) in place.
    left = 1.0
    _resolve(n, px, py, vx, vy, left, nwall, wall, pair, -1, -1, -1, rad, flag, cnx, cny, ckind, cforced)
    for _ in range(_EVENTS_PER_ROBOT * n_moving):
        t_first, ev_k, ev_j, ev_m = _first_event(n, px, py, vx, vy, rad, nwall, wall, pair, left)
        if ev_k < 0:
            for k in range(n):
                px[k] = px[k] + vx[k] * left
                py[k] = py[k] + vy[k] * left
            break
        k = ev_k
        if ev_m < 0:
            place = _enter_wall(wall, k, ev_j, px[k], py[k], vx[k], vy[k], rad[k] + _PLACE)
        else:
            m = ev_m
            place = enter_disc(px[k], py[k], vx[k] - vx[m], vy[k] - vy[m], px[m], py[m], rad[k] + rad[m] + _PLACE)
        step = min(max(place, 0.0), t_first)
        for q in range(n):
            px[q] = px[q] + vx[q] * step
            py[q] = py[q] + vy[q] * step
        left = left - step
        _resolve(n, px, py, vx, vy, left, nwall, wall, pair, ev_k, ev_j, ev_m, rad, flag, cnx, cny, ckind, cforced)


@_step
def _finish(w, n, ids, px, py, sx, sy, rad, flag, nwall, wall, x_out, y_out, contact):  # pragma: no cover
    # Write world w's end positions (m) and contact flags, with the safety net against
    # rounding: a robot never ends deeper in a wall than at its start (sx, sy).
    for k in range(n):
        i = ids[k]
        if flag[k] and (px[k] != sx[k] or py[k] != sy[k]):
            depth_end = -_INF
            depth_start = -_INF
            for j in range(nwall[k]):
                depth_end = max(depth_end, rad[k] - _wall_distance(wall, k, j, px[k], py[k])[0])
                depth_start = max(depth_start, rad[k] - _wall_distance(wall, k, j, sx[k], sy[k])[0])
            if depth_end > _HIT and depth_end > depth_start:
                px[k] = sx[k]
                py[k] = sy[k]
        x_out[w, i] = px[k]
        y_out[w, i] = py[k]
        contact[w, i] = flag[k]
