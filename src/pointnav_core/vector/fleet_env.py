"""Several robots per world in the batched engine: ``VectorPointNavEnv(n, n_robots=R)``.

Every world is a :class:`~pointnav_core.envs.multi_pointnav.MultiPointNavEnv` with ``R`` robots on
the kinematic backend (``finished="park"`` by default, or ``"remove"``), stepped as
``(num_envs, n_robots)`` arrays: robots that could meet a wall or each other are resolved
together by :func:`~pointnav_core.vector.robots.advance_robots` on one clock per world
(by the one-robot :func:`~pointnav_core.vector.contacts.advance` where a world has only
one such robot), the others move by their arc (the backend's fast path). Each robot's task accounting is
the one-robot engine's, masked by the robots still active (PettingZoo's ``agents``). With
``sensors={"scan": {...}}`` every robot's scan sees the floor and the discs of the other
robots of its world that the multi-robot env's scan sees when it observes the step: those
present before the step's finished robots leave (parked, removed or fallen alike), all of
them after a reset; with ``sensors={"local_map": {...}}`` every robot's map draws the discs
of the same robots as code 3. Robots may differ in radius (a ``robot`` list): each takes
the fast path by the clearance table of its radius, meets walls at its radius and another
robot at the sum of their radii, and is a disc of its radius in the scans and maps.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

import gymnasium as gym
import numpy as np

from pointnav_core import scenes
from pointnav_core.envs.config import EnvConfig, takes_config, vector_fleet_arguments
from pointnav_core.envs.fleet import check_finished
from pointnav_core.errors import ArgumentError, TaskStateError
from pointnav_core.utils import validation
from pointnav_core.vector import contacts_jit
from pointnav_core.vector.accounting import read_task, task_step
from pointnav_core.vector.arguments import as_scene_list, check_real_actions
from pointnav_core.vector.contacts import advance
from pointnav_core.vector.contacts_jit import advance_compiled
from pointnav_core.vector.crowd import (
    VectorCrowd,
    check_vector_pedestrians,
    crowd_map_high,
)
from pointnav_core.vector.discrete import DiscretePlan
from pointnav_core.vector.drive import (
    arc,
    body_command,
    sub_steps,
    substep_drive,
    travel,
)
from pointnav_core.vector.env import VectorPointNavEnv
from pointnav_core.vector.falls import apply_falls
from pointnav_core.vector.fleet_pool import FleetPool, check_fixed_episode
from pointnav_core.vector.floors import FloorTables
from pointnav_core.vector.per_robot import (
    envelope,
    read_tasks,
    robot_specs,
    task_arguments,
)
from pointnav_core.vector.pool_build import pool_options
from pointnav_core.vector.robots import advance_robots, robot_walls
from pointnav_core.vector.scan import requested_scan
from pointnav_core.vector.state import Motion
from pointnav_core.vector.xp import amax, as_dtype, copy, make_arrays

__all__ = ["VectorFleetEnv"]


class VectorFleetEnv(VectorPointNavEnv):
    """``num_envs`` worlds of ``n_robots`` robots each, stepped as arrays.

    Built by ``VectorPointNavEnv(num_envs, n_robots=R, ...)`` with ``R > 1``; see
    :class:`~pointnav_core.vector.VectorPointNavEnv` ("Several robots per world") for the
    interface. Parameters are those of ``VectorPointNavEnv`` plus:

    Parameters
    ----------
    max_cycles : int
        Steps after which every robot still active is truncated, >= 1 (the multi-robot
        env's argument; default 500).
    finished : {"park", "remove"}
        A robot whose episode ended stays as an obstacle, or leaves the world.
    action_space : {"continuous", "discrete"}
        With ``"discrete"``, every robot acts with an integer (``discrete_actions`` as for
        the multi-robot env), run as the multi-robot env runs them: the robots of a world
        together, for as many control steps as its longest action
        (:mod:`pointnav_core.vector.discrete`).
    discrete_actions : dict, optional
        ``forward_step``, ``turn_angle``, ``stop``, as the multi-robot env; each robot's
        actions are planned with its own speed limits (a slower robot holds an action for
        more control steps).
    starts_per_goal : int
        Sets of starts per pool episode, >= 1: the extra sets share its goals and their
        settled fields (:class:`~pointnav_core.vector.fleet_pool.FleetPool`).
    workers, progress
        As for :class:`~pointnav_core.vector.env.VectorPointNavEnv`: a pool's scenes built
        in worker processes (the same pool), with a progress bar over them.
    """

    _pool_class = FleetPool

    @takes_config(vector_fleet_arguments, extra=("max_episode_steps",))
    def __init__(
        self,
        num_envs: int = 1,
        n_robots: int = 2,
        scene: scenes.Scene | Sequence[scenes.Scene] | None = None,
        robot: Any = None,
        task: Mapping[str, Any] | None = None,
        sensors: Mapping[str, Any] | None = None,
        device: str = "numpy",
        seed: int | None = None,
        pool_size: int = 8,
        action_frequency: float = 10.0,
        max_episode_steps: int | None = None,
        max_cycles: int = 500,
        finished: str = "park",
        action_space: str = "continuous",
        discrete_actions: Mapping[str, Any] | None = None,
        starts_per_goal: int = 1,
        config: EnvConfig | None = None,
        workers: int | None = None,
        progress: bool | None = None,
        pedestrians: Mapping[str, Any] | None = None,
    ) -> None:
        from pointnav_core.crowds import make_pedestrians
        from pointnav_core.envs.multi_pointnav import parallel_env

        self.config = config  # applied by takes_config; max_cycles defaults to its max_steps

        self.num_envs = validation.integer("num_envs", num_envs, minimum=1)
        self.n_robots = validation.integer("n_robots", n_robots, minimum=2)
        self.max_cycles = validation.integer("max_cycles", max_cycles, minimum=1)
        self.finished = check_finished(finished)
        scan_term = requested_scan(sensors)
        crowd = make_pedestrians(pedestrians)
        check_vector_pedestrians(crowd, device)
        if max_episode_steps is not None:
            max_episode_steps = validation.integer("max_episode_steps", max_episode_steps, minimum=1)
        task = task_arguments(task, self.n_robots, max_episode_steps)  # one dict, or one per robot
        self.pool_size = validation.integer("pool_size", pool_size, minimum=1)
        self.starts_per_goal = validation.integer("starts_per_goal", starts_per_goal, minimum=1)
        self.arrays = a = make_arrays(device)
        self.device = device
        self.scenes = scene_list = as_scene_list(scene)
        self._pool_workers, self._pool_progress = pool_options(workers, progress, len(scene_list))
        #: One spec per robot; ``robot`` is their envelope (largest radius, highest speeds).
        self.robots = robot_specs(robot, self.n_robots)
        self.robot = spec = envelope(self.robots)
        # The multi-robot env of each scene samples its episodes and is the semantics.
        self._samplers = [
            parallel_env(scene=s, n_robots=self.n_robots, robot=list(self.robots),
                         task=[dict(t) for t in task] if isinstance(task, list) else dict(task), backend="kinematic",
                         max_cycles=self.max_cycles, finished=finished, action_frequency=action_frequency,
                         sensors=sensors, action_space=action_space, discrete_actions=discrete_actions)
            for s in scene_list
        ]
        first = self._samplers[0]
        read_task(self, first.tasks[0], first.action_frequency)  # rate check on the envelope
        read_tasks(self, first.tasks, self.robots, a)  # then the per-robot settings, (1, R)
        t = self.task
        acts = first.discrete_actions
        # Each robot's own commands and control steps (its speed limits), as the multi-robot env plans them.
        self._discrete = None if acts is None else DiscretePlan(acts, list(self.robots), self.action_frequency, a)
        shared = [env.backend.floor_geometry(t.floor) for env in self._samplers]  # built by their backends
        self.floors = FloorTables(scene_list, t.floor, spec.radius, a, shared)
        # Each robot's clearance table, of its own radius: (R, all cells).
        self._fast = a.xp.stack([self.floors.fast_for(s.radius) for s in self.robots])
        self._make_spaces(first, crowd, sensors)
        self._rng = np.random.default_rng(seed)
        n, r = self.num_envs, self.n_robots
        self.world_scene = a.asarray(np.arange(n) % len(scene_list), a.i64)
        self._robot_scene = a.asarray(np.repeat(np.arange(n) % len(scene_list), r).reshape(n, r), a.i64)
        self._robot_ids = a.asarray(np.arange(r), a.i64).reshape(1, r)
        self.pool: FleetPool | None = None  # type: ignore[assignment]
        self._allocate((n, r), scan_term, sensors)
        self._active = a.zeros((n, r), a.boolean)
        self._present = a.zeros((n, r), a.boolean)
        self._seen = self._present  # the robots the scans see at the next observation
        self._cycles = a.zeros(n, a.i64)
        self.crowd = VectorCrowd.for_engine(crowd, self, [s.radius for s in self.robots], self._pool_progress)

    def _make_spaces(self, first: Any, crowd: Any, sensors: Any) -> None:
        """The observation bounds of every (scene, robot) and the batched spaces, from the
        multi-robot envs (``first`` gives the action space), with a ``crowd``'s code in the
        local map."""
        a = self.arrays
        bounds = [[t.observation_bounds for t in env.tasks] for env in self._samplers]  # (scene, robot)
        lows, highs = (np.array([[b[k] for b in row] for row in bounds], np.float64) for k in (0, 1))
        self._low, self._high = a.asarray(lows.astype(np.float32)), a.asarray(highs.astype(np.float32))  # as the env's
        low, high = lows.min(axis=(0, 1)).astype(np.float32), highs.max(axis=(0, 1)).astype(np.float32)
        if crowd is not None:  # the samplers have none: their local map's top code is a robot's
            high = crowd_map_high(high, sensors)
        self.single_observation_space = gym.spaces.Box(low, high, dtype=np.float32)
        self.single_action_space = first.action_space(first.possible_agents[0])
        batch = gym.vector.utils.batch_space
        self.observation_space = batch(batch(self.single_observation_space, self.n_robots), self.num_envs)
        if isinstance(self.single_action_space, gym.spaces.Discrete):  # batched twice it would be an int Box
            nvec = np.full((self.num_envs, self.n_robots), int(self.single_action_space.n))
            self.action_space = gym.spaces.MultiDiscrete(nvec)
        else:
            self.action_space = batch(batch(self.single_action_space, self.n_robots), self.num_envs)

    # ------------------------------------------------------------------ pools
    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        """Reset every world. ``options={"episodes": [[(start_xy, yaw, goal_xy), ...], ...]}``
        (per world, one tuple per robot) fixes each world's episode, at this reset and every
        autoreset, until a reset without it; a new ``seed`` redraws the pools."""
        self._reset_pools(seed, options)
        a = self.arrays
        every = a.full(self.num_envs, True, a.boolean)
        with np.errstate(invalid="ignore", divide="ignore"):
            self._reset_worlds(every)
            self._seen = self._present
            self._started = True
            zero, no = a.zeros((self.num_envs, self.n_robots)), a.zeros((self.num_envs, self.n_robots), a.boolean)
            shown = copy(a.xp, self._active)
            return self._observe(shown), self._info(no, zero, zero, zero, no, shown, no)

    def _fixed_episode(self, i: int, episode: Any, s: int) -> Any:
        return check_fixed_episode(self._samplers[s], episode, f"options['episodes'][{i}]"), s

    def _reset_worlds(self, mask: Any) -> None:
        super()._reset_worlds(mask)  # the one-robot engine's, on (num_envs, n_robots) state
        idx = self.arrays.nonzero(mask)
        self._cycles[idx] = 0
        self._active[idx] = True
        self._present[idx] = True

    def check_actions(self, actions: Any) -> Any:
        """``actions`` as a float64 array ``(num_envs, n_robots, action_dim)`` (2 for a
        differential drive, 3 for a holonomic one), or with discrete actions an int64 array
        ``(num_envs, n_robots)``; ValueError naming ``actions`` if bad.

        Every entry must be valid (finite; with discrete actions an integer in range), also
        those of inactive robots (which are ignored).
        """
        if self._discrete is not None:
            return self._discrete.check(actions, self.num_envs, self.n_robots)
        shape = tuple(getattr(actions, "shape", np.shape(actions)))
        want = (self.num_envs, self.n_robots, self.robot.action_dim)
        if shape != want:
            raise ArgumentError(f"actions must have shape {want} for a {self.robot.drive} drive, got {shape}")
        check_real_actions(actions)
        arr = self.arrays.asarray(actions)
        if not bool(self.arrays.xp.isfinite(arr).all()):
            raise ArgumentError("actions must be finite (no NaN or infinity)")
        return arr

    def _step(self, actions: Any) -> tuple[Any, Any, Any, Any, dict[str, Any]]:
        if not self._started:
            raise TaskStateError("call reset() before step()")
        act = self.check_actions(actions)
        crowd = self.crowd  # it walks beside the robots present, each control step
        if crowd is not None:
            crowd.begin(self._present)
        if self._discrete is not None:
            moved, contact, stopped = self._discrete.run(self, act, acting=self._active)
        else:
            # Robots that are not agents any more get no command (the backend's _NO_COMMAND).
            moved, contact = self.drive(self.arrays.xp.where(self._active[..., None], act, 0.0 * act), self.state)
            stopped = None
            if crowd is not None:
                crowd.step(moved, self.dt)
        return self._account(moved, contact, stopped, None if crowd is None else crowd.finish(self._active))

    def drive(self, act: Any, state: Motion) -> tuple[Motion, Any]:
        """One control step of every world from ``state`` under commands ``act``
        ``(num_envs, n_robots, action_dim)`` in ``[-1, 1]`` units, not committed: the new pose,
        height, velocities and fall speed, and the contacts. A falling robot
        present in the world drops (:func:`~pointnav_core.vector.falls.apply_falls`); it
        neither drives nor blocks. A robot out of the world stays as it is."""
        a, xp = self.arrays, self.arrays.xp
        dt, radius = self.dt, self.radius  # (1, R): each robot's radius
        falling = state.fall_speed > 0.0
        present = self._present & ~falling
        vmax, wmax = self.vmax, self.wmax  # (1, R): each robot's speed limits
        vx, vy, w = body_command(xp, act, vmax, wmax, self.holonomic)
        zero = xp.zeros_like(vx)
        x0, y0, yaw0 = state.x, state.y, state.yaw
        dx, dy = arc(xp, yaw0, vx, vy, w, dt)
        length = travel(xp, vx, vy, dt)
        # The backend's fast path: clearance beyond the step and no other free robot within reach.
        scene = self._robot_scene
        row, col, inside = self.floors.cells(scene, x0, y0)
        budget = self._fast[self._robot_ids, self.floors.flat_index(scene, row, col, inside)]
        reach = radius + length
        # The backend's sum, in its order: robot i's reach, then robot j's radius and travel.
        gap = reach[:, :, None] + radius[:, None, :] + length[:, None, :]
        gap2 = (x0[:, :, None] - x0[:, None, :]) ** 2 + (y0[:, :, None] - y0[:, None, :]) ** 2
        ids = self._robot_ids
        others = (ids.reshape(1, -1, 1) != ids.reshape(1, 1, -1)) & present[:, None, :] & (gap2 <= gap * gap)
        fast = present & inside & (budget > length) & ~others.any(-1)
        slow = present & ~fast
        x, y, yaw = x0 + xp.where(fast, dx, zero), y0 + xp.where(fast, dy, zero), yaw0 + w * dt
        contact = zero > 1.0
        began = contact
        if a.any(slow):
            # Every slow robot of a world takes the world's sub-steps (the backend's _slow_step).
            n_sub = sub_steps(xp, length, w, dt, self.floors.res[scene])
            n_sub = amax(xp, xp.where(slow, n_sub, zero), -1)
            n_sub = xp.where(slow, n_sub[:, None], zero)
            sx, sy, syaw, fall, contact = substep_drive(
                xp, (x0, y0, yaw0), (vx, vy, w), n_sub, dt, self._move_slow,
                lambda px, py: self.floors.is_void(scene, px, py), (dx, dy),
            )
            x, y, yaw = xp.where(slow, sx, x), xp.where(slow, sy, y), xp.where(slow, syaw, yaw)
            began = slow & fall
        vel_x = xp.where(fast, dx / dt, (x - x0) / dt)
        vel_y = xp.where(fast, dy / dt, (y - y0) / dt)
        vel_w = xp.where(fast, w, (yaw - yaw0) / dt)
        vel_x, vel_y, vel_w = (xp.where(present, v, zero) for v in (vel_x, vel_y, vel_w))
        moved = apply_falls(xp, state, {"x": x, "y": y, "yaw": yaw, "vx": vel_x, "vy": vel_y, "yaw_rate": vel_w}, began, dt)
        # A robot out of the world (removed, or fallen and gone) is not moved by the backend.
        out = ~self._present
        moved = dataclasses.replace(moved, z=xp.where(out, state.z, moved.z),
                                    fall_speed=xp.where(out, state.fall_speed, moved.fall_speed),
                                    vz=xp.where(out, zero, moved.vz))
        return moved, contact & ~falling

    def _account(self, moved: Motion, contact: Any, stopped: Any,
                 touched: Any = None) -> tuple[Any, Any, Any, Any, dict[str, Any]]:
        """Each active robot's task step (``PointNavigationTask.step``, masked by the robots
        still acting) over the moves from the committed state, then the commit and the
        next-step autoresets. ``stopped``: the robots that called STOP (None without STOP);
        ``touched``: those that touched a pedestrian."""
        a, xp, st = self.arrays, self.arrays.xp, self.state
        acting, present = self._active, self._present
        zero = xp.zeros_like(st.x)
        t = task_step(self, moved, contact, stopped, acting, touched)  # each acting robot's task step
        cycles = self._cycles + 1
        reward, terminated, success, fell = t.reward, t.terminated, t.success, t.fell
        truncated = t.truncated | (acting & (cycles >= self.max_cycles)[:, None])
        r_pot, r_col, r_goal, r_custom = t.r_pot, t.r_col, t.r_goal, t.r_custom  # r_custom: the slack term's
        ended = terminated | truncated
        active = acting & ~ended
        # A robot that fell leaves its floor; with "remove" every finished robot leaves.
        gone = (ended & fell) if self.finished == "park" else ended
        self.state = st.moved(moved, path_length=t.path, goal_distance=t.dist, potential=xp.where(acting, t.pot, st.potential),
                              steps=t.steps, collisions=t.collisions)
        self._cycles = cycles
        self._active, self._present = active, present & ~gone
        # The multi-robot env observes every robot before its finished robots leave the world.
        self._seen = present
        shown = acting
        resetting = copy(xp, self._needs_reset)
        if a.any(resetting):
            # Next-step autoreset: every robot of a world with no agent left starts again.
            self._reset_worlds(resetting)
            keep = ~resetting[:, None]
            reward, terminated, truncated, success, contact = (
                v & keep if v.dtype == a.boolean else xp.where(keep, v, zero)
                for v in (reward, terminated, truncated, success, contact)
            )
            r_pot, r_col, r_goal = (xp.where(keep, r, zero) for r in (r_pot, r_col, r_goal))
            r_custom = {name: xp.where(keep, r, zero) for name, r in r_custom.items()}
            shown = xp.where(keep, acting, self._active)
            self._seen = xp.where(keep, present, self._present)
        self._needs_reset = ~self._active.any(-1)
        info = self._info(success, r_pot, r_col, r_goal, contact, shown, resetting[:, None] & shown)
        for name, r in r_custom.items():
            info[f"reward_{name}"] = xp.where(shown, r, zero)
        return self._observe(shown), reward, terminated, truncated, info


    def _move_slow(self, x0: Any, y0: Any, dx: Any, dy: Any, slow: Any) -> tuple[Any, Any, Any]:
        """The ``slow`` robots moved together by their chords ``(dx, dy)`` (m) with contacts,
        the others where they are: ``x``, ``y`` and the contact flags, ``(num_envs, n_robots)``."""
        a = self.arrays
        if contacts_jit.available(self.floors):  # every world in one compiled loop
            sx, sy, c = advance_compiled(self.floors, self._robot_scene, x0, y0, dx, dy, slow, self.radius,
                                         self.max_travel)
            return a.asarray(sx), a.asarray(sy), a.asarray(c, a.boolean)
        x, y, contact = x0 + 0.0, y0 + 0.0, a.xp.zeros_like(slow)
        self._advance_slow(x0, y0, dx, dy, slow, x, y, contact)
        return x, y, contact

    def _advance_slow(self, x0: Any, y0: Any, dx: Any, dy: Any, slow: Any, x: Any, y: Any, contact: Any) -> None:
        """The array path of the slow robots' contacts: writes their ends into ``x``, ``y``
        and their flags into ``contact`` (in place)."""
        a, xp, scene = self.arrays, self.arrays.xp, self._robot_scene
        radius = xp.zeros_like(x0) + self.radius  # (W, R)
        n_slow = slow.sum(-1)
        # A world with one slow robot is the one-robot resolver's case (the backend's
        # advance with a single robot): cheaper, and most busy worlds are such.
        alone = a.nonzero((slow & (n_slow == 1)[:, None]).reshape(-1))
        if alone.shape[0]:
            flat = [v.reshape(-1)[alone] for v in (scene, x0, y0, dx, dy, radius)]
            nx, ny, c = advance(self.floors, *flat, self.max_travel)
            x.reshape(-1)[alone], y.reshape(-1)[alone], contact.reshape(-1)[alone] = nx, ny, c
        busy = a.nonzero(n_slow > 1)
        if busy.shape[0]:
            bx, by, bdx, bdy = x0[busy], y0[busy], dx[busy], dy[busy]
            brad = radius[busy]
            walls = robot_walls(self.floors, scene[busy], bx, by, bdx, bdy, brad, self.max_travel)
            nx, ny, c = advance_robots(a, bx, by, bdx, bdy, brad, present=slow[busy], walls=walls)
            bslow = slow[busy]
            x[busy] = xp.where(bslow, nx, x[busy])
            y[busy] = xp.where(bslow, ny, y[busy])
            contact[busy] = c & bslow

    # ------------------------------------------------------------------ observation and info
    def _scan_ranges(self, c: Any, s: Any) -> Any:
        """Every robot's scan readings (m), ``(num_envs, n_robots, n_rays)``; robots outside
        ``_seen`` neither see nor are seen (their rows are hidden by ``_observe``)."""
        xp, st = self.arrays.xp, self.state
        yaw = xp.arctan2(s, c)  # the heading as the multi-robot env's frame gives it
        return self.scan.readings(self.world_scene, st.x, st.y, yaw, self._seen, self.radius, st.steps,
                                  None if self.crowd is None else self.crowd.discs())

    def _map_values(self) -> Any:
        """Every robot's local map, ``(num_envs, n_robots, cells * cells)``, with the discs of
        the robots in ``_seen`` (the scan's rule); rows outside it are hidden by ``_observe``."""
        st = self.state
        return self.local_map.values(self.world_scene, st.x, st.y, st.yaw, self._seen, self.radius,
                                     None if self.crowd is None else self.crowd.discs())

    def _observe(self, shown: Any) -> Any:
        """The robots' ``low_dim`` observations, zero where ``shown`` is False."""
        obs = super()._observe()
        return obs * as_dtype(self.arrays.xp, shown[..., None], obs.dtype)

    def _info(self, success: Any, r_pot: Any, r_col: Any, r_goal: Any, contact: Any, shown: Any, resetting: Any) -> dict[str, Any]:
        xp = self.arrays.xp
        info = super()._info(success, r_pot, r_col, r_goal, contact, resetting)
        for key, value in info.items():
            if key != "autoreset":
                info[key] = value & shown if value.dtype == self.arrays.boolean else xp.where(shown, value, xp.zeros_like(value))
        info["active"] = copy(self.arrays.xp, self._active)
        return info
