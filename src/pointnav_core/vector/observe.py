"""What the batched engines hand out each step: the ``low_dim`` observation and ``info``.

Both read a :class:`~pointnav_core.vector.state.WorldState`, one entry per world (or per
robot), and compute what the single env's observation terms and metrics compute, as arrays
(numpy or torch). The engines add the scan and the local map, which need their sensors.
"""

from __future__ import annotations

import math
from typing import Any

from pointnav_core.task.metrics import soft_spl_values, spl_values
from pointnav_core.vector.state import WorldState
from pointnav_core.vector.xp import copy

__all__ = ["low_dim", "step_info"]


def low_dim(xp: Any, st: WorldState, goal_in_polar: Any) -> tuple[Any, Any, Any]:
    """The flat ``low_dim`` observation, unclipped float64 ``(..., 8)``, and the headings'
    cosines and sines (for the scan).

    Parameters
    ----------
    xp : module
        ``numpy`` or ``torch``.
    st : WorldState
        The committed state.
    goal_in_polar : bool or bool array
        Whether the goal is given as (distance m, bearing rad) instead of (forward, left) m:
        a bool, or a ``(1, R)`` mask when robots' tasks differ.

    Returns
    -------
    obs, c, s : arrays
        The goal in the robot frame, the body-frame velocities (m/s), ``vz`` (m/s), two
        zeros and the yaw rate (rad/s); ``cos(yaw)`` and ``sin(yaw)``.
    """
    c, s = xp.cos(st.yaw), xp.sin(st.yaw)
    dx, dy = st.goal_x - st.x, st.goal_y - st.y
    lx, ly = c * dx + s * dy, c * dy - s * dx
    if goal_in_polar is not False:
        rho = xp.sqrt(lx * lx + ly * ly)
        phi = xp.where(rho > 0.0, xp.arctan2(ly, lx), 0.0)
        phi = xp.where(phi == -math.pi, math.pi, phi)  # the single env's bearing in (-pi, pi]
        if goal_in_polar is True:
            lx, ly = rho, phi
        else:
            lx, ly = xp.where(goal_in_polar, rho, lx), xp.where(goal_in_polar, phi, ly)
    vx, vy = st.vx, st.vy
    zero = xp.zeros_like(vx)
    obs = xp.stack([lx, ly, c * vx + s * vy, c * vy - s * vx, st.vz, zero, zero, st.yaw_rate], -1)
    return obs, c, s


def step_info(xp: Any, st: WorldState, success: Any, r_pot: Any, r_col: Any, r_goal: Any, contact: Any,
              resetting: Any) -> dict[str, Any]:
    """The one-robot engine's ``info``: the single env's metrics (SPL, SoftSPL, lengths in m)
    and reward terms, each a fresh array (the state's are written in place at the next
    autoreset)."""
    d0, length, d_t = st.start_distance, st.path_length, st.goal_distance
    spl = spl_values(success, d0, length, xp.where)  # the single env's definition
    soft = soft_spl_values(d_t, d0, length, xp.where)
    info = {
        "success": success, "spl": spl, "soft_spl": soft, "path_length": length, "geodesic_dist": d0,
        "distance_to_goal": d_t, "collisions": st.collisions, "episode_length": st.steps,
        "in_contact": contact, "reward_potential": r_pot, "reward_collision": r_col,
        "reward_pointgoal": r_goal, "autoreset": resetting,
    }
    return {key: copy(xp, value) for key, value in info.items()}
