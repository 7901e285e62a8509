"""The one-robot batched engine's control step: every world's drive, contacts and falls.

Worlds whose robot stands with clearance beyond the step (the floor's fast table) move by
the exact arc; the others take the backend's sub-steps (:func:`~.drive.substep_drive`),
each chord resolved for contacts by the compiled kernel where numba is present, else by
:func:`~.contacts.advance`. A falling robot ignores its command and drops
(:func:`~.falls.apply_falls`). Nothing is committed: the engine's accounting does that.
"""

from __future__ import annotations

from typing import Any

from pointnav_core.vector import contacts_jit
from pointnav_core.vector.contacts import advance
from pointnav_core.vector.drive import (
    arc,
    body_command,
    sub_steps,
    substep_drive,
    travel,
)
from pointnav_core.vector.falls import apply_falls
from pointnav_core.vector.state import Motion
from pointnav_core.vector.xp import copy

__all__ = ["drive_worlds"]


def drive_worlds(engine: Any, act: Any, state: Motion) -> tuple[Motion, Any]:
    """One control step of every world of ``engine`` from ``state``, not committed.

    Parameters
    ----------
    engine : VectorPointNavEnv
        The one-robot engine: its ``robot``, ``dt`` (s), ``holonomic``, ``world_scene``,
        ``floors`` and ``max_travel`` (m) are read.
    act : array, shape (num_envs, action_dim)
        Commands in ``[-1, 1]`` units.
    state : Motion
        The state the step starts from (the committed :class:`~.state.WorldState`, or a
        discrete action's earlier sub-step).

    Returns
    -------
    moved : Motion
        The new pose (m, rad), height (m), velocities (m/s, rad/s) and fall speed (m/s).
    contact : array of bool, shape (num_envs,)
        The worlds whose robot touched a wall.
    """
    a, xp = engine.arrays, engine.arrays.xp
    spec, dt = engine.robot, engine.dt
    vx, vy, w = body_command(xp, act, spec.max_linear_velocity, spec.max_angular_velocity, engine.holonomic)
    x0, y0, yaw0 = state.x, state.y, state.yaw
    dx, dy = arc(xp, yaw0, vx, vy, w, dt)  # the exact arc over the step (drive_arc)
    length = travel(xp, vx, vy, dt)
    scene = engine.world_scene
    row, col, inside = engine.floors.cells(scene, x0, y0)
    budget = engine.floors.fast[engine.floors.flat_index(scene, row, col, inside)]
    standing = ~(state.fall_speed > 0.0)
    fast = inside & (budget > length)
    x, y, yaw = x0 + dx, y0 + dy, yaw0 + w * dt
    vel_x, vel_y, vel_w = dx / dt, dy / dt, w
    contact = xp.zeros_like(x) > 1.0
    began = contact
    slow = a.nonzero(~fast & standing)
    if slow.shape[0]:
        sc = scene[slow]
        resolver = contacts_jit.advance_one if contacts_jit.available(engine.floors) else advance

        def move(px: Any, py: Any, mx: Any, my: Any, part: Any) -> tuple[Any, Any, Any]:
            # The worlds of ``part`` by their chords; a later sub-step has fewer of them.
            if bool(part.all()):
                return resolver(engine.floors, sc, px, py, mx, my, spec.radius, engine.max_travel)
            idx = a.nonzero(part)
            ix, iy, ic = resolver(engine.floors, sc[idx], px[idx], py[idx], mx[idx], my[idx], spec.radius, engine.max_travel)
            nx, ny, c = px + 0.0, py + 0.0, xp.zeros_like(part)
            nx[idx], ny[idx], c[idx] = ix, iy, ic
            return nx, ny, c

        n_sub = sub_steps(xp, length[slow], w[slow], dt, engine.floors.res[sc])
        sx, sy, syaw, fall, c = substep_drive(
            xp, (x0[slow], y0[slow], yaw0[slow]), (vx[slow], vy[slow], w[slow]), n_sub, dt, move,
            lambda px, py: engine.floors.is_void(sc, px, py), (dx[slow], dy[slow]),
        )
        x[slow], y[slow], yaw[slow] = sx, sy, syaw
        vel_x[slow] = (sx - x0[slow]) / dt
        vel_y[slow] = (sy - y0[slow]) / dt
        vel_w = xp.where(fast, vel_w, (yaw - yaw0) / dt)
        began = copy(xp, began)
        began[slow] = fall
        contact[slow] = c
    moved = apply_falls(xp, state, {"x": x, "y": y, "yaw": yaw, "vx": vel_x, "vy": vel_y, "yaw_rate": vel_w}, began, dt)
    return moved, contact
