"""The compiled path of :func:`pointnav_core.crowds.orca.orca_step` (imports numba).

Imported only through ``utils.compiled.kernel``, so the package imports without numba. One
agent at a time, RVO2's ``Agent::computeNeighbors``, ``Agent::computeNewVelocity`` (agent
lines only) and ``linearProgram1/2/3`` transcribed statement by statement in float32, the
precision of RVO2's ``Vector2``: every constant is a float32 so that no expression widens
to float64, and a vector divided by a scalar is multiplied by the scalar's inverse, as
``Vector2::operator/`` does. A line is a row ``(point x, point y, direction x, direction y)``.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["orca_worlds"]

_jit = numba.njit(cache=True, nogil=True, error_model="numpy")
_F = np.float32
_ZERO = np.float32(0.0)
_HALF = np.float32(0.5)
_ONE = np.float32(1.0)
_EPS = np.float32(1e-5)  # RVO_EPSILON


@_jit
def _det(ax, ay, bx, by):  # pragma: no cover
    return ax * by - ay * bx


@_jit
def _neighbours(px, py, i, range_sq, k, idx, dist):  # pragma: no cover
    # Agent::insertAgentNeighbor over the agents in index order: the k nearest closer than
    # sqrt(range_sq), nearest first, an equal distance after those already in.
    count = 0
    for j in range(px.shape[0]):
        if j == i:
            continue
        dx = px[i] - px[j]
        dy = py[i] - py[j]
        d = dx * dx + dy * dy
        if d < range_sq:
            if count < k:
                count += 1
            s = count - 1
            while s != 0 and d < dist[s - 1]:
                dist[s] = dist[s - 1]
                idx[s] = idx[s - 1]
                s -= 1
            dist[s] = d
            idx[s] = j
            if count == k:
                range_sq = dist[count - 1]
    return count


@_jit
def _agent_line(rpx, rpy, rvx, rvy, cr, inv_tau, inv_dt, vx, vy, line):  # pragma: no cover
    # The agent ORCA line of one neighbour (relative position rp = other - self, relative
    # velocity rv = self - other, combined radius cr), as computeNewVelocity builds it.
    dist_sq = rpx * rpx + rpy * rpy
    cr_sq = cr * cr
    if dist_sq > cr_sq:
        wx = rvx - inv_tau * rpx
        wy = rvy - inv_tau * rpy
        w_sq = wx * wx + wy * wy
        dot = wx * rpx + wy * rpy
        if dot < _ZERO and dot * dot > cr_sq * w_sq:
            w_len = np.sqrt(w_sq)
            inv = _ONE / w_len
            ux, uy = wx * inv, wy * inv
            line[2], line[3] = uy, -ux
            s = cr * inv_tau - w_len
            ux, uy = s * ux, s * uy
        else:
            leg = np.sqrt(dist_sq - cr_sq)
            inv = _ONE / dist_sq
            if _det(rpx, rpy, wx, wy) > _ZERO:
                line[2] = (rpx * leg - rpy * cr) * inv
                line[3] = (rpx * cr + rpy * leg) * inv
            else:
                line[2] = -(rpx * leg + rpy * cr) * inv
                line[3] = -(-rpx * cr + rpy * leg) * inv
            dot = rvx * line[2] + rvy * line[3]
            ux = dot * line[2] - rvx
            uy = dot * line[3] - rvy
    else:
        wx = rvx - inv_dt * rpx
        wy = rvy - inv_dt * rpy
        w_len = np.sqrt(wx * wx + wy * wy)
        inv = _ONE / w_len
        ux, uy = wx * inv, wy * inv
        line[2], line[3] = uy, -ux
        s = cr * inv_dt - w_len
        ux, uy = s * ux, s * uy
    line[0] = vx + _HALF * ux
    line[1] = vy + _HALF * uy


@_jit
def _lp1(lines, no, radius, optx, opty, direction_opt, result):  # pragma: no cover
    # linearProgram1: the best point on line `no` within the speed circle and lines < no.
    ppx, ppy, ddx, ddy = lines[no, 0], lines[no, 1], lines[no, 2], lines[no, 3]
    dot = ppx * ddx + ppy * ddy
    disc = dot * dot + radius * radius - (ppx * ppx + ppy * ppy)
    if disc < _ZERO:
        return False
    sq = np.sqrt(disc)
    t_left = -dot - sq
    t_right = -dot + sq
    for i in range(no):
        den = _det(ddx, ddy, lines[i, 2], lines[i, 3])
        num = _det(lines[i, 2], lines[i, 3], ppx - lines[i, 0], ppy - lines[i, 1])
        if np.fabs(den) <= _EPS:
            if num < _ZERO:
                return False
            continue
        t = num / den
        # std::min(t_right, t) and std::max(t_left, t), which keep the first of equals
        if den >= _ZERO:
            if t < t_right:  # noqa: PLR1730 (min() need not keep the first of equal zeros)
                t_right = t
        elif t_left < t:
            t_left = t
        if t_left > t_right:
            return False
    if direction_opt:
        t = t_right if optx * ddx + opty * ddy > _ZERO else t_left
    else:
        t = ddx * (optx - ppx) + ddy * (opty - ppy)
        if t < t_left:
            t = t_left
        elif t > t_right:
            t = t_right
    result[0] = ppx + t * ddx
    result[1] = ppy + t * ddy
    return True


@_jit
def _lp2(lines, m, radius, optx, opty, direction_opt, result):  # pragma: no cover
    # linearProgram2: the first m lines; returns the line that failed, or m.
    if direction_opt:
        result[0], result[1] = optx * radius, opty * radius
    elif optx * optx + opty * opty > radius * radius:
        inv = _ONE / np.sqrt(optx * optx + opty * opty)
        result[0], result[1] = optx * inv * radius, opty * inv * radius
    else:
        result[0], result[1] = optx, opty
    for i in range(m):
        if _det(lines[i, 2], lines[i, 3], lines[i, 0] - result[0], lines[i, 1] - result[1]) > _ZERO:
            keep0, keep1 = result[0], result[1]
            if not _lp1(lines, i, radius, optx, opty, direction_opt, result):
                result[0], result[1] = keep0, keep1
                return i
    return m


@_jit
def _project(lines, i, j, out):  # pragma: no cover
    # linearProgram3's projected line of line j on line i; False where they point alike.
    ix, iy, idx, idy = lines[i, 0], lines[i, 1], lines[i, 2], lines[i, 3]
    jx, jy, jdx, jdy = lines[j, 0], lines[j, 1], lines[j, 2], lines[j, 3]
    determinant = _det(idx, idy, jdx, jdy)
    if np.fabs(determinant) <= _EPS:
        if idx * jdx + idy * jdy > _ZERO:
            return False
        out[0] = _HALF * (ix + jx)
        out[1] = _HALF * (iy + jy)
    else:
        s = _det(jdx, jdy, ix - jx, iy - jy) / determinant
        out[0] = ix + s * idx
        out[1] = iy + s * idy
    dx = jdx - idx
    dy = jdy - idy
    inv = _ONE / np.sqrt(dx * dx + dy * dy)
    out[2] = dx * inv
    out[3] = dy * inv
    return True


@_jit
def _lp3(lines, m, begin, radius, result, proj):  # pragma: no cover
    # linearProgram3 without obstacle lines: the least-violating velocity from line `begin` on.
    distance = _ZERO
    keep = np.empty(2, np.float32)
    for i in range(begin, m):
        if _det(lines[i, 2], lines[i, 3], lines[i, 0] - result[0], lines[i, 1] - result[1]) > distance:
            count = 0
            for j in range(i):
                if _project(lines, i, j, proj[count]):
                    count += 1
            keep[0], keep[1] = result[0], result[1]
            if _lp2(proj, count, radius, -lines[i, 3], lines[i, 2], True, result) < count:
                result[0], result[1] = keep[0], keep[1]
            distance = _det(lines[i, 2], lines[i, 3], lines[i, 0] - result[0], lines[i, 1] - result[1])


@_jit
def _new_velocity(pos, vel, pref, radius, max_speed, i, params, k, idx, dist, lines, proj, out):  # pragma: no cover
    # computeNeighbors + computeNewVelocity of agent i; params = (dt, range_sq, 1/tau).
    inv_dt = _ONE / params[0]
    count = 0
    if k > 0:
        count = _neighbours(pos[:, 0], pos[:, 1], i, params[1], k, idx, dist)
    for s in range(count):
        j = idx[s]
        _agent_line(pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1], vel[i, 0] - vel[j, 0], vel[i, 1] - vel[j, 1],
                    radius[i] + radius[j], params[2], inv_dt, vel[i, 0], vel[i, 1], lines[s])
    fail = _lp2(lines, count, max_speed[i], pref[i, 0], pref[i, 1], False, out)
    if fail < count:
        _lp3(lines, count, fail, max_speed[i], out, proj)


@_jit
def orca_worlds(pos, vel, pref, radius, max_speed, params, max_neighbors):  # pragma: no cover
    """One RVO2 ``doStep`` in each world, in place: every agent's new velocity from the
    old state first, then every position. ``pos``, ``vel``, ``pref`` (w, n, 2), ``radius``,
    ``max_speed`` (w, n), float32; ``params`` float32 (time step, neighbour distance squared,
    1 / time horizon); ``max_neighbors`` an int."""
    n = pos.shape[1]
    k = max(min(max_neighbors, n - 1), 0)
    idx = np.empty(max(k, 1), np.int64)
    dist = np.empty(max(k, 1), np.float32)
    lines = np.empty((max(k, 1), 4), np.float32)
    proj = np.empty((max(k, 1), 4), np.float32)
    new = np.empty((n, 2), np.float32)
    for w in range(pos.shape[0]):
        for i in range(n):
            _new_velocity(pos[w], vel[w], pref[w], radius[w], max_speed[w], i, params, k, idx, dist, lines, proj, new[i])
        for i in range(n):
            vel[w, i, 0], vel[w, i, 1] = new[i, 0], new[i, 1]
            pos[w, i, 0] = pos[w, i, 0] + new[i, 0] * params[0]
            pos[w, i, 1] = pos[w, i, 1] + new[i, 1] * params[0]
