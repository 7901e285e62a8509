"""The plain (numpy) path of :func:`pointnav_core.crowds.social_force.social_force_step`.

Every agent of every world at once, with pairwise ``(w, n, n, 2)`` arrays, in float64 and in
pysocialforce's order of operations (``forces.DesiredForce``, ``SocialForce``,
``ObstacleForce``, ``PedRepulsiveForce`` with ``potentials.PedPedPotential`` and
``fieldofview.FieldOfView``, ``scene.PedState.step``). The compiled path
(``_social_force_kernel``) runs the same formulas one agent at a time; ``exp`` and ``atan2``
of numpy and of the C library can differ in the last bit, so the two agree to rounding, not
bit for bit. ``p`` is :func:`~pointnav_core.crowds.social_force.packed`'s parameter vector.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["social_force_array"]

F64 = NDArray[np.float64]

# Indices of the packed parameters (social_force.packed).
(DT, TAU, GOAL_THRESHOLD, STOP, SOCIAL, LAMBDA, GAMMA, N, N_PRIME, REPULSION, V0, SIGMA, COS_PHI, FOV_FACTOR,
 DELTA, WALL, WALL_SIGMA, WALL_THRESHOLD, RADIUS) = range(19)


def _total(x: F64) -> F64:
    """The sum over the last axis in index order (the compiled path's order; ``sum``'s
    pairwise order would change with the padding of a world's walls)."""
    return np.cumsum(x, axis=-1)[..., -1] if x.shape[-1] else x.sum(-1)


def _unit(x: F64, y: F64) -> tuple[F64, F64, F64]:
    """``(x, y) / |(x, y)|`` and the length; the zero vector for a zero length
    (``stateutils.normalize``)."""
    length = np.hypot(x, y)
    with np.errstate(invalid="ignore", divide="ignore"):
        ux, uy = x / length, y / length
    zero = length == 0
    return np.where(zero, 0.0, ux), np.where(zero, 0.0, uy), length


def _moussaid(pos: F64, vel: F64, p: F64) -> F64:
    """``SocialForce``: the sum over the others of Moussaid et al.'s (2009) repulsion."""
    dx = pos[:, :, None, 0] - pos[:, None, :, 0]  # [w, a, b] = r_a - r_b, as pysocialforce's each_diff
    dy = pos[:, :, None, 1] - pos[:, None, :, 1]
    ex, ey, dist = _unit(dx, dy)
    vx = -(vel[:, :, None, 0] - vel[:, None, :, 0])
    vy = -(vel[:, :, None, 1] - vel[:, None, :, 1])
    tx, ty, length = _unit(p[LAMBDA] * vx + ex, p[LAMBDA] * vy + ey)
    theta = np.arctan2(ty, tx) - np.arctan2(ey, ex)
    b = p[GAMMA] * length
    with np.errstate(invalid="ignore", divide="ignore"):
        fv = np.exp(-1.0 * dist / b - np.square(p[N_PRIME] * b * theta))
        fa = -np.sign(theta) * np.exp(-1.0 * dist / b - np.square(p[N] * b * theta))
    # An agent does not push itself, nor does a pair with no interaction vector (b = 0: the
    # same place and velocity), where pysocialforce divides 0 by 0.
    off = (b == 0) | np.eye(pos.shape[1], dtype=bool)
    fx = np.where(off, 0.0, fv * tx + fa * -ty)
    fy = np.where(off, 0.0, fv * ty + fa * tx)
    return np.stack([_total(fx), _total(fy)], axis=-1) * p[SOCIAL]


def _potential(rx: F64, ry: F64, sx: F64, sy: F64, step: F64, p: F64) -> F64:
    """Helbing and Molnar's V_ab = V0 exp(-b / sigma), b the semi-minor axis of the ellipse
    through ``r`` with foci 0 and ``s`` = ``step`` e_b (``PedPedPotential.value_r_ab``)."""
    inner = (np.hypot(rx, ry) + np.hypot(rx - sx, ry - sy)) ** 2 - step**2
    return p[V0] * np.exp(-(0.5 * np.sqrt(np.maximum(inner, 0.0))) / p[SIGMA])


def _helbing_molnar(pos: F64, vel: F64, goal_dir: F64, p: F64) -> F64:
    """``PedRepulsiveForce``: minus the finite-difference gradient of V_ab, weighted by the
    field of view of ``a``, summed over the others."""
    rx = pos[:, :, None, 0] - pos[:, None, :, 0]
    ry = pos[:, :, None, 1] - pos[:, None, :, 1]
    step = p[DT] * np.hypot(vel[..., 0], vel[..., 1])[:, None, :]  # delta_t * speed of b
    sx, sy = step * goal_dir[:, None, :, 0], step * goal_dir[:, None, :, 1]
    value = _potential(rx, ry, sx, sy, step, p)
    fx = -1.0 * ((_potential(rx + p[DELTA], ry, sx, sy, step, p) - value) / p[DELTA])
    fy = -1.0 * ((_potential(rx, ry + p[DELTA], sx, sy, step, p) - value) / p[DELTA])
    # FieldOfView(e_a, -f_ab): full weight where -f_ab is within phi of a's desired direction.
    seen = goal_dir[:, :, None, 0] * -fx + goal_dir[:, :, None, 1] * -fy > np.hypot(fx, fy) * p[COS_PHI]
    weight = np.where(seen, 1.0, p[FOV_FACTOR])
    weight[:, np.arange(pos.shape[1]), np.arange(pos.shape[1])] = 0.0
    return np.stack([_total(weight * fx), _total(weight * fy)], axis=-1) * p[REPULSION]


def _walls(pos: F64, points: F64, count: NDArray[np.int64], p: F64) -> F64:
    """``ObstacleForce``: exp(-(d - radius) / sigma) away from every wall point within
    ``threshold + radius`` of the agent's edge."""
    ux, uy, dist = _unit(pos[:, :, None, 0] - points[:, None, :, 0], pos[:, :, None, 1] - points[:, None, :, 1])
    gap = dist - p[RADIUS]
    near = (gap < p[WALL_THRESHOLD] + p[RADIUS]) & (np.arange(points.shape[1]) < count[:, None, None])
    scale = np.where(near, np.exp(-gap / p[WALL_SIGMA]), 0.0)
    return np.stack([_total(ux * scale), _total(uy * scale)], axis=-1) * p[WALL]


def social_force_array(
    pos: F64, vel: F64, goal: F64, speed: F64, max_speed: F64, points: F64, count: NDArray[np.int64],
    p: F64, model: int,
) -> None:
    """One step of every world, in place: ``pos``, ``vel`` ``(w, n, 2)`` (m, m/s); ``goal``
    ``(w, n, 2)`` (m); ``speed``, ``max_speed`` ``(w, n)`` (m/s); wall points ``(w, k, 2)``
    (m) of which the first ``count`` of each world are used; ``model`` 0 for Moussaid's
    social force, 1 for Helbing and Molnar's."""
    gx, gy, goal_dist = _unit(goal[..., 0] - pos[..., 0], goal[..., 1] - pos[..., 1])
    goal_dir = np.stack([gx, gy], axis=-1)
    # DesiredForce: relax to the desired velocity, or to a stop within goal_threshold.
    far = (goal_dist > p[GOAL_THRESHOLD])[..., None]
    force = np.where(far, goal_dir * speed[..., None] - vel, -1.0 * vel) / p[TAU]
    force = force + (_moussaid(pos, vel, p) if model == 0 else _helbing_molnar(pos, vel, goal_dir, p))
    if points.shape[1]:
        force = force + _walls(pos, points, count, p)
    # PedState.step: v + dt F capped at the max speed, zero near the goal, then x + dt v.
    new = vel + p[DT] * force
    new_speed = np.hypot(new[..., 0], new[..., 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        factor = np.where(new_speed == 0, 0.0, np.minimum(1.0, max_speed / new_speed))
    new = np.where((goal_dist < p[STOP])[..., None], 0.0, new * factor[..., None])
    pos += new * p[DT]
    vel[...] = new
