"""``VectorPointNavEnv``: many point-navigation worlds stepped together as arrays.

Every world is a :class:`~pointnav_core.envs.pointnav.PointNavEnv` with one robot on the kinematic
backend (several robots per world: :mod:`pointnav_core.vector.fleet_env`), and the batched
step reproduces them (drive, contacts and sliding, the task's rewards, terminations, SPL
and SoftSPL, the flat ``low_dim`` observation, the range scan and the local map) with array operations
over all worlds at once: there is no Python loop over worlds on the step path.
The same code runs on numpy (``device="numpy"``) and on torch (``"cpu"``, ``"cuda"``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Self

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv

from pointnav_core import scenes
from pointnav_core.envs import common as _envcommon
from pointnav_core.envs.config import EnvConfig, takes_config, vector_arguments
from pointnav_core.errors import ArgumentError, TaskStateError
from pointnav_core.utils import validation
from pointnav_core.vector import contacts_jit
from pointnav_core.vector.accounting import read_task, task_step
from pointnav_core.vector.arguments import (
    as_scene_list,
    check_continuous_actions,
    task_arguments,
)
from pointnav_core.vector.crowd import (
    VectorCrowd,
    check_vector_pedestrians,
    crowd_map_high,
    recorded_crowds,
)
from pointnav_core.vector.discrete import DiscretePlan
from pointnav_core.vector.drive_step import drive_worlds
from pointnav_core.vector.episodes import EpisodePool, episode_reach, fixed_pose
from pointnav_core.vector.floors import FloorTables
from pointnav_core.vector.local_map import VectorLocalMap, local_map_term
from pointnav_core.vector.observe import low_dim, step_info
from pointnav_core.vector.pool_build import build_parts, pool_options
from pointnav_core.vector.refresh import PoolRefreshing
from pointnav_core.vector.scan import ScanTables, VectorScan, requested_scan
from pointnav_core.vector.state import Motion, WorldState
from pointnav_core.vector.xp import as_dtype, cat, copy, make_arrays

__all__ = ["VectorPointNavEnv"]


class VectorPointNavEnv(PoolRefreshing, VectorEnv):
    """``num_envs`` single-robot point-navigation worlds, stepped as arrays.

    A ``gymnasium.vector.VectorEnv`` with next-step autoreset. Each world behaves as a
    :class:`~pointnav_core.envs.pointnav.PointNavEnv` with ``flatten_obs=True`` on the kinematic
    backend (same reward terms, terminations, SPL and SoftSPL; the differences are in
    ``docs/decisions.md``, "The batched engine").

    Parameters
    ----------
    num_envs : int
        Worlds, >= 1.
    n_robots : int
        Robots per world, >= 1. With more than one, the engine is the multi-robot one
        (see "Several robots per world" below), which also takes ``max_cycles`` (int,
        default 500) and ``finished`` (``"park"``, the default, or ``"remove"``), as
        :func:`pointnav_core.envs.multi_pointnav.parallel_env` does.
    scene : Scene or sequence of Scene, optional
        World ``i`` runs on ``scene[i % len(scene)]``, at its own resolution. Floors with
        obstacle polygons (floor plans, the generated houses) need the compiled contacts
        (the CPU with numba); the scan sees their polygons as the single env's does. Default: the single env's default house
        as a grid.
    robot : RobotSpec or dict, optional
        As for the single env: a differential drive (actions ``(v, w)``) or a holonomic one
        (actions ``(vx, vy, w)`` in the robot frame, +x ahead, +y to the left), scaled and
        integrated as the kinematic backend does (:mod:`pointnav_core.vector.drive`). With
        several robots per world, also a list with one entry per robot, as for
        :func:`~pointnav_core.envs.multi_pointnav.parallel_env`: their speed limits and radii may
        differ, their drive may not (the actions are one array).
    task : dict, optional
        ``PointNavigationTask`` keyword arguments, as for the single env (its default
        ``path_range`` too). Custom terms are not supported. Any ``fall_height`` (m):
        a fall goes on over as many control steps as it takes to pass it, as in the
        single env (:mod:`pointnav_core.vector.falls`). With several robots per world,
        also a list of one dict per robot (see "Several robots per world").
    sensors : dict, optional
        ``{"scan": {...}}`` (:class:`~pointnav_core.sensors.RangeScan` arguments, as for the
        single env): the flat observation is the 8 ``low_dim`` values, then the scan's
        ``n_rays`` ranges (m, in ``[0, max_range]``), in the single env's order and bounds,
        cast by :mod:`pointnav_core.vector.scan` (compiled with numba on numpy, arrays on
        torch). Noise and dropout are the single env's draws: world ``w`` of seed ``s`` as ``reset(seed=s + w)``.
        ``{"local_map": {...}}`` (:class:`~pointnav_core.sensors.LocalMap` arguments) adds
        its ``cells * cells`` codes (0 free, 1 blocked, 2 void or off the map, 3 another
        robot; after the scan when both are given), equal to the single env's
        (:mod:`pointnav_core.vector.local_map`); ``dtype`` shapes only the single env's
        ``Dict`` observation, the flat one is float32 either way.
    device : str
        ``"numpy"`` (default), or torch on ``"cpu"`` or ``"cuda[:n]"``.
    seed : int, optional
        Seeds the episode pools and the draws from them.
    pool_size : int
        Goals prepared per scene, >= 1 (each with its settled goal field);
        :meth:`refresh_pool` prepares fresh ones while the worlds run.
    action_frequency : float
        Control steps per second (Hz).
    action_space : str
        ``"continuous"`` (default) or ``"discrete"``: Habitat's actions, as the single env
        (:mod:`pointnav_core.task.actions`), each run as its control steps
        (:mod:`pointnav_core.vector.discrete`).
    discrete_actions : dict, optional
        ``forward_step``, ``turn_angle``, ``stop``, as the single env.
    starts_per_goal : int
        Episodes per pool goal, >= 1: the extra starts share the goal's field, so a larger
        pool costs next to nothing more to prepare.
    max_episode_steps : int, optional
        The task's ``max_steps``, as ``gymnasium.make(..., max_episode_steps=N)`` sets it for
        the single env (the derived ``path_range`` follows).
    config : EnvConfig, optional
        :class:`~pointnav_core.envs.config.EnvConfig`: ``robot``, ``task``, ``max_steps``,
        ``sensors``, ``action_frequency``, ``action_space`` and ``discrete_actions``, which
        may then not be given (nor ``max_episode_steps``); its ``backend`` must be
        ``"kinematic"`` and its ``flatten_obs`` True. A single env built from the same
        config has the same spaces (:mod:`pointnav_core.envs.config`).
    workers : int, optional
        Processes that build a pool over several scenes, each scene's episodes and goal
        fields in one (:mod:`pointnav_core.vector.pool_build`); the pool is the same, byte
        for byte, for any number. Default: the usable cores, at most one per scene, from
        4 scenes on; 1 builds in this process. A script that uses more than one must guard
        its entry point (``if __name__ == "__main__":``), as for any spawned process.
    progress : bool, optional
        A tqdm bar over the pool's scenes on stderr; default: from 4 scenes on, on a terminal.
    pedestrians : dict, optional
        A crowd in every world, as the single env's ``pedestrians`` (``"orca"`` or
        ``"static"``; numpy with numba): each world's crowd is the one a single env (a
        multi-robot env) walks beside the same robots (:mod:`pointnav_core.vector.crowd`);
        the scan sees it, the local map marks it (code 4), and ``info`` counts
        ``pedestrian_collisions`` (with ``end_on_collision``, a touch ends the episode).

    Notes
    -----
    ``step`` takes actions of shape ``(num_envs, 2)`` (or ``(num_envs, 1, 2)``) in
    ``[-1, 1]`` (clipped), ``(num_envs, 3)`` (or ``(num_envs, 1, 3)``) for a holonomic
    robot, or with discrete actions integers of shape ``(num_envs,)``, and
    returns observations ``(num_envs, 8)`` float32 (``(num_envs, 8 + n_rays)`` with the
    scan, plus ``cells * cells`` with the local map), rewards float64, terminated and truncated bool, and ``info``, a dict of arrays of shape
    ``(num_envs,)``: ``success``, ``spl``, ``soft_spl``, ``path_length``,
    ``geodesic_dist``, ``distance_to_goal``, ``collisions``, ``episode_length``,
    ``in_contact``, ``reward_potential``, ``reward_collision``, ``reward_pointgoal`` (and ``reward_slack`` with ``r_slack > 0``) and
    ``autoreset`` (the worlds this step reset instead of stepping). Arrays are numpy with
    ``device="numpy"`` and torch tensors on the device otherwise. On the CPU (numpy, or
    torch on ``"cpu"``) with the ``fast`` extra (numba), the contacts
    (:mod:`pointnav_core.vector.contacts_jit`) and the scan run as compiled loops over the
    worlds, proven equal to the array code that runs on a GPU.

    **Several robots per world** (``n_robots=R > 1``; an instance of the subclass
    :class:`~pointnav_core.vector.fleet_env.VectorFleetEnv`). Each world behaves as a
    :func:`pointnav_core.envs.multi_pointnav.parallel_env` with ``n_robots=R`` on the kinematic backend
    with the same ``finished`` and ``max_cycles``: robots are solid for each other, a
    robot-robot contact counts as a collision for both, every robot has its own task
    (rewards, terminations, SPL), and all robots still active are truncated after
    ``max_cycles`` steps. Every return carries the robot axis: ``step`` takes actions
    ``(num_envs, R, 2)`` (``(num_envs, R, 3)`` for holonomic robots; all finite, those of
    inactive robots are ignored), or with
    ``action_space="discrete"`` integers ``(num_envs, R)`` (all in range), and returns
    observations ``(num_envs, R, 8)`` float32 (``(num_envs, R, 8 + n_rays)`` with the scan,
    which sees the other robots present in its world as the multi-robot env's scan does;
    plus ``cells * cells`` with the local map, which draws the same robots as code 3),
    rewards ``(num_envs, R)`` float64,
    terminated and truncated ``(num_envs, R)`` bool and ``info`` arrays ``(num_envs, R)``
    with, besides the keys above, ``active``: the robots that are still agents (PettingZoo's
    ``agents``). A robot whose episode ended returns its last observation, reward and flags
    in that step and is inactive from then on: its entries are zero (False) and its action
    is ignored; with ``finished="park"`` it stays in the world as an obstacle, with
    ``"remove"`` it leaves it (a robot that fell leaves it in both modes). A world with no
    active robot left resets all its robots at the next step (next-step autoreset, as
    above, with ``autoreset`` True for all of them). Episodes are drawn, per scene, by that
    scene's ``parallel_env`` (non-overlapping starts, goals kept
    :func:`pointnav_core.envs.fleet.goal_separation` apart); ``reset(options={"episodes": [[
    (start_xy, yaw, goal_xy), ...], ...]})`` fixes, per world, one tuple per robot.
    Discrete actions run as the multi-robot env runs them: a world takes as many control
    steps as its robots' longest action; in each, a robot whose action lasts and has
    touched nothing drives, the others stand (and can still be touched, which counts as
    their collision); STOP ends that robot's episode (a success within ``goal_tolerance``).
    ``starts_per_goal`` gives each pool episode more sets of starts for the same goals
    (drawn by the multi-robot env's sampler, robot by robot, clear of each other).
    ``robot`` and ``task`` lists (:mod:`pointnav_core.vector.per_robot`) give robot ``i`` of
    every world entry ``i``: its task's ``goal_tolerance``, ``reward_type``,
    ``goal_in_polar``, ``termination_config`` (``max_steps``, ``max_collisions``,
    ``fall_height``), ``reward_config`` and ``path_range`` and its robot's speed limits
    (m/s, rad/s; with discrete actions, each robot's actions then last its own number of
    control steps) and radius (m: walls at its radius, another robot at the sum of the two
    radii, its disc in the others' scans and maps) may differ; a list whose tasks'
    ``floor`` differ raises ``ValueError`` naming ``task``, as does a list of the wrong
    length or an entry of the wrong type (naming ``task[i]`` or ``robot[i]``).

    Examples
    --------
    >>> from pointnav_core.scenes import Scene
    >>> grid = np.zeros((20, 20), np.uint8)
    >>> grid[[0, -1], :] = grid[:, [0, -1]] = 1  # a walled 2 x 2 m room
    >>> env = VectorPointNavEnv(4, scene=Scene.from_array(grid, 0.1), seed=0, pool_size=2,
    ...                         task={"path_range": (0.5, 1.5)})
    >>> obs, info = env.reset()
    >>> obs.shape, obs.dtype
    ((4, 8), dtype('float32'))
    >>> obs, reward, terminated, truncated, info = env.step(np.zeros((4, 2)))
    >>> info["episode_length"].tolist(), reward.tolist()  # standing still: no progress
    ([1, 1, 1, 1], [0.0, 0.0, 0.0, 0.0])
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}
    _pool_class: Any = EpisodePool  # the episodes prepared ahead (the fleet's have a robot axis)

    def __new__(cls, *args: Any, **kwargs: Any) -> Self:
        # Several robots per world are their own engine (vector.fleet_env), built from here.
        if cls is VectorPointNavEnv:
            n_robots = kwargs.get("n_robots", args[1] if len(args) > 1 else 1)
            if isinstance(n_robots, (int, np.integer)) and not isinstance(n_robots, bool) and n_robots > 1:
                from pointnav_core.vector.fleet_env import VectorFleetEnv

                return super().__new__(VectorFleetEnv)
            for name in ("max_cycles", "finished"):
                if name in kwargs:
                    raise ArgumentError(f"{name} applies to several robots per world (n_robots > 1), got n_robots={n_robots!r}")
        return super().__new__(cls)

    @takes_config(vector_arguments, extra=("max_episode_steps",))
    def __init__(
        self,
        num_envs: int = 1,
        n_robots: int = 1,
        scene: scenes.Scene | Sequence[scenes.Scene] | None = None,
        robot: Any = None,
        task: Mapping[str, Any] | None = None,
        sensors: Mapping[str, Any] | None = None,
        device: str = "numpy",
        seed: int | None = None,
        pool_size: int = 8,
        action_frequency: float = 10.0,
        max_episode_steps: int | None = None,
        action_space: str = "continuous",
        discrete_actions: Mapping[str, Any] | None = None,
        starts_per_goal: int = 1,
        config: EnvConfig | None = None,
        workers: int | None = None,
        progress: bool | None = None,
        pedestrians: Mapping[str, Any] | None = None,
    ) -> None:
        from pointnav_core.crowds import make_pedestrians
        from pointnav_core.envs.pointnav import PointNavEnv

        #: The :class:`~pointnav_core.envs.config.EnvConfig` these worlds were built from, or None.
        self.config = config

        self.num_envs = validation.integer("num_envs", num_envs, minimum=1)
        if validation.integer("n_robots", n_robots, minimum=1) != 1:  # several: built by __new__
            raise ArgumentError(f"n_robots must be 1 here, got {n_robots}: VectorPointNavEnv builds the multi-robot engine")
        scan_term = requested_scan(sensors)
        task = task_arguments(task)
        crowd = make_pedestrians(pedestrians)
        check_vector_pedestrians(crowd, device)
        self.pool_size = validation.integer("pool_size", pool_size, minimum=1)
        self.starts_per_goal = validation.integer("starts_per_goal", starts_per_goal, minimum=1)
        self.arrays = make_arrays(device)
        self.device = device
        self.scenes = scene_list = as_scene_list(scene)
        self._pool_workers, self._pool_progress = pool_options(workers, progress, len(scene_list))
        self.robot = _envcommon.make_robot(robot)  # either drive (vector.drive)
        self._samplers = [
            PointNavEnv(scene=s, robot=self.robot, task=dict(task), sensors=sensors, flatten_obs=True,
                        action_frequency=action_frequency, action_space=action_space, discrete_actions=discrete_actions)
            for s in scene_list
        ]
        if max_episode_steps is not None:
            for env in self._samplers:  # sets the task's max_steps and refits a derived path_range
                env.max_episode_steps = max_episode_steps
        first = self._samplers[0]
        read_task(self, first.task, first.action_frequency)
        t, spec, a = self.task, self.robot, self.arrays
        acts = first.discrete_actions
        self._discrete = None if acts is None else DiscretePlan(acts, spec, self.action_frequency, a)
        shared = [env.backend.floor_geometry(t.floor) for env in self._samplers]  # built by their backends
        self.floors = FloorTables(scene_list, t.floor, spec.radius, a, shared)
        bounds = [env.task.observation_bounds for env in self._samplers]
        self._low = a.asarray(np.stack([b[0] for b in bounds]).astype(np.float32))  # float32: _observe clips after its cast
        self._high = a.asarray(np.stack([b[1] for b in bounds]).astype(np.float32))
        low = np.min([b[0] for b in bounds], axis=0)
        high = np.max([b[1] for b in bounds], axis=0)
        if crowd is not None:  # the samplers have none: their local map's top code is a robot's
            high = crowd_map_high(high, sensors)
        self.single_observation_space = gym.spaces.Box(low, high, dtype=np.float32)
        self.single_action_space = first.action_space
        self.observation_space = gym.vector.utils.batch_space(self.single_observation_space, self.num_envs)
        self.action_space = gym.vector.utils.batch_space(self.single_action_space, self.num_envs)
        self._rng = np.random.default_rng(seed)
        self.world_scene = a.asarray(np.arange(self.num_envs) % len(scene_list), a.i64)
        self.pool: EpisodePool | None = None  # sampled at the first reset that needs it
        self._allocate((self.num_envs,), scan_term, sensors)
        #: Every world's pedestrians (:class:`~pointnav_core.vector.crowd.VectorCrowd`), or None.
        self.crowd = VectorCrowd.for_engine(crowd, self, [spec.radius], self._pool_progress)

    def _allocate(self, shape: tuple[int, ...], scan_term: Any, sensors: Mapping[str, Any] | None) -> None:
        """The state arrays of ``shape`` (one entry per world, or per robot), the per-world
        flags and the sensors (both engines)."""
        a = self.arrays
        contacts_jit.prepare(self.floors)  # not in the first step that meets a wall
        self._fixed: Any = None
        #: The committed state of every world (robot); a step replaces it (vector.state).
        self.state = WorldState.zeros(a, shape)
        self._needs_reset = a.zeros(self.num_envs, a.boolean)
        self._started = False
        tables = None if scan_term is None else ScanTables(self.scenes, self.task.floor, a)
        self.scan = None if scan_term is None else VectorScan(scan_term, tables)
        if self.scan is not None:
            self.scan.seed(self._rng)
        map_term = local_map_term(sensors)
        self.local_map = None if map_term is None else VectorLocalMap(map_term, self.floors)

    # ------------------------------------------------------------------ pools
    @property
    def _reach(self) -> float:
        """How far (m) a robot's centre can get from its start in one episode (:func:`episode_reach`)."""
        return episode_reach(self, self._discrete)

    def _build_pool(self, fixed: Sequence[tuple[Any, float, Any, int]]) -> None:
        size = 0 if fixed else self.pool_size
        seeds = self._rng.integers(2**31, size=size * len(self.scenes))
        # Each scene's part, in worker processes with workers > 1 (the same arrays).
        parts = None if fixed else build_parts(self._pool_class, self._samplers, size, seeds, self.starts_per_goal,
                                               self._reach, self._pool_workers, self._pool_progress)
        self.pool = self._pool_class(self._samplers, size, seeds, self.arrays, fixed, self.starts_per_goal, self._reach,
                                     parts=parts)
        if self.crowd is not None:  # the pool's crowds are drawn anew
            self.crowd.seed(int(self._rng.integers(2**63)))

    # ------------------------------------------------------------------ Gymnasium API
    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        """Reset every world. ``options={"episodes": [(start_xy, yaw, goal_xy), ...]}`` (one per
        world, yaw in rad) fixes each world's episode, at this reset and every autoreset, until a
        reset without it; an entry may also be a dataset episode (``PointNavEpisode``), checked
        as the single env checks it (its ``scene_id`` against the world's scene's, its floor,
        start and goal). A new ``seed`` redraws the pools."""
        self._reset_pools(seed, options)
        a = self.arrays
        with np.errstate(invalid="ignore", divide="ignore"):
            self._reset_worlds(a.full(self.num_envs, True, a.boolean))
        self._started = True
        obs = self._observe()
        with np.errstate(invalid="ignore", divide="ignore"):
            return obs, self._info(a.zeros(self.num_envs, a.boolean), a.zeros(self.num_envs), a.zeros(self.num_envs),
                                   a.zeros(self.num_envs), a.zeros(self.num_envs, a.boolean), a.zeros(self.num_envs, a.boolean))

    def _reset_pools(self, seed: int | None, options: Any) -> None:
        """A reset's checks and pools (both engines): reseed, fix the given episodes (each
        checked by :meth:`_fixed_episode`) or redraw the pools when needed."""
        self._finish_refresh()
        a = self.arrays
        if options is not None and not isinstance(options, Mapping):
            raise ArgumentError(f"options must be None or a dict, got {options!r}")
        episodes = (options or {}).get("episodes")
        if seed is not None:
            self._rng = np.random.default_rng(validation.integer("seed", seed, minimum=0))
            if self.scan is not None:
                self.scan.seed(self._rng)
        if episodes is not None:
            if len(episodes) != self.num_envs:
                raise ArgumentError(f"options['episodes'] must hold one episode per world ({self.num_envs}), got {len(episodes)}")
            scene_of = a.numpy(self.world_scene)
            fixed = [self._fixed_episode(i, episode, int(scene_of[i])) for i, episode in enumerate(episodes)]
            self._build_pool(fixed)
            self._fixed = a.asarray(self.pool.n_sampled + np.arange(self.num_envs), a.i64)
            recorded_crowds(self, {self.pool.n_sampled + i: getattr(ep, "pedestrians", None) for i, ep in enumerate(episodes)})
        elif self.pool is None or seed is not None or self._fixed is not None:
            self._fixed = None
            self._build_pool(())
            recorded_crowds(self, {})

    def _fixed_episode(self, i: int, episode: Any, s: int) -> tuple[Any, float, Any, int]:
        """World ``i``'s given episode on scene ``s``, checked; ValueError naming it."""
        env = self._samplers[s]
        return (*fixed_pose(f"options['episodes'][{i}]", episode, env.scene, env.task.floor, self.robot), s)

    def _reset_worlds(self, mask: Any) -> None:
        a, xp, st = self.arrays, self.arrays.xp, self.state
        n = self.num_envs
        if self._fixed is not None:
            ep = self._fixed
        else:
            k = a.asarray(self._rng.integers(self.pool.pool_size, size=n), a.i64)
            ep = self.world_scene * self.pool.pool_size + k
        idx = a.nonzero(mask)
        height = self.floors.height[self.world_scene[idx]]  # (k,); each robot of a fleet's world
        st.start_episodes(xp, idx, self.pool, ep[idx], height, self.geodesic_reward)
        self._needs_reset[idx] = False
        if self.crowd is not None:
            self.crowd.start_worlds(a.numpy(idx), a.numpy(ep[idx]), self.pool)
        if self.scan is not None:  # the worlds' episode counts key the scan's noise
            self.scan.begin(mask, n)

    def check_actions(self, actions: Any) -> Any:
        """``actions`` as a float64 array ``(num_envs, action_dim)`` (2 for a differential
        drive, 3 for a holonomic one), or with discrete actions an int64 array
        ``(num_envs,)``; ValueError naming ``actions`` if bad."""
        if self._discrete is not None:
            return self._discrete.check(actions, self.num_envs)
        return check_continuous_actions(actions, self.num_envs, self.robot, self.arrays)

    def step(self, actions: Any) -> tuple[Any, Any, Any, Any, dict[str, Any]]:
        """Advance every world one control step (worlds that ended last step reset instead)."""
        if self.refresh_active:
            self._poll_pool()
        with np.errstate(invalid="ignore", divide="ignore"):  # inf distances are masked by where
            return self._step(actions)

    def _step(self, actions: Any) -> tuple[Any, Any, Any, Any, dict[str, Any]]:
        if not self._started:
            raise TaskStateError("call reset() before step()")
        act = self.check_actions(actions)
        crowd = self.crowd  # it walks beside the moved robots, each control step
        if crowd is not None:
            crowd.begin()
        if self._discrete is None:
            moved, contact = self.drive(act, self.state)
            stopped = None
            if crowd is not None:
                crowd.step(moved, self.dt)
        else:
            moved, contact, stopped = self._discrete.run(self, act)
        return self._account(moved, contact, stopped, None if crowd is None else crowd.finish()[:, 0])

    def drive(self, act: Any, state: Motion) -> tuple[Motion, Any]:
        """One control step of every world from ``state`` under commands ``act``
        ``(num_envs, action_dim)``, not committed: the new pose, height, velocities and fall
        speed, and the contacts. A falling robot ignores its command and drops
        (:func:`~pointnav_core.vector.falls.apply_falls`)."""
        return drive_worlds(self, act, state)  # a method: the fleet has its own, the discrete plan calls either

    def _account(self, moved: Motion, contact: Any, stopped: Any,
                 touched: Any = None) -> tuple[Any, Any, Any, Any, dict[str, Any]]:
        """The task's step over the worlds' moves from the committed state: rewards, ends, info,
        then the commit and the next-step autoresets. ``stopped``: the worlds that called STOP;
        ``touched``: those whose robot touched a pedestrian."""
        a, xp = self.arrays, self.arrays.xp
        t = task_step(self, moved, contact, stopped, pedestrian=touched)  # PointNavigationTask.step's accounting
        reward, terminated, truncated, success = t.reward, t.terminated, t.truncated, t.success
        r_pot, r_col, r_goal, r_custom = t.r_pot, t.r_col, t.r_goal, t.r_custom
        # Commit, then reset the worlds that ended on the previous step (next-step autoreset).
        self.state = self.state.moved(moved, path_length=t.path, goal_distance=t.dist, potential=t.pot, steps=t.steps,
                                      collisions=t.collisions)
        resetting = copy(xp, self._needs_reset)
        if a.any(resetting):
            self._reset_worlds(resetting)
            keep = ~resetting
            reward = xp.where(keep, reward, 0.0)
            terminated, truncated, success, contact = terminated & keep, truncated & keep, success & keep, contact & keep
            r_pot, r_col, r_goal = (xp.where(keep, r, 0.0) for r in (r_pot, r_col, r_goal))
            r_custom = {name: xp.where(keep, r, 0.0) for name, r in r_custom.items()}
        self._needs_reset = terminated | truncated
        info = self._info(success, r_pot, r_col, r_goal, contact, resetting)
        for name, r in r_custom.items():  # fresh arrays, as _info's
            info[f"reward_{name}"] = copy(xp, r)
        return self._observe(), reward, terminated, truncated, info

    # ------------------------------------------------------------------ observation and info
    def _observe(self) -> Any:
        xp = self.arrays.xp
        obs, c, s = low_dim(xp, self.state, self.goal_in_polar)
        if self.scan is not None:
            obs = cat(xp, [obs, self._scan_ranges(c, s)], -1)
        # Cast, then clip in place (rounding is monotone: the floats of clipping first); one
        # scene's bounds broadcast over the worlds (no gather), else each world its scene's.
        obs = as_dtype(xp, obs, xp.float32)
        low, high = self._low[..., :obs.shape[-1]], self._high[..., :obs.shape[-1]]
        low, high = (low[0], high[0]) if low.shape[0] == 1 else (low[self.world_scene], high[self.world_scene])
        obs = xp.minimum(xp.maximum(obs, low, out=obs), high, out=obs)
        if self.local_map is not None:  # after the scan (the single env's order); codes within their bounds
            obs = cat(xp, [obs, self._map_values()], -1)
        return obs

    def _scan_ranges(self, c: Any, s: Any) -> Any:
        """The scan's readings (m), ``(num_envs, n_rays)``, at the headings' cosines ``c`` and sines ``s``."""
        xp, st = self.arrays.xp, self.state
        yaw, one = xp.arctan2(s, c)[:, None], xp.ones_like(c)[:, None] > 0.0  # the single env's frame heading
        return self.scan.readings(self.world_scene, st.x[:, None], st.y[:, None], yaw, one, self.robot.radius,
                                  st.steps[:, None], None if self.crowd is None else self.crowd.discs())[:, 0]

    def _map_values(self) -> Any:
        """The local map's codes, ``(num_envs, cells * cells)`` float32 (one robot: no discs)."""
        st = self.state
        one = self.arrays.xp.ones_like(st.x)[:, None] > 0.0
        return self.local_map.values(self.world_scene, st.x[:, None], st.y[:, None], st.yaw[:, None], one,
                                     self.robot.radius, None if self.crowd is None else self.crowd.discs())[:, 0]

    def _info(self, success: Any, r_pot: Any, r_col: Any, r_goal: Any, contact: Any, resetting: Any) -> dict[str, Any]:
        info = step_info(self.arrays.xp, self.state, success, r_pot, r_col, r_goal, contact, resetting)
        if self.crowd is not None:  # counted after this step's autoresets, as the single env's reset gives 0
            info["pedestrian_collisions"] = self.crowd.collisions.reshape(self.state.x.shape).copy()
        return info
