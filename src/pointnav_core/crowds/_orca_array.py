"""The plain (numpy) path of :func:`pointnav_core.crowds.orca.orca_step`.

The same float32 statements as the compiled path (``_orca_kernel``), written once for every
agent of every world at the same time: RVO2's loops over an agent's lines become loops over
the line index with a mask of the agents still in them. Only element-wise float32 ufuncs are
used (no ``dot``, no ``sum``: their summation order is not RVO2's), and each branch of RVO2's
``if`` is computed for every agent and picked with ``np.where``, so each agent gets the float
it gets from RVO2. Arrays are ``(a, ...)`` over the ``a = worlds x agents`` agents; a line
is ``(point x, point y, direction x, direction y)`` on the last axis.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["orca_array"]

F32 = NDArray[np.float32]
Mask = NDArray[np.bool_]
_F = np.float32
_ZERO = _F(0.0)
_HALF = _F(0.5)
_ONE = _F(1.0)
_EPS = _F(1e-5)  # RVO_EPSILON


def _det(ax: F32, ay: F32, bx: F32, by: F32) -> F32:
    return ax * by - ay * bx


def _neighbours(pos: F32, range_sq: np.float32, k: int) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Each agent's ``k`` nearest others closer than ``sqrt(range_sq)``, nearest first, equal
    distances in index order (``Agent::insertAgentNeighbor`` over the agents in index order).
    Returns their indices ``(w, n, k)`` within the world and their count ``(w, n)``."""
    dx = pos[:, :, None, 0] - pos[:, None, :, 0]
    dy = pos[:, :, None, 1] - pos[:, None, :, 1]
    dist = dx * dx + dy * dy
    n = pos.shape[1]
    dist[:, np.arange(n), np.arange(n)] = np.inf
    dist[dist >= range_sq] = np.inf
    order = np.argsort(dist, axis=-1, kind="stable")[..., :k]
    count = np.isfinite(np.take_along_axis(dist, order, -1)).sum(-1)
    return order, count


def _lines(rp: F32, rv: F32, cr: F32, vel: F32, inv_tau: np.float32, inv_dt: np.float32) -> F32:
    """The agent ORCA lines ``(a, k, 4)`` of relative positions ``rp`` (other - self),
    relative velocities ``rv`` (self - other), combined radii ``cr`` and own velocities."""
    rpx, rpy, rvx, rvy = rp[..., 0], rp[..., 1], rv[..., 0], rv[..., 1]
    dist_sq = rpx * rpx + rpy * rpy
    cr_sq = cr * cr
    # No collision: w from the cut-off centre to the relative velocity.
    wx = rvx - inv_tau * rpx
    wy = rvy - inv_tau * rpy
    w_sq = wx * wx + wy * wy
    dot = wx * rpx + wy * rpy
    cutoff = (dot < _ZERO) & (dot * dot > cr_sq * w_sq)
    w_len = np.sqrt(w_sq)
    inv = _ONE / w_len
    cux, cuy = wx * inv, wy * inv
    cs = cr * inv_tau - w_len
    # Legs.
    leg = np.sqrt(dist_sq - cr_sq)
    inv = _ONE / dist_sq
    left = _det(rpx, rpy, wx, wy) > _ZERO
    ldx = np.where(left, (rpx * leg - rpy * cr) * inv, -(rpx * leg + rpy * cr) * inv)
    ldy = np.where(left, (rpx * cr + rpy * leg) * inv, -(-rpx * cr + rpy * leg) * inv)
    ldot = rvx * ldx + rvy * ldy
    # Collision: the cut-off circle of one time step.
    kx = rvx - inv_dt * rpx
    ky = rvy - inv_dt * rpy
    k_len = np.sqrt(kx * kx + ky * ky)
    inv = _ONE / k_len
    kux, kuy = kx * inv, ky * inv
    ks = cr * inv_dt - k_len
    apart = dist_sq > cr_sq
    on_circle = ~apart | cutoff
    ux = np.where(apart, cux, kux)  # the unit w of either cut-off circle
    uy = np.where(apart, cuy, kuy)
    s = np.where(apart, cs, ks)
    out = np.empty((*rp.shape[:-1], 4), np.float32)
    out[..., 2] = np.where(on_circle, uy, ldx)
    out[..., 3] = np.where(on_circle, -ux, ldy)
    u_x = np.where(on_circle, s * ux, ldot * ldx - rvx)
    u_y = np.where(on_circle, s * uy, ldot * ldy - rvy)
    out[..., 0] = vel[:, None, 0] + _HALF * u_x
    out[..., 1] = vel[:, None, 1] + _HALF * u_y
    return out


def _lp1(lines: F32, no: int, radius: F32, opt: F32, direction_opt: bool, rows: Mask) -> tuple[Mask, F32]:
    """linearProgram1 on line ``no`` for the agents ``rows``: whether it succeeds, and its point."""
    px, py, dx, dy = (lines[:, no, c] for c in range(4))
    dot = px * dx + py * dy
    disc = dot * dot + radius * radius - (px * px + py * py)
    alive = rows & (disc >= _ZERO)
    sq = np.sqrt(np.where(alive, disc, _ZERO))
    t_left = -dot - sq
    t_right = -dot + sq
    for i in range(no):
        den = _det(dx, dy, lines[:, i, 2], lines[:, i, 3])
        num = _det(lines[:, i, 2], lines[:, i, 3], px - lines[:, i, 0], py - lines[:, i, 1])
        parallel = np.fabs(den) <= _EPS
        alive &= ~(parallel & (num < _ZERO))
        t = num / den
        bound = alive & ~parallel
        # std::min(t_right, t) and std::max(t_left, t), which keep the first of equals
        t_right = np.where(bound & (den >= _ZERO) & (t < t_right), t, t_right)
        t_left = np.where(bound & (den < _ZERO) & (t_left < t), t, t_left)
        alive &= ~(bound & (t_left > t_right))
    if direction_opt:
        t = np.where(opt[:, 0] * dx + opt[:, 1] * dy > _ZERO, t_right, t_left)
    else:
        t = dx * (opt[:, 0] - px) + dy * (opt[:, 1] - py)
        t = np.where(t < t_left, t_left, np.where(t > t_right, t_right, t))
    return alive, np.stack([px + t * dx, py + t * dy], axis=-1)


