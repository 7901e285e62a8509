"""The compiled path of an ORCA crowd's control step, :meth:`pointnav_core.crowds.Crowd.step`
(imports numba).

Imported only through ``utils.compiled.kernel``, so the package imports without numba. One
call does what the crowd's numpy path does in a dozen array operations and three calls of
other compiled functions, each with its Python set-up: passing waypoints (the wall test of
``floor._collision_kernel``), the preferred velocities, ORCA (``crowds._orca_kernel``, in
RVO2's float32), the wall rule (with its landing on the next waypoint), the new positions,
the arrivals and the robots' contacts.
Every statement is the numpy path's in the same order and precision, so the two give the
same floats (``tests/pairs_crowds.py``); the headings (``atan2``) are left to numpy, whose
``arctan2`` and the C library's can differ in the last bit.
"""

from __future__ import annotations

import numba
import numpy as np

from pointnav_core.crowds._orca_kernel import orca_worlds
from pointnav_core.floor._collision_kernel import segment_clear as _clear

__all__ = ["orca_crowd_step", "orca_crowd_worlds"]

_jit = numba.njit(cache=True, nogil=True, error_model="numpy")


@_jit
def _preferred(pos, speed, paths, nxt, last, dt, walls, pref):  # pragma: no cover
    # Crowd.preferred, one pedestrian at a time: its rounds of passing waypoints stop at the
    # first that is not near or not in plain sight (the numpy path's later rounds test the
    # same segment again and pass nothing), and norms are sqrt(x * x + y * y) as numpy's.
    for i in range(pos.shape[0]):
        px, py = pos[i, 0], pos[i, 1]
        reach = max(speed[i] * dt, 0.05)
        for _ in range(4):
            dx = paths[i, nxt[i], 0] - px
            dy = paths[i, nxt[i], 1] - py
            if not (np.sqrt(dx * dx + dy * dy) < reach and nxt[i] < last[i]):
                break
            if not _clear(px, py, paths[i, nxt[i] + 1, 0], paths[i, nxt[i] + 1, 1], walls):
                break
            nxt[i] += 1
        dx = paths[i, nxt[i], 0] - px
        dy = paths[i, nxt[i], 1] - py
        dist = np.sqrt(dx * dx + dy * dy)
        s = speed[i]
        if nxt[i] == last[i]:
            s = min(s, dist / dt)
        if dist > 0:
            pref[i, 0] = dx * (s / dist)
            pref[i, 1] = dy * (s / dist)
        else:
            pref[i, 0] = 0.0
            pref[i, 1] = 0.0


@_jit
def _landing(px, py, wx, wy, speed, dt):  # pragma: no cover
    # Crowd.landing for one pedestrian: toward (wx, wy), no faster than reaches it in dt.
    dx, dy = wx - px, wy - py
    dist = np.sqrt(dx * dx + dy * dy)
    if not dist > 0:
        return 0.0, 0.0
    s = min(speed, dist / dt)
    return dx * (s / dist), dy * (s / dist)


@_jit
def _orca_velocities(pos, vel, pref, radius, speed, robots, robot_vel, m, dt, neighbor_dist, max_neighbors,
                     time_horizon):  # pragma: no cover
    """ORCA's new velocities, ``(1, P + m, 2)`` float32, among the pedestrians and the first
    ``m`` robots."""
    n = pos.shape[0]
    # ORCA among the pedestrians and the seen robots in float32, as Crowd._orca hands them to
    # orca_step: the robots keep their velocities and their speeds are their limits.
    a = n + m
    pos32 = np.empty((1, a, 2), np.float32)
    vel32 = np.empty((1, a, 2), np.float32)
    pref32 = np.empty((1, a, 2), np.float32)
    radius32 = np.empty((1, a), np.float32)
    top32 = np.empty((1, a), np.float32)
    for i in range(n):
        pos32[0, i, 0], pos32[0, i, 1] = pos[i, 0], pos[i, 1]
        vel32[0, i, 0], vel32[0, i, 1] = vel[i, 0], vel[i, 1]
        pref32[0, i, 0], pref32[0, i, 1] = pref[i, 0], pref[i, 1]
        radius32[0, i], top32[0, i] = radius[i], speed[i]
    for j in range(m):
        pos32[0, n + j, 0], pos32[0, n + j, 1] = robots[j, 0], robots[j, 1]
        vel32[0, n + j, 0], vel32[0, n + j, 1] = robot_vel[j, 0], robot_vel[j, 1]
        pref32[0, n + j, 0], pref32[0, n + j, 1] = robot_vel[j, 0], robot_vel[j, 1]
        radius32[0, n + j], top32[0, n + j] = robots[j, 2], np.hypot(robot_vel[j, 0], robot_vel[j, 1])
    params = np.empty(3, np.float32)  # orca_step's: (dt, neighbour distance squared, 1 / horizon)
    params[0] = dt
    reach32 = np.float32(neighbor_dist)
    params[1] = reach32 * reach32
    params[2] = np.float32(1.0) / np.float32(time_horizon)
    orca_worlds(pos32, vel32, pref32, radius32, top32, params, max_neighbors)
    return vel32


