"""The compiled path of :func:`pointnav_core.crowds.social_force.social_force_step`
(imports numba).

Imported only through ``utils.compiled.kernel``, so the package imports without numba. One
agent at a time, the formulas of the numpy path (``_social_force_array``, which cites
pysocialforce's classes) in float64, with the same pair order, so the two differ only where
numpy's and the C library's ``exp`` and ``atan2`` round differently (the last bit).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from pointnav_core.crowds._social_force_array import (
    COS_PHI,
    DELTA,
    DT,
    FOV_FACTOR,
    GAMMA,
    GOAL_THRESHOLD,
    LAMBDA,
    N_PRIME,
    RADIUS,
    REPULSION,
    SIGMA,
    SOCIAL,
    STOP,
    TAU,
    V0,
    WALL,
    WALL_SIGMA,
    WALL_THRESHOLD,
    N,
)

__all__ = ["social_force_worlds"]

_jit = numba.njit(cache=True, nogil=True, error_model="numpy")


@_jit
def _unit(x, y):  # pragma: no cover
    length = math.hypot(x, y)
    if length == 0:
        return 0.0, 0.0, length
    return x / length, y / length, length


@_jit
def _moussaid(pos, vel, a, b, p):  # pragma: no cover
    # SocialForce's term of agent b on agent a (before the factor).
    ex, ey, dist = _unit(pos[a, 0] - pos[b, 0], pos[a, 1] - pos[b, 1])
    vx = -(vel[a, 0] - vel[b, 0])
    vy = -(vel[a, 1] - vel[b, 1])
    tx, ty, length = _unit(p[LAMBDA] * vx + ex, p[LAMBDA] * vy + ey)
    big_b = p[GAMMA] * length
    if big_b == 0:
        return 0.0, 0.0
    theta = math.atan2(ty, tx) - math.atan2(ey, ex)
    fv = math.exp(-1.0 * dist / big_b - (p[N_PRIME] * big_b * theta) ** 2)
    sign = 1.0 if theta > 0 else (-1.0 if theta < 0 else 0.0)
    fa = -sign * math.exp(-1.0 * dist / big_b - (p[N] * big_b * theta) ** 2)
    return fv * tx + fa * -ty, fv * ty + fa * tx


@_jit
def _potential(rx, ry, sx, sy, step, p):  # pragma: no cover
    inner = (math.hypot(rx, ry) + math.hypot(rx - sx, ry - sy)) ** 2 - step**2
    return p[V0] * math.exp(-(0.5 * math.sqrt(max(inner, 0.0))) / p[SIGMA])


@_jit
def _helbing_molnar(pos, vel, goal_dir, a, b, p):  # pragma: no cover
    # PedRepulsiveForce's term of agent b on agent a (before the factor), field of view included.
    rx = pos[a, 0] - pos[b, 0]
    ry = pos[a, 1] - pos[b, 1]
    step = p[DT] * math.hypot(vel[b, 0], vel[b, 1])
    sx = step * goal_dir[b, 0]
    sy = step * goal_dir[b, 1]
    value = _potential(rx, ry, sx, sy, step, p)
    fx = -1.0 * ((_potential(rx + p[DELTA], ry, sx, sy, step, p) - value) / p[DELTA])
    fy = -1.0 * ((_potential(rx, ry + p[DELTA], sx, sy, step, p) - value) / p[DELTA])
    seen = goal_dir[a, 0] * -fx + goal_dir[a, 1] * -fy > math.hypot(fx, fy) * p[COS_PHI]
    weight = 1.0 if seen else p[FOV_FACTOR]
    return weight * fx, weight * fy


@_jit
def _world(pos, vel, goal, speed, max_speed, points, count, p, model, goal_dir, goal_dist, new):  # pragma: no cover
    n = pos.shape[0]
    for a in range(n):
        goal_dir[a, 0], goal_dir[a, 1], goal_dist[a] = _unit(goal[a, 0] - pos[a, 0], goal[a, 1] - pos[a, 1])
    for a in range(n):
        if goal_dist[a] > p[GOAL_THRESHOLD]:
            fx = (goal_dir[a, 0] * speed[a] - vel[a, 0]) / p[TAU]
            fy = (goal_dir[a, 1] * speed[a] - vel[a, 1]) / p[TAU]
        else:
            fx = -1.0 * vel[a, 0] / p[TAU]
            fy = -1.0 * vel[a, 1] / p[TAU]
        sx = 0.0
        sy = 0.0
        for b in range(n):
            if b == a:
                continue
            if model == 0:
                tx, ty = _moussaid(pos, vel, a, b, p)
            else:
                tx, ty = _helbing_molnar(pos, vel, goal_dir, a, b, p)
            sx += tx
            sy += ty
        scale = p[SOCIAL] if model == 0 else p[REPULSION]
        fx = fx + sx * scale
        fy = fy + sy * scale
        if count > 0:
            wx = 0.0
            wy = 0.0
            for k in range(count):
                ux, uy, dist = _unit(pos[a, 0] - points[k, 0], pos[a, 1] - points[k, 1])
                gap = dist - p[RADIUS]
                if gap < p[WALL_THRESHOLD] + p[RADIUS]:
                    e = math.exp(-gap / p[WALL_SIGMA])
                    wx += ux * e
                    wy += uy * e
            fx = fx + wx * p[WALL]
            fy = fy + wy * p[WALL]
        nx = vel[a, 0] + p[DT] * fx
        ny = vel[a, 1] + p[DT] * fy
        s = math.hypot(nx, ny)
        factor = 0.0 if s == 0 else min(1.0, max_speed[a] / s)
        if goal_dist[a] < p[STOP]:  # arrived: stop
            new[a, 0] = 0.0
            new[a, 1] = 0.0
        else:
            new[a, 0] = nx * factor
            new[a, 1] = ny * factor
    for a in range(n):
        pos[a, 0] += new[a, 0] * p[DT]
        pos[a, 1] += new[a, 1] * p[DT]
        vel[a, 0] = new[a, 0]
        vel[a, 1] = new[a, 1]


@_jit
def social_force_worlds(pos, vel, goal, speed, max_speed, points, count, p, model):  # pragma: no cover
    """One step of every world, in place (the arguments of ``social_force_array``)."""
    n = pos.shape[1]
    goal_dir = np.empty((n, 2))
    goal_dist = np.empty(n)
    new = np.empty((n, 2))
    for w in range(pos.shape[0]):
        _world(pos[w], vel[w], goal[w], speed[w], max_speed[w], points[w], count[w], p, model, goal_dir, goal_dist, new)