def _lp2(lines: F32, m: NDArray[np.int64], radius: F32, opt: F32, direction_opt: bool, rows: Mask) -> tuple[F32, NDArray[np.int64]]:
    """linearProgram2 over the first ``m[a]`` lines of each agent ``a`` in ``rows``: the
    velocities, and the line that failed (``m`` where none did)."""
    ox, oy = opt[:, 0], opt[:, 1]
    if direction_opt:
        result = np.stack([ox * radius, oy * radius], axis=-1)
    else:
        outside = ox * ox + oy * oy > radius * radius
        inv = _ONE / np.sqrt(ox * ox + oy * oy)
        result = np.stack([np.where(outside, ox * inv * radius, ox), np.where(outside, oy * inv * radius, oy)], -1)
    fail = m.copy()
    for i in range(lines.shape[1]):
        run = rows & (i < m) & (fail == m)
        run &= _det(lines[:, i, 2], lines[:, i, 3], lines[:, i, 0] - result[:, 0], lines[:, i, 1] - result[:, 1]) > _ZERO
        if not run.any():
            continue
        ok, point = _lp1(lines, i, radius, opt, direction_opt, run)
        result[run & ok] = point[run & ok]
        fail[run & ~ok] = i
    return result, fail


def _projected(lines: F32, i: int) -> tuple[F32, NDArray[np.int64]]:
    """linearProgram3's projections of lines ``0..i-1`` on line ``i``, those kept packed
    first in order, and their count per agent."""
    ix, iy, idx, idy = (lines[:, i, None, c] for c in range(4))
    jx, jy, jdx, jdy = (lines[:, :i, c] for c in range(4))
    determinant = _det(idx, idy, jdx, jdy)
    parallel = np.fabs(determinant) <= _EPS
    kept = ~(parallel & (idx * jdx + idy * jdy > _ZERO))
    s = _det(jdx, jdy, ix - jx, iy - jy) / determinant
    proj = np.empty((lines.shape[0], i, 4), np.float32)
    proj[..., 0] = np.where(parallel, _HALF * (ix + jx), ix + s * idx)
    proj[..., 1] = np.where(parallel, _HALF * (iy + jy), iy + s * idy)
    dx = jdx - idx
    dy = jdy - idy
    inv = _ONE / np.sqrt(dx * dx + dy * dy)
    proj[..., 2] = dx * inv
    proj[..., 3] = dy * inv
    order = np.argsort(~kept, axis=-1, kind="stable")
    return np.take_along_axis(proj, order[..., None], 1), kept.sum(-1)


def _lp3(lines: F32, m: NDArray[np.int64], begin: NDArray[np.int64], radius: F32, result: F32) -> None:
    """linearProgram3 without obstacle lines, in place on ``result``, for the agents whose
    linearProgram2 failed at line ``begin < m``."""
    distance = np.zeros(len(m), np.float32)
    for i in range(lines.shape[1]):
        run = (begin <= i) & (i < m)
        px, py, dx, dy = (lines[:, i, c] for c in range(4))
        run &= _det(dx, dy, px - result[:, 0], py - result[:, 1]) > distance
        if not run.any():
            continue
        proj, count = _projected(lines, i)
        opt = np.stack([-dy, dx], axis=-1)
        point, fail = _lp2(proj, count, radius, opt, True, run)
        take = run & (fail >= count)  # else RVO2 keeps the previous velocity
        result[take] = point[take]
        distance = np.where(run, _det(dx, dy, px - result[:, 0], py - result[:, 1]), distance)


def orca_array(pos: F32, vel: F32, pref: F32, radius: F32, max_speed: F32, params: F32, max_neighbors: int) -> None:
    """One RVO2 ``doStep`` in each world, in place; the arguments of ``_orca_kernel.orca_worlds``."""
    w, n = pos.shape[:2]
    k = max(min(max_neighbors, n - 1), 0)
    dt, range_sq, inv_tau = params[0], params[1], params[2]
    flat_vel = vel.reshape(-1, 2)
    new = pref.reshape(-1, 2).copy()
    speed = max_speed.reshape(-1)
    count = np.zeros(w * n, np.int64)
    lines = np.zeros((w * n, k, 4), np.float32)
    with np.errstate(all="ignore"):  # branches RVO2 does not take are computed and dropped
        if k > 0:
            order, count = _neighbours(pos, range_sq, k)
            nbr = (order + (np.arange(w) * n)[:, None, None]).reshape(w * n, k)
            flat_pos, flat_r = pos.reshape(-1, 2), radius.reshape(-1)
            rp = flat_pos[nbr] - flat_pos[:, None]
            rv = flat_vel[:, None] - flat_vel[nbr]
            cr = flat_r[:, None] + flat_r[nbr]
            lines = _lines(rp, rv, cr, flat_vel, inv_tau, _ONE / dt)
            count = count.reshape(-1)
        every = np.ones(w * n, bool)
        new, fail = _lp2(lines, count, speed, new, False, every)
        if (fail < count).any():
            _lp3(lines, count, np.where(fail < count, fail, count), speed, new)
    vel[...] = new.reshape(w, n, 2)
    pos[...] = pos + vel * dt