@_jit
def _contacts(robots, new_pos, radius, contacts):  # pragma: no cover
    """Fill ``contacts`` with whether each robot's disc overlaps a pedestrian's at ``new_pos``."""
    n = new_pos.shape[0]
    for j in range(robots.shape[0]):
        touch = False
        for i in range(n):
            d = np.hypot(robots[j, 0] - new_pos[i, 0], robots[j, 1] - new_pos[i, 1])
            if d < robots[j, 2] + radius[i]:
                touch = True
                break
        contacts[j] = touch


@_jit
def orca_crowd_step(pos, vel, radius, speed, goals, paths, nxt, last, robots, robot_vel, seen, dt, neighbor_dist,
                    max_neighbors, time_horizon, goal_reached, walls, new_pos, new_vel, flags, contacts):  # pragma: no cover
    """One control step of an ORCA crowd (``Crowd.step`` and ``Crowd.contacts``), without the
    headings and the new plans, which the caller does from ``flags``.

    Parameters
    ----------
    pos, vel : (P, 2) float64
        The pedestrians' centres (m) and velocities (m/s) before the step (read only).
    radius, speed : (P,) float64
        Radii (m) and preferred speeds (m/s).
    goals : (P, 2) float64
        Goals (m).
    paths : (P, L, 2) float64; nxt, last : (P,) int64
        The padded paths, each one's next waypoint (advanced here, in place) and last point.
    robots : (M, 3) float64; robot_vel : (M, 2) float64
        The robots' discs ``(x, y, radius)`` (m) and planar velocities (m/s).
    seen : int
        How many of the robots, from the first, ORCA avoids (``M`` or 0).
    dt, neighbor_dist, time_horizon : float
        Step (s), neighbour distance (m) and time horizon (s) of ORCA.
    max_neighbors : int
    goal_reached : float
        Distance (m) to the goal under which a pedestrian has arrived.
    walls : tuple
        ``floor._collision_kernel.segment_hits``' arguments after the segment, for a disc of
        the crowd's largest radius.
    new_pos, new_vel : (P, 2) float64
        Filled with the positions (m) and velocities (m/s) after the step.
    flags : (P,) int8
        Filled with bit 1 blocked (stood still for the step), bit 2 arrived, bit 4 moving
        (speed above 1e-9 m/s).
    contacts : (M,) bool
        Filled with whether each robot's disc overlaps a pedestrian's after the step.

    Returns
    -------
    int
        How many pedestrians need a new plan (blocked or arrived).
    """
    n, m = pos.shape[0], seen
    replans = 0
    pref = np.empty((n, 2))
    _preferred(pos, speed, paths, nxt, last, dt, walls, pref)
    vel32 = _orca_velocities(pos, vel, pref, radius, speed, robots, robot_vel, m, dt, neighbor_dist,
                             max_neighbors, time_horizon)
    # The wall rule: ORCA's velocity, else the preferred one, else onto the next waypoint
    # and no farther (Crowd.landing), else stand still.
    for i in range(n):
        px, py = pos[i, 0], pos[i, 1]
        vx, vy = np.float64(vel32[0, i, 0]), np.float64(vel32[0, i, 1])
        bit = 0
        qx, qy = px + vx * dt, py + vy * dt
        if not _clear(qx, qy, qx, qy, walls):
            vx, vy = pref[i, 0], pref[i, 1]
            qx, qy = px + vx * dt, py + vy * dt
            if not _clear(qx, qy, qx, qy, walls):
                vx, vy = _landing(px, py, paths[i, nxt[i], 0], paths[i, nxt[i], 1], speed[i], dt)
                qx, qy = px + vx * dt, py + vy * dt
                if not _clear(qx, qy, qx, qy, walls):
                    vx, vy, bit = 0.0, 0.0, 1
        new_vel[i, 0], new_vel[i, 1] = vx, vy
        if bit:
            new_pos[i, 0], new_pos[i, 1] = px, py
        else:
            new_pos[i, 0], new_pos[i, 1] = px + vx * dt, py + vy * dt
        if np.hypot(vx, vy) > 1e-9:
            bit |= 4
        gx = goals[i, 0] - new_pos[i, 0]
        gy = goals[i, 1] - new_pos[i, 1]
        if np.sqrt(gx * gx + gy * gy) < goal_reached:
            bit |= 2
        flags[i] = bit
        replans += bit & 3 != 0
    _contacts(robots, new_pos, radius, contacts)
    return replans


@_jit
def orca_crowd_worlds(worlds, count, pos, vel, radius, speed, goals, paths, nxt, last, robots, robot_vel, seen, dt,
                      neighbor_dist, max_neighbors, time_horizon, goal_reached, walls, new_pos, new_vel, flags,
                      contacts):  # pragma: no cover
    """:func:`orca_crowd_step` for each world of ``worlds`` (all on one floor, whose walls are
    ``walls``): every array has a leading world axis, world ``w`` has ``count[w]``
    pedestrians (the first rows) and ``seen[w]`` robots that ORCA avoids. One definition:
    world by world, the single env's step."""
    for j in range(worlds.shape[0]):
        w = worlds[j]
        k = count[w]
        orca_crowd_step(pos[w, :k], vel[w, :k], radius[w, :k], speed[w, :k], goals[w, :k], paths[w, :k], nxt[w, :k],
                        last[w, :k], robots[w], robot_vel[w], seen[w], dt, neighbor_dist, max_neighbors,
                        time_horizon, goal_reached, walls, new_pos[w, :k], new_vel[w, :k], flags[w, :k], contacts[w])
