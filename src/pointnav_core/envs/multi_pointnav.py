"""Multi-robot point-goal navigation as a PettingZoo ``ParallelEnv``: ``MultiPointNav-v0``.

| Import             | `from pointnav_core.envs import multi_pointnav`, then `multi_pointnav.parallel_env()` |
|--------------------|--------------------------------------------------------------------------------------|
| Actions            | Continuous; discrete with `action_space="discrete"`                  |
| Parallel API       | Yes                                                                  |
| Manual Control     | No                                                                   |
| Agents             | `agents = ["robot_0", ..., "robot_<n_robots - 1>"]`                 |
| Number of Agents   | `n_robots` (default 2)                                               |
| Action Shape       | `(2,)` differential drive, `(3,)` holonomic; `Discrete(4)`           |
| Action Values      | `[-1, 1]`, float32; or MOVE_FORWARD, TURN_LEFT, TURN_RIGHT, STOP     |
| Observation Shape  | `(8,)` (plus the sensors' values when on); with `flatten_obs=False`  |
|                    | a `Dict` of `xy_pos_to_goal (2,)`, `robot_lin_vel (3,)`,             |
|                    | `robot_ang_vel (3,)`, and `scan (n_rays,)`, `local_map (cells,       |
|                    | cells)` when on                                                      |
| Observation Values | bounded, float32 (as in `PointNavEnv`)                               |
| State Shape        | `(8 * n_robots,)`                                                    |
| State Values       | bounded, float32                                                     |

Registered as ``pointnav_core/MultiPointNav-v0`` in PettingZoo's ``"parallel"`` and ``"aec"``
registries when ``pointnav_core`` is imported, so after ``import pointnav_core``,
``pettingzoo.make("parallel", "pointnav_core/MultiPointNav-v0")`` builds this env and
``pettingzoo.make("aec", ...)`` its AEC form.

Description
-----------
Many robots share one scene; each has its own :class:`~pointnav_core.task.PointNavigationTask`
(its ``robot_idn`` is the robot's index) with its own start, goal and episode, exactly as
in the single-robot :class:`~pointnav_core.envs.pointnav.PointNavEnv`: the same rewards, termination
conditions, metrics and observations. Agent ``robot_<i>`` drives robot ``i``. Robots are
solid for each other: the backend resolves robot-robot contacts like obstacle contacts, and
such a contact counts as a collision for *both* robots (their tasks' ``collision`` reward
and ``max_collision`` counter).

Arguments
---------
``parallel_env(scene=None, n_robots=2, robot=None, task=None, backend="kinematic",
backend_kwargs=None, max_cycles=500, render_mode=None, flatten_obs=True, finished="park",
action_frequency=10.0, sensors=None, action_space="continuous", discrete_actions=None,
config=None)``; ``config`` (an :class:`~pointnav_core.envs.config.EnvConfig`) sets every argument below but
``scene``, ``n_robots``, ``max_cycles`` (default: its ``max_steps``), ``render_mode`` and ``finished``.

| Argument           | Type                        | Default           | Description            |
|--------------------|-----------------------------|-------------------|------------------------|
| `scene`            | **Scene** or `None`         | `scenes.rooms(0)` | floors all robots share|
| `n_robots`         | **int** >= 1                | `2`               | robots (and agents)    |
| `robot`            | **RobotSpec**/dict, or list | `RobotSpec()`     | one for all, or each   |
| `task`             | **dict**, or list           | `{}`              | task arguments: one for|
|                    |                             |                   | all, or one per robot  |
| `backend`          | **str**, class or instance  | `"kinematic"`     | any registered backend |
| `backend_kwargs`   | **dict** or `None`          | `None`            | the backend's arguments|
| `max_cycles`       | **int** >= 1                | `500`             | steps, then all agents |
|                    |                             |                   | are truncated          |
| `render_mode`      | **str** or `None`           | `None`            | `"rgb_array"` or None  |
| `flatten_obs`      | **bool**                    | `True`            | flat `(8,)` `low_dim`, |
|                    |                             |                   | or a `Dict` if False   |
| `finished`         | `"park"` or `"remove"`      | `"park"`          | a finished robot stays,|
|                    |                             |                   | or leaves the world    |
| `action_frequency` | **float**                   | `10.0`            | 0.1 to 10,000 Hz       |
| `sensors`          | **dict** or `None`          | `None`            | `scan`, `local_map` for|
|                    |                             |                   | every robot            |
| `action_space`     | **str**                     | `"continuous"`    | or `"discrete"`        |
| `discrete_actions` | **dict** or `None`          | `None`            | step, angle, STOP      |
| `pedestrians`      | **dict** or `None`          | `None`            | a crowd (`PointNavEnv`)|

``pedestrians`` (keys and rules as :class:`~pointnav_core.envs.pointnav.PointNavEnv`'s) puts
one crowd on the first robot's floor, clear of and beside every robot; each robot's contacts
and social metrics (``info["pedestrian_collisions"]``, ``info["social"]``) are its own.

``task`` entries are :class:`~pointnav_core.task.PointNavigationTask` keyword arguments
(a list may also hold ready tasks); the env sets ``robot_idn`` (an entry that gives one must
give its own index). A list of ``robot`` or ``task`` entries must have ``n_robots`` entries.

Observation and action spaces
-----------------------------
Per agent, the same as ``PointNavEnv`` for that robot: the action is ``(v, w)`` (or
``(vx, vy, w)`` for a holonomic robot) in ``[-1, 1]``, scaled by the robot's maxima and held
for one control step; the observation is the robot's own goal in its own frame and its own
velocities (OmniGibson's flat 8-vector, or a ``Dict`` with ``flatten_obs=False``). Agents do
not observe each other's state: :meth:`MultiPointNavEnv.state` is the global view. With
``sensors`` (as in ``PointNavEnv``: :mod:`pointnav_core.sensors`) every robot gets its own
sensors: its range scan sees the other robots present on its floor as discs, and its
local map marks them. With ``action_space="discrete"`` every agent acts with an integer
(:mod:`pointnav_core.task.actions`); the robots' commands run together, each for its own
action's control steps (a robot whose action is shorter, or ended at a contact, stands
still meanwhile), and the env step counts once.
``observation_space(agent)`` and ``action_space(agent)`` return the same object every call.

State
-----
``state()`` is a float32 vector of ``8 * n_robots`` values, robot by robot:
``x, y, z, yaw, goal_x, goal_y, goal_z, active`` (metres, radians; ``active`` is 1.0 while
the robot's agent is in ``agents``, else 0.0). x and y are bounded by the union of the
floors' extents plus 1 m, z by the floor heights minus 10 m and plus 1 m, yaw by
``[-pi, pi]``; values are clipped to ``state_space``.

Rewards
-------
Each agent gets its own task's reward (potential, collision, point-goal), a Python
``float``; ``infos[agent]`` is that task's info (``success``, ``spl``, ``collisions``,
``reward_breakdown``, ...), also at reset. Flags are Python ``bool``.

Starting state
--------------
At ``reset`` the backend forgets every robot's place, then robots are placed one by one:
first those with a fixed ``initial_pos`` (in index order), then the others. Each task samples
its start as usual, and the backend's ``is_valid_pose`` already counts the robots placed
before it, so **no two robots overlap**. Goals are **distinct**: two robots' goals on the
same floor are at least ``max(tol_i + tol_j, r_i + r_j, cell)`` apart (``tol`` the goal
tolerance, ``r`` the radius, ``cell`` the floor's map resolution), so that their success
discs do not overlap, both robots can stand on their goals, and even point robots with no
tolerance get goals at least a cell apart. A sampled goal that is too close to a goal
chosen before (or to a fixed goal) is re-drawn, together with its start, up to
``PointNavigationTask.max_trials`` times, then :class:`~pointnav_core.errors.SamplingError`
names the robots. Fixed starts that would overlap, and fixed goals closer than that, are a
``ValueError`` at construction.
All randomness comes from the seed given to ``reset``.

Episode end
-----------
Each agent's episode ends by its task's conditions (success, collisions, falling, its
``max_steps`` timeout) or, for all agents at once, when the env has taken ``max_cycles``
steps since reset (a truncation, as in PettingZoo's MPE; the task's own ``info`` does not
count it). An agent whose episode ended is in that step's return dicts for the last time
(its final observation) and is removed from ``agents`` in that step; it never comes back
before the next ``reset``. Its robot stays **parked** in the world, standing still, as an
obstacle for the others (``finished="park"``), or is taken out of the world
(``finished="remove"``: nothing collides with it). A robot that fell (drove over void) has
left its floor and is taken out of the world in either mode.

Stepping rules
--------------
``step(actions)`` needs exactly one action for every agent in ``agents``:

- a missing action (or ``None``) for an alive agent is a ``ValueError``;
- an action for an agent that is not alive (its episode ended) is a ``ValueError``, and so
  is one for an unknown agent;
- an action of the wrong shape, or with NaN or infinity, is a ``ValueError`` naming the
  agent; values outside ``[-1, 1]`` are clipped;
- ``step`` when no agent is alive (before the first reset, or after every episode ended)
  raises :class:`~pointnav_core.task.TaskStateError`: call ``reset``.

All these are checked before anything moves, so a rejected step changes nothing. If a
step fails half-way (a backend error), the episode is void and ``step`` raises until the
next ``reset``.

Rendering
---------
``render()`` returns a top-down ``(H, W, 3)`` uint8 image when
``render_mode="rgb_array"`` (:func:`pointnav_core.render.recording.render_env`): the first task's
floor, every robot present on it (parked ones too) and, with ``visualize_goal`` /
``visualize_path``, each task's markers. PettingZoo's ``render_test`` builds every env with
``render_mode="human"`` first, so ``"human"`` is accepted at construction; it is not
supported (there is no window), and ``render()`` then raises ``NotImplementedError``.
``render(mode)`` also works when ``mode`` is None or the ``render_mode`` (RLlib's
PettingZoo wrapper passes it); another mode is a ``ValueError``.

Examples
--------
>>> import numpy as np
>>> from pointnav_core.envs import multi_pointnav
>>> env = multi_pointnav.parallel_env(n_robots=3, task={"goal_tolerance": 0.3})
>>> observations, infos = env.reset(seed=0)
>>> env.agents, observations["robot_0"].shape, observations["robot_0"].dtype
(['robot_0', 'robot_1', 'robot_2'], (8,), dtype('float32'))
>>> actions = {agent: np.array([1.0, 0.0], dtype=np.float32) for agent in env.agents}
>>> observations, rewards, terminations, truncations, infos = env.step(actions)
>>> type(rewards["robot_1"]), terminations["robot_1"], infos["robot_1"]["episode_length"]
(<class 'float'>, False, 1)
>>> env.state().shape, env.state_space.contains(env.state())
((24,), True)

Version History
---------------
* v0: Initial version.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from numpy.typing import NDArray
from pettingzoo import AECEnv, ParallelEnv
from pettingzoo.utils.conversions import parallel_to_aec, parallel_to_aec_wrapper

from pointnav_core import scenes
from pointnav_core.backends.protocol import Backend, make_backend
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.envs import _crowd, _multi_actions, _multi_agents
from pointnav_core.envs import common as _envcommon
from pointnav_core.envs._multi_crowd import FleetCrowd, reset_fleet
from pointnav_core.envs._multi_render import render_frame
from pointnav_core.envs._multi_state import global_state, state_space
from pointnav_core.envs.config import EnvConfig, multi_robot_arguments, takes_config
from pointnav_core.envs.fleet import (
    check_finished,
    check_fixed_positions,
    derived_path_ranges,
    goal_separation,
    make_robots,
    make_tasks,
    prefixed,
)
from pointnav_core.errors import ArgumentError
from pointnav_core.floor.maps import BoundedCache
from pointnav_core.task import TaskStateError
from pointnav_core.task.actions import make_discrete_actions
from pointnav_core.utils import validation

__all__ = ["MultiPointNavEnv", "env", "parallel_env", "raw_env"]


class MultiPointNavEnv(ParallelEnv[str, Any, np.ndarray]):
    """Many robots, one scene, one :class:`PointNavigationTask` each: a PettingZoo ParallelEnv.

    The module docstring (:mod:`pointnav_core.envs.multi_pointnav`) is this env's documentation page:
    agents, spaces, state, rewards, starting state, episode end, stepping rules.

    Parameters
    ----------
    scene : Scene, optional
        The floors all robots share; default ``scenes.rooms(seed=0)``.
    n_robots : int
        Number of robots (agents ``robot_0`` ... ``robot_<n_robots - 1>``), >= 1.
    robot : RobotSpec or dict or None, or a list of them
        One spec for every robot, or one per robot.
    task : dict or None, or a list of dicts, None or PointNavigationTask
        ``PointNavigationTask`` arguments for every robot, or one entry per robot; the env
        sets each task's ``robot_idn``.
    backend : str or type or Backend
        A registered backend name (``backends.protocol.available_backends()``), a class, or an instance.
    backend_kwargs : dict, optional
        Arguments of the backend's constructor (name or class only).
    max_cycles : int
        Steps after which every agent still alive is truncated, >= 1.
    render_mode : {None, "rgb_array"}
        ``"human"`` is accepted for PettingZoo's ``render_test`` but cannot render.
    flatten_obs : bool
        Flat ``(8,)`` observations (the default: PettingZoo's ``api_test`` and RLlib's
        default encoders expect arrays); False gives the ``Dict`` of ``PointNavEnv``.
    finished : {"park", "remove"}
        A finished robot stays as an obstacle, or leaves the world.
    action_frequency : float
        Control rate (Hz), from 0.1 to 10,000.
    config : EnvConfig, optional
        :class:`~pointnav_core.envs.config.EnvConfig`: every robot's ``robot`` and ``task``
        (with its ``max_steps``), ``backend``, ``flatten_obs``, ``action_frequency``,
        ``sensors``, ``action_space`` and ``discrete_actions``, which may then not be given
        (a ValueError names them); ``max_cycles`` defaults to its ``max_steps``.

    Raises
    ------
    ValueError
        For any invalid argument, naming it (``task[2]: goal_tolerance ...``).
    """

    metadata = {"render_modes": ["rgb_array"], "name": "MultiPointNav-v0", "render_fps": 10}

    @takes_config(multi_robot_arguments)
    def __init__(
        self,
        scene: scenes.Scene | None = None,
        n_robots: int = 2,
        robot: RobotSpec | Mapping[str, Any] | Sequence[Any] | None = None,
        task: Mapping[str, Any] | Sequence[Any] | None = None,
        backend: str | type | Backend = "kinematic",
        backend_kwargs: Mapping[str, Any] | None = None,
        max_cycles: int = 500,
        render_mode: str | None = None,
        *,
        flatten_obs: bool = True,
        finished: str = "park",
        action_frequency: float = 10.0,
        sensors: Mapping[str, Any] | None = None,
        action_space: str = "continuous",
        discrete_actions: Mapping[str, Any] | None = None,
        pedestrians: Mapping[str, Any] | None = None,
        config: EnvConfig | None = None,
    ) -> None:
        #: The :class:`~pointnav_core.envs.config.EnvConfig` this env was built from, or None.
        self.config = config
        if render_mode is not None and render_mode not in (*self.metadata["render_modes"], "human"):
            modes = self.metadata["render_modes"]
            raise ArgumentError(f"render_mode must be None or one of {modes}, got {render_mode!r}")
        n = validation.integer("n_robots", n_robots, minimum=1)
        self.max_cycles = validation.integer("max_cycles", max_cycles, minimum=1)
        check_finished(finished)
        scene, frequency = _envcommon.check_world_args(scene, flatten_obs, action_frequency, backend_kwargs)
        self.robots = make_robots(robot, n)
        derive = derived_path_ranges(task, n)
        self.discrete_actions = make_discrete_actions(action_space, discrete_actions)
        crowd = _crowd.make_crowd(pedestrians, scene)
        task = _envcommon.add_stop(_envcommon.add_sensors(task, sensors), self.discrete_actions)
        tasks = make_tasks(_crowd.add_pedestrian_termination(task, crowd), n)
        self.crowd = crowd  #: The pedestrians (:class:`~pointnav_core.crowds.Crowd`), or None.
        self._fleet_crowd = self._own_fleet = None if crowd is None else FleetCrowd(crowd, n)

        self.scene = scene
        self.render_mode = render_mode
        self._renderers = BoundedCache(2)  # floor pictures prepared for render()
        self.flatten_obs = bool(flatten_obs)
        self.finished = finished
        self.action_frequency = frequency
        # A robot has min(its task's max_steps, max_cycles) steps to reach its goal.
        for i, (t, rb) in enumerate(zip(tasks, self.robots)):
            steps = min(t.max_steps, self.max_cycles)
            length = _envcommon.step_length(rb, frequency, self.discrete_actions)
            _envcommon.fit_path_range(t, length, steps, derive[i], name=f"task[{i}]")
        self.backend = make_backend(backend, **dict(backend_kwargs or {}))
        self.backend.load(scene, self.robots, frequency)
        for i, t in enumerate(tasks):
            try:
                t.load(self)  # fails here, naming the parameter, if it does not fit
            except ValueError as err:
                raise prefixed(f"task[{i}]", err) from None
        #: One task per robot, indexed by ``robot_idn`` (read it, don't replace entries).
        self.tasks = tasks
        #: m, how far apart two robots' goals must be (read by the batched fleet's pools).
        self.separation = goal_separation(scene, tasks, self.robots)
        check_fixed_positions(tasks, self.robots, self.separation)
        # Robots with a fixed start are placed first, so no sampled start can take it.
        #: Robot indices in the order a reset places them.
        self.reset_order = sorted(range(n), key=lambda i: tasks[i].initial_pos is None)

        self._set_agents(tasks, frequency)
        self._active = [False] * n
        self._cycles = 0
        self._np_random: np.random.Generator | None = None
        self._np_random_seed: int | None = None
        # True until a reset completes, and after a step or reset that failed half-way.
        self._void = True
        self._started = False  # whether reset() was ever called

    def _set_agents(self, tasks: list[Any], frequency: float) -> None:
        """Build the agents, their spaces, the state space and the step loop's values (``frequency``, Hz)."""
        table = _multi_agents.AgentTable(self.robots, tasks, self.discrete_actions, self.flatten_obs, frequency)
        #: The agents' spaces and per-step values (:class:`~pointnav_core.envs._multi_agents.AgentTable`).
        self.agent_table = table
        self.possible_agents = table.names
        self.agents: list[str] = []
        self.action_spaces, self.observation_spaces = table.action_spaces, table.observation_spaces
        self.state_space = state_space(self.scene, len(tasks))
        self._state_low = self.state_space.low.astype(np.float64)
        self._state_high = self.state_space.high.astype(np.float64)
        # Read on every step and reset: plain attributes.
        self._index, self._plans, self._observe, self._slots = table.index, table.plans, table.observe, table.slots

    # ------------------------------------------------------------------ PettingZoo API
    def observation_space(self, agent: str) -> spaces.Space[Any]:
        """The observation space of ``agent`` (the same object on every call)."""
        return self.agent_table.observation_space(agent)

    def action_space(self, agent: str) -> spaces.Box:
        """The action space of ``agent`` (the same object on every call)."""
        return self.agent_table.action_space(agent)  # type: ignore[return-value]

    @property
    def np_random(self) -> np.random.Generator:
        """The env's random generator, seeded by ``reset(seed=...)`` (the tasks' only source)."""
        if self._np_random is None:
            self._np_random, self._np_random_seed = seeding.np_random()
        return self._np_random

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, dict[str, Any]]]:
        """Start a new episode for every robot; the same ``seed`` gives the same episodes.

        ``options={"episodes": [...]}`` plays dataset episodes, one per robot in robot
        order (or a dict keyed by agent; see :mod:`pointnav_core.datasets.playback`); other
        options are not used. Returns observations and infos keyed by agent (each info is
        that robot's task info at step 0).
        """
        if options is not None and not isinstance(options, Mapping):
            raise ArgumentError(f"options must be None or a dict, got {options!r}")
        given = self.agent_table.episodes((options or {}).get("episodes"))
        if seed is not None or self._np_random is None:
            self._np_random, self._np_random_seed = seeding.np_random(seed)
        self.agents = []
        self._void = True
        self._started = True
        self.backend.reset()
        infos = _multi_agents.reset_tasks(self, self.tasks, self.reset_order, self.separation, given)
        self._fleet_crowd = reset_fleet(self, self._own_fleet, given[0], infos)  # robot 0's episode's crowd
        self._active = [True] * len(self.tasks)
        self._cycles = 0
        self.agents = self.possible_agents[:]
        self._void = False
        observe = self._observe
        observations = {agent: observe[i](self) for i, agent in enumerate(self.agents)}
        return observations, {agent: infos[i] for i, agent in enumerate(self.agents)}

    def step(self, actions: Mapping[str, Any]) -> _multi_agents.StepReturns:
        """Apply one action per alive agent for one control step.

        Returns observations, rewards, terminations, truncations and infos, each keyed by
        the agents that acted; those whose episode ended are no longer in ``agents``. See
        the module docstring's "Stepping rules" for what is an error.
        """
        agents = self.agents
        if not agents:
            raise _multi_actions.no_agents_error(self._started, self._void)
        # Check every action before anything moves (finiteness: the backend, which moves
        # nothing when it refuses a step): a rejected step changes nothing.
        plans = self._plans
        commands, todo = _multi_actions.check_actions(agents, actions, self._slots, plans, self._index)
        fleet = self._fleet_crowd
        after = None if fleet is None else fleet.begin(self)  # the crowd walks every control step
        if plans is None:
            try:
                self.backend.step(commands)
                if after is not None:
                    after()
            except ValueError as err:  # a rejected step moved nothing: name the agent
                raise _multi_actions.named_action_error(err, todo) from None
            except BaseException:
                self.agents = []
                self._void = True
                raise
            contacts = None
        try:
            if plans is not None:
                contacts = _multi_actions.step_discrete(self.backend, plans, commands, after)
            self._cycles += 1
            returns, alive, ended = _multi_agents.step_tasks(self, todo, contacts, self._cycles >= self.max_cycles)
            if fleet is not None:
                fleet.finish(self, self._index, returns)
            for i in ended:
                self._finish(i)
            self.agents = alive
        except BaseException:
            self.agents = []
            self._void = True
            raise
        return returns

    def pedestrian_contact(self, idn: int) -> bool:
        """Whether robot ``idn`` touched a pedestrian during the last action."""
        return self._fleet_crowd is not None and self._fleet_crowd.touched[idn]

    def _finish(self, i: int) -> None:
        self._active[i] = False
        gone = any(c.removes_robot and c.done for c in self.tasks[i].termination_conditions.values())
        if self.finished == "remove" or gone:
            self.backend.set_present(i, False)

    def state(self) -> NDArray[np.float32]:
        """Return the global state: ``x, y, z, yaw, goal_x, goal_y, goal_z, active`` per robot.

        A fresh float32 array of shape ``(8 * n_robots,)``, clipped to ``state_space``.

        Raises
        ------
        TaskStateError
            Before the first reset, or after a reset or step that failed half-way.
        """
        if self._void:
            raise TaskStateError("state() needs an episode: call reset() first")
        return global_state(
            self.backend, self.tasks, self._active, self._state_low, self._state_high
        )

    def render(self, mode: str | None = None) -> NDArray[np.uint8] | None:
        """Return a top-down RGB image (H, W, 3) uint8 when ``render_mode="rgb_array"``.

        ``mode``, if given, must be the ``render_mode`` chosen at construction.
        """
        return render_frame(self, mode, self._renderers)

    def close(self) -> None:
        """Release the backend's resources (if it holds any)."""
        close = getattr(self.backend, "close", None)
        if callable(close):
            close()

    def __repr__(self) -> str:
        return (
            f"MultiPointNavEnv(n_robots={len(self.robots)}, backend="
            f"{type(self.backend).__name__}, agents={self.agents})"
        )


def parallel_env(**kwargs: Any) -> MultiPointNavEnv:
    """Build the parallel env: ``MultiPointNavEnv(**kwargs)`` (see the module docstring)."""
    return MultiPointNavEnv(**kwargs)


def raw_env(**kwargs: Any) -> AECEnv[str, Any, Any]:
    """Build the AEC form without PettingZoo's order-enforcing wrapper."""
    return parallel_to_aec_wrapper(MultiPointNavEnv(**kwargs))


def env(**kwargs: Any) -> AECEnv[str, Any, Any]:
    """Build the AEC form: ``parallel_to_aec(parallel_env(**kwargs))`` (order-enforced)."""
    return parallel_to_aec(MultiPointNavEnv(**kwargs))
