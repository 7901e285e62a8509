"""The point-goal navigation task: OmniGibson's ``PointNavigationTask`` as a state machine.

:class:`PointNavigationTask` owns one robot's episode: it samples a start and a goal,
lands the robot, and after every control step measures progress, decides whether the
episode is over (:mod:`~pointnav_core.terminations`), pays rewards
(:mod:`~pointnav_core.rewards`) and reports metrics (:mod:`~pointnav_core.metrics`). It
never moves anything itself: the environment steps the backend, then calls
:meth:`PointNavigationTask.step`.

Lifecycle
---------
The task is a small state machine (h11 style, :mod:`~pointnav_core.lifecycle`): its states
are :class:`TaskState` and its legal moves the table ``lifecycle.TRANSITIONS``, drawn in
``docs/lifecycle.md``. ``step`` is legal only while RUNNING. Calling it in any other state
raises :class:`TaskStateError` and changes nothing. ``reset`` is legal in every state.

The environment
---------------
The ``env`` handed to :meth:`~PointNavigationTask.reset`, :meth:`~PointNavigationTask.step`
and :meth:`~PointNavigationTask.get_obs` is the environment object (a ``PointNavEnv``, or a
multi-robot env). The task reads only the four members of :class:`TaskEnv`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, ClassVar, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core import validation
from pointnav_core.backend import float_twin
from pointnav_core.frozen import FrozenMapping
from pointnav_core.lifecycle import (
    ERROR,
    IDLE,
    ILLEGAL_HINT,
    TaskState,
    TaskStateError,
    allows,
    move,
)
from pointnav_core.lifecycle import Event as _Event
from pointnav_core.markers import VisualMarker, _waypoints_along
from pointnav_core.metrics import _soft_spl, _spl
from pointnav_core.observations import (
    Frame,
    ObservationLayout,
    ObservationTerm,
    default_observation_terms,
)
from pointnav_core.rewards import (
    CollisionReward,
    PointGoalReward,
    PotentialReward,
    RewardFunction,
)
from pointnav_core.sampling import GoalConstraint, sample_episode
from pointnav_core.terminations import (
    Falling,
    MaxCollision,
    PointGoal,
    TerminationCondition,
    Timeout,
    _check_count,
    _check_length,
)

if TYPE_CHECKING:
    from pointnav_core.backend import Backend, RobotSpec
    from pointnav_core.scenes import FloorGoalField, Scene

__all__ = [
    "REWARD_TYPES",
    "PointNavigationTask",
    "TaskEnv",
    "TaskState",
    "TaskStateError",
]

#: Valid values of ``reward_type``: the distance the potential reward is measured in.
REWARD_TYPES = ("l2", "geodesic")

# How far from 1 the norm of a fixed initial_quat may be (it is then normalised).
_QUAT_NORM_TOL = 1e-3


class TaskEnv(Protocol):
    """What the task needs from the environment it runs in.

    A ``PointNavEnv`` provides these, and so must any multi-robot environment.
    """

    @property
    def scene(self) -> Scene:
        """The floors, their sampling and geodesic queries."""
        ...

    @property
    def backend(self) -> Backend:
        """The world: poses, velocities, contacts of every robot."""
        ...

    @property
    def robots(self) -> Sequence[RobotSpec]:
        """One spec per robot; the index is ``robot_idn``."""
        ...

    @property
    def np_random(self) -> np.random.Generator:
        """The only source of randomness the task uses (seeded by the env's reset)."""
        ...


# ------------------------------------------------------------------------------ validation


_check_bool = validation.boolean


def _check_position(name: str, value: Any) -> tuple[float, float] | None:
    if value is None:
        return None
    try:
        arr = validation.vector(name, value, sizes=(2, 3))
    except ValueError:
        raise ValueError(
            f"{name} must be None or a finite position (x, y, z) in metres (z is replaced by "
            f"the floor height), got {value!r}"
        ) from None
    return float(arr[0]), float(arr[1])


def _check_quat(name: str, value: Any) -> tuple[float, float, float, float] | None:
    if value is None:
        return None
    try:
        arr = validation.vector(name, value, sizes=(4,))
    except ValueError:
        raise ValueError(
            f"{name} must be None or a finite unit quaternion (x, y, z, w), got {value!r}"
        ) from None
    norm = math.sqrt(float(arr @ arr))
    if abs(norm - 1.0) > _QUAT_NORM_TOL:
        raise ValueError(
            f"{name} must be a unit quaternion (x, y, z, w), got {value!r} of norm {norm:.6g}"
        )
    x, y, z, w = (float(c) / norm for c in arr)
    return x, y, z, w


def _check_path_range(value: Any) -> tuple[float, float] | None:
    if value is None:
        return None
    try:
        # Not finite-only: the maximum may be inf. '12' is not (1.0, 2.0), nor True 1.0.
        lo, hi = validation.vector("path_range", value, sizes=(2,), finite=False)
    except (TypeError, ValueError):
        raise ValueError(
            f"path_range must be None or (min, max) geodesic distances in metres, got {value!r}"
        ) from None
    if not (math.isfinite(lo) and lo >= 0.0 and hi > lo):  # hi may be inf; NaN fails
        raise ValueError(
            f"path_range must be (min, max) with 0 <= min < max (m), min finite, got {value!r}"
        )
    return float(lo), float(hi)


def _check_index(name: str, value: Any) -> int:
    return validation.integer(name, value, minimum=0)


def _merge_config(
    name: str, defaults: Mapping[str, Any], overrides: Mapping[str, Any] | None
) -> Mapping[str, Any]:
    merged = dict(defaults)
    if overrides is None:
        return FrozenMapping(merged)
    if not isinstance(overrides, Mapping):
        raise ValueError(f"{name} must be None or a dict, got {overrides!r}")
    for key in overrides:
        if key not in defaults:
            raise ValueError(
                f"{name} has an unknown key {key!r}; valid keys are {list(defaults)}"
            )
    merged.update(overrides)
    return FrozenMapping(merged)


def _compose(kind: str, base: type, defaults: Sequence[Any], extra: Any) -> dict[str, Any]:
    """Defaults plus ``extra`` terms by name: a term named like a default replaces it in
    place, any other is appended. ``kind`` names the argument in errors."""
    terms = {t.name: t for t in defaults}
    if extra is None:
        return terms
    if isinstance(extra, (str, bytes, Mapping)) or not isinstance(extra, Sequence):
        raise ValueError(f"{kind} must be None or a sequence of {base.__name__} objects, got {extra!r}")
    seen: set[str] = set()
    for term in extra:
        if not isinstance(term, base):
            raise ValueError(f"{kind} must hold {base.__name__} objects, got {term!r}")
        name = term.name
        if not isinstance(name, str) or not name:
            raise ValueError(f"{kind}: {term!r} must have a non-empty str name, got {name!r}")
        if name in seen:
            raise ValueError(f"{kind} has two terms named {name!r}")
        seen.add(name)
        terms[name] = term
    return terms


# ------------------------------------------------------------------------------ the task


class PointNavigationTask:
    """Drive robot ``robot_idn`` to a goal position on floor ``floor``.

    A faithful, bug-fixed port of OmniGibson's ``PointNavigationTask`` (same parameters,
    rewards, terminations, observations and metrics) that runs on any
    :class:`~pointnav_core.backend.Backend`.

    Parameters
    ----------
    robot_idn : int
        Index of the robot this task drives (in ``env.robots``), >= 0.
    floor : int
        Floor to navigate on, >= 0.
    initial_pos : array_like, shape (3,) or (2,), optional
        Fixed start (x, y, z) in metres; z is replaced by the floor height. None: sample a
        usable start uniformly at every reset.
    initial_quat : array_like, shape (4,), optional
        Fixed start orientation, a unit quaternion (x, y, z, w). None: a heading drawn
        uniformly from [0, 2 pi) at every reset.
    goal_pos : array_like, shape (3,) or (2,), optional
        Fixed goal (x, y, z) in metres. None: sample a goal reachable from the start.
    goal_tolerance : float
        Success when the xy distance to the goal is strictly below this (m), >= 0.
    goal_in_polar : bool
        Goal observation as (rho, phi) instead of (x, y) in the robot frame.
    path_range : (float, float), optional
        (min, max) in metres: a sampled start/goal pair must have min < geodesic < max.
        Ignored when both the start and the goal are fixed.
    visualize_goal : bool
        Show start and goal markers (discs of radius ``goal_tolerance``) when rendering
        (see :attr:`markers`).
    visualize_path : bool
        Show the current shortest path as ``n_vis_waypoints`` markers when rendering,
        moved after every step (see :attr:`markers`).
    goal_height : float
        Goal marker height (m), >= 0.
    waypoint_height : float
        Waypoint marker height (m), >= 0.
    waypoint_width : float
        Waypoint marker radius (m), > 0.
    n_vis_waypoints : int
        Number of waypoint markers, >= 1.
    reward_type : {"l2", "geodesic"}
        Distance the potential reward is measured in.
    termination_config : dict, optional
        Overrides of :attr:`default_termination_config`.
    reward_config : dict, optional
        Overrides of :attr:`default_reward_config`.
    termination_conditions, reward_functions, observation_terms : sequence, optional
        Extra :class:`~pointnav_core.terminations.TerminationCondition`,
        :class:`~pointnav_core.rewards.RewardFunction` and
        :class:`~pointnav_core.observations.ObservationTerm` objects. One named like a
        built-in term replaces it in place; any other is added after the built-in ones
        (evaluated, summed and observed in that order).

    Raises
    ------
    ValueError
        For any invalid argument, naming it. ``robot_idn``, ``floor``, ``initial_pos``
        and ``goal_pos`` are checked against the environment when the task first meets
        it (:meth:`load`).

    Notes
    -----
    Decisions where OmniGibson is silent or faulty:

    - A sampled goal is at least ``goal_tolerance`` (xy) from the start, so that no
      episode is won before it starts. Fixed positions are taken as given.
    - If the goal is not reachable from the start, ``geodesic_dist`` is ``inf`` and the
      geodesic potential uses L2 for the whole episode (``info["potential_metric"]``).
    - Where the robot stands legally but no geodesic is defined (its centre off the usable
      grid, e.g. while falling), the potential keeps its last value, so the potential
      reward is 0 there and the episode's potential rewards still telescope.
    - When the timeout fires on the same step as another condition, the step is both
      ``terminated`` and ``truncated`` (Gymnasium allows both; ``terminated`` tells a
      learner not to bootstrap).

    Examples
    --------
    >>> task = PointNavigationTask(goal_tolerance=0.3, termination_config={"max_steps": 200})
    >>> dict(task.termination_config)
    {'max_collisions': 500, 'max_steps': 200, 'fall_height': 0.03}
    >>> list(task.termination_conditions), list(task.reward_functions)
    (['max_collision', 'timeout', 'falling', 'pointgoal'], ['potential', 'collision', 'pointgoal'])
    >>> task.state
    <TaskState.IDLE: 'idle'>
    >>> PointNavigationTask(reward_type="manhattan")
    Traceback (most recent call last):
    ...
    ValueError: reward_type must be one of ['l2', 'geodesic'], got 'manhattan'
    """

    #: Attempts at sampling a valid start and goal before :class:`SamplingError`.
    max_trials: ClassVar[int] = 100

    #: Termination defaults (read-only; pass ``termination_config`` to override).
    default_termination_config: ClassVar[Mapping[str, Any]] = FrozenMapping(
        {"max_collisions": 500, "max_steps": 500, "fall_height": 0.03}
    )
    #: Reward defaults (read-only; pass ``reward_config`` to override).
    default_reward_config: ClassVar[Mapping[str, Any]] = FrozenMapping(
        {"r_potential": 1.0, "r_collision": 0.1, "r_pointgoal": 10.0}
    )

    def __init__(
        self,
        robot_idn: int = 0,
        floor: int = 0,
        initial_pos: ArrayLike | None = None,
        initial_quat: ArrayLike | None = None,
        goal_pos: ArrayLike | None = None,
        goal_tolerance: float = 0.5,
        goal_in_polar: bool = False,
        path_range: tuple[float, float] | None = None,
        visualize_goal: bool = False,
        visualize_path: bool = False,
        goal_height: float = 0.06,
        waypoint_height: float = 0.05,
        waypoint_width: float = 0.1,
        n_vis_waypoints: int = 10,
        reward_type: str = "l2",
        termination_config: Mapping[str, Any] | None = None,
        reward_config: Mapping[str, Any] | None = None,
        termination_conditions: Sequence[TerminationCondition] | None = None,
        reward_functions: Sequence[RewardFunction] | None = None,
        observation_terms: Sequence[ObservationTerm] | None = None,
    ) -> None:
        self._robot_idn = _check_index("robot_idn", robot_idn)
        self._floor = _check_index("floor", floor)
        self._initial_pos = _check_position("initial_pos", initial_pos)
        self._initial_quat = _check_quat("initial_quat", initial_quat)
        self._goal_pos = _check_position("goal_pos", goal_pos)
        self._goal_tolerance = _check_length("goal_tolerance", goal_tolerance)
        self._goal_in_polar = _check_bool("goal_in_polar", goal_in_polar)
        self._path_range = _check_path_range(path_range)
        self._visualize_goal = _check_bool("visualize_goal", visualize_goal)
        self._visualize_path = _check_bool("visualize_path", visualize_path)
        self._goal_height = _check_length("goal_height", goal_height)
        self._waypoint_height = _check_length("waypoint_height", waypoint_height)
        self._waypoint_width = _check_length("waypoint_width", waypoint_width)
        if self._waypoint_width == 0.0:
            raise ValueError(
                f"waypoint_width must be a finite number > 0 (m), got {waypoint_width!r}"
            )
        self._n_vis_waypoints = _check_count("n_vis_waypoints", n_vis_waypoints, minimum=1)
        if not isinstance(reward_type, str) or reward_type not in REWARD_TYPES:
            raise ValueError(
                f"reward_type must be one of {list(REWARD_TYPES)}, got {reward_type!r}"
            )
        self._reward_type = reward_type
        self._termination_config = _merge_config(
            "termination_config", self.default_termination_config, termination_config
        )
        self._reward_config = _merge_config(
            "reward_config", self.default_reward_config, reward_config
        )
        try:
            terminations = dict(self._create_termination_conditions())
        except ValueError as err:
            raise ValueError(f"termination_config: {err}") from None
        try:
            rewards = dict(self._create_reward_functions())
        except ValueError as err:
            raise ValueError(f"reward_config: {err}") from None
        terminations = _compose("termination_conditions", TerminationCondition, list(terminations.values()), termination_conditions)
        rewards = _compose("reward_functions", RewardFunction, list(rewards.values()), reward_functions)
        observations = _compose(
            "observation_terms", ObservationTerm, default_observation_terms(self._goal_in_polar), observation_terms
        )
        self._observations: Mapping[str, ObservationTerm] = FrozenMapping(observations)
        self._obs_layout: ObservationLayout | None = None
        self._frame = Frame()
        self._terminations: Mapping[str, TerminationCondition] = FrozenMapping(terminations)
        self._rewards: Mapping[str, RewardFunction] = FrozenMapping(rewards)
        # The same, as tuples of (name, object) pairs for the per-step loops (both
        # mappings are read-only, so these never go stale).
        self._termination_items = tuple(terminations.items())
        self._reward_items = tuple(rewards.items())

        self._state = IDLE
        # Bound at the first meeting with an env (load): caches for the per-step path.
        self._env: Any = None
        self._spec: Any = None
        # The backend last stepped with, and its float twins of get_pose / get_velocity
        # (None: read the protocol methods); see backend.float_twin.
        self._backend: Any = None
        self._pose_floats: Any = None
        self._velocity_floats: Any = None
        self._floor_height = 0.0
        # The episode (valid from the first successful reset).
        self._start_xy: tuple[float, float] | None = None
        self._start_quat: tuple[float, float, float, float] | None = None
        self._goal_xy: tuple[float, float] | None = self._goal_pos
        self._goal_field: FloorGoalField | None = None
        self._field_distance: Any = None
        self._geodesic_dist = math.inf
        self._metric = "l2"
        self._robot_xyz = (0.0, 0.0, 0.0)
        self._robot_quat: list[float] = [0.0, 0.0, 0.0, 1.0]
        self._potential = 0.0
        self._distance_to_goal = math.inf
        self._path_length = 0.0
        self._collisions = 0
        self._in_contact = False
        self._steps = 0
        self._success = False
        self._results: dict[str, tuple[bool, bool]] = {}
        # Visual markers (pointnav_core.markers): touched only when visualize_goal or
        # visualize_path is on. ``_markers`` is the tuple ``markers`` returns, None when a
        # step moved the waypoints and it must be rebuilt.
        self._waypoint_spacing = 0.2
        self._goal_markers: tuple[VisualMarker, ...] = ()
        self._waypoint_xy: NDArray[np.float64] | None = None
        self._waypoint_visible: NDArray[np.bool_] | None = None
        self._markers: tuple[VisualMarker, ...] | None = ()

    # ------------------------------------------------------------------ composition
    def _create_termination_conditions(self) -> dict[str, TerminationCondition]:
        """Build the termination conditions, in evaluation order (override to change them)."""
        cfg = self._termination_config
        conditions: list[TerminationCondition] = [
            MaxCollision(max_collisions=cfg["max_collisions"]),
            Timeout(max_steps=cfg["max_steps"]),
            Falling(fall_height=cfg["fall_height"]),
            PointGoal(goal_tolerance=self._goal_tolerance),
        ]
        return {c.name: c for c in conditions}

    def _create_reward_functions(self) -> dict[str, RewardFunction]:
        """Build the reward functions, in evaluation order (override to change them)."""
        cfg = self._reward_config
        rewards: list[RewardFunction] = [
            PotentialReward(r_potential=cfg["r_potential"]),
            CollisionReward(r_collision=cfg["r_collision"]),
            PointGoalReward(r_pointgoal=cfg["r_pointgoal"]),
        ]
        return {r.name: r for r in rewards}

    # ------------------------------------------------------------------ parameters
    @property
    def robot_idn(self) -> int:
        """Index of the robot this task drives."""
        return self._robot_idn

    @property
    def floor(self) -> int:
        """Floor the task navigates on."""
        return self._floor

    @property
    def initial_pos(self) -> NDArray[np.float64] | None:
        """The fixed start (x, y, z) in metres with z = 0 until loaded, or None (sampled)."""
        if self._initial_pos is None:
            return None
        return np.array((*self._initial_pos, self._floor_height))

    @property
    def initial_quat(self) -> NDArray[np.float64] | None:
        """The fixed start orientation (x, y, z, w), or None (random heading)."""
        return None if self._initial_quat is None else np.array(self._initial_quat)

    @property
    def goal_pos(self) -> NDArray[np.float64] | None:
        """The fixed goal (x, y, z) in metres, or None (sampled); see :meth:`get_goal_pos`."""
        return None if self._goal_pos is None else np.array((*self._goal_pos, self._floor_height))

    @property
    def goal_tolerance(self) -> float:
        """Success radius (m)."""
        return self._goal_tolerance

    @property
    def goal_in_polar(self) -> bool:
        """Whether the goal observation is (rho, phi)."""
        return self._goal_in_polar

    @property
    def path_range(self) -> tuple[float, float] | None:
        """(min, max) geodesic of sampled start/goal pairs (m), or None; settable, used
        from the next reset (the envs set it to what the robot can drive in time)."""
        return self._path_range

    @path_range.setter
    def path_range(self, value: tuple[float, float] | None) -> None:
        self._path_range = _check_path_range(value)

    @property
    def max_steps(self) -> int:
        """Steps after which the episode is truncated (``termination_config["max_steps"]``);
        settable, used from the next step (``gymnasium.make(max_episode_steps=...)`` sets it)."""
        return int(self._termination_config["max_steps"])

    @max_steps.setter
    def max_steps(self, value: int) -> None:
        steps = validation.integer("max_steps", value, minimum=1)
        self._termination_config = FrozenMapping({**self._termination_config, "max_steps": steps})
        current = self._terminations.get("timeout")
        if isinstance(current, Timeout):
            current.max_steps = steps

    @property
    def visualize_goal(self) -> bool:
        """Whether renderers draw the start and goal markers."""
        return self._visualize_goal

    @property
    def visualize_path(self) -> bool:
        """Whether renderers draw the shortest path's waypoint markers."""
        return self._visualize_path

    @property
    def goal_height(self) -> float:
        """Goal marker height (m)."""
        return self._goal_height

    @property
    def waypoint_height(self) -> float:
        """Waypoint marker height (m)."""
        return self._waypoint_height

    @property
    def waypoint_width(self) -> float:
        """Waypoint marker radius (m)."""
        return self._waypoint_width

    @property
    def n_vis_waypoints(self) -> int:
        """Number of waypoint markers."""
        return self._n_vis_waypoints

    @property
    def markers(self) -> tuple[VisualMarker, ...]:
        """The markers this task shows now, as :class:`~pointnav_core.markers.VisualMarker`.

        In order: the ``start`` and ``goal`` markers (radius ``goal_tolerance``, at
        ``goal_height`` above the floor) when ``visualize_goal``, then ``n_vis_waypoints``
        ``waypoint`` markers (radius ``waypoint_width``, at ``waypoint_height``) when
        ``visualize_path``, placed along the shortest path from the robot to the goal at
        reset and after every step (spacing and hiding rules:
        :func:`~pointnav_core.markers.place_waypoints`; all hidden when the robot has no
        path to the goal). Empty when both flags are off, and until a reset succeeds.
        Markers are data for renderers: nothing collides with them.
        """
        if self._markers is None:
            markers = self._goal_markers
            if self._waypoint_xy is not None and self._waypoint_visible is not None:
                z = self._floor_height + self._waypoint_height
                radius = self._waypoint_width
                markers += tuple(
                    VisualMarker(kind="waypoint", position=(x, y, z), radius=radius, visible=shown)
                    for (x, y), shown in zip(
                        self._waypoint_xy.tolist(), self._waypoint_visible.tolist()
                    )
                )
            self._markers = markers
        return self._markers

    @property
    def reward_type(self) -> str:
        """``"l2"`` or ``"geodesic"``."""
        return self._reward_type

    @property
    def termination_config(self) -> Mapping[str, Any]:
        """The merged termination configuration (read-only)."""
        return self._termination_config

    @property
    def reward_config(self) -> Mapping[str, Any]:
        """The merged reward configuration (read-only)."""
        return self._reward_config

    @property
    def termination_conditions(self) -> Mapping[str, TerminationCondition]:
        """Name -> termination condition, in evaluation order (read-only mapping)."""
        return self._terminations

    @property
    def reward_functions(self) -> Mapping[str, RewardFunction]:
        """Name -> reward function, in evaluation order (read-only mapping)."""
        return self._rewards

    # ------------------------------------------------------------------ episode state
    @property
    def state(self) -> TaskState:
        """Where the task is in its lifecycle."""
        return self._state

    @property
    def robot_xyz(self) -> tuple[float, float, float]:
        """Robot position (m) at the last reset or step, refreshed before the conditions run."""
        return self._robot_xyz

    @property
    def in_contact(self) -> bool:
        """Whether the robot touched an obstacle or another robot in this step (backend's word)."""
        return self._in_contact

    @property
    def floor_height(self) -> float:
        """Height (m) of the task's floor (0.0 until the task has met an env)."""
        return self._floor_height

    @property
    def goal_xy(self) -> tuple[float, float] | None:
        """This episode's goal (x, y) in metres (None before the first reset of a sampled goal)."""
        return self._goal_xy

    @property
    def potential(self) -> float:
        """Potential (m) at the last reset or step: the distance the potential reward uses."""
        return self._potential

    @property
    def distance_to_goal(self) -> float:
        """Geodesic distance (m) from the robot to the goal at the last reset or step
        (``inf`` where none is defined, e.g. over void); ``info["distance_to_goal"]``."""
        return self._distance_to_goal

    @property
    def potential_metric(self) -> str:
        """``"l2"`` or ``"geodesic"``: the potential's metric this episode (fixed at reset)."""
        return self._metric

    @property
    def termination_results(self) -> Mapping[str, tuple[bool, bool]]:
        """Name -> ``(done, success)`` of every condition at this step (read it, don't write)."""
        return self._results

    @property
    def geodesic_dist(self) -> float:
        """Geodesic distance (m) from this episode's start to the goal; ``inf`` if unreachable."""
        return self._geodesic_dist

    @property
    def path_length(self) -> float:
        """Planar distance (m) driven in this episode, including the last step."""
        return self._path_length

    @property
    def collisions(self) -> int:
        """Steps with a contact in this episode."""
        return self._collisions

    @property
    def episode_length(self) -> int:
        """Steps taken in this episode."""
        return self._steps

    @property
    def success(self) -> bool:
        """Whether the episode has ended in success."""
        return self._success

    # ------------------------------------------------------------------ lifecycle
    def _move(self, event: _Event) -> None:
        self._state = move(self._state, event)

    def check_step(self) -> None:
        """Raise :class:`TaskStateError` unless :meth:`step` is legal now (nothing changes).

        Environments call this before stepping the backend, so that an illegal step moves
        nothing in the world either.
        """
        if not allows(self._state, _Event.STEP):
            move(self._state, _Event.STEP)  # raises, naming the state and what to do

    def load(self, env: TaskEnv) -> None:
        """Meet an environment: check this task fits it, and cache what steps need.

        Checks that ``robot_idn`` names one of ``env.robots``, that ``floor`` is one of the
        scene's floors, and that a fixed ``initial_pos`` / ``goal_pos`` is usable by the
        robot there (on the map, on a FREE cell, and at least the robot's radius from any
        obstacle or void). :meth:`reset` calls this when it meets a new env; environments
        call it at construction so that a bad task fails early.

        Raises
        ------
        ValueError
            Naming ``robot_idn``, ``floor``, ``initial_pos`` or ``goal_pos``.
        """
        robots = env.robots
        if self._robot_idn >= len(robots):
            raise ValueError(
                f"robot_idn must be in [0, {len(robots)}) for an environment with "
                f"{len(robots)} robot(s), got {self._robot_idn}"
            )
        scene = env.scene
        if self._floor >= scene.n_floors:
            raise ValueError(
                f"floor must be in [0, {scene.n_floors}) for a scene with {scene.n_floors} "
                f"floor(s), got {self._floor}"
            )
        spec = robots[self._robot_idn]
        for name, xy in (("initial_pos", self._initial_pos), ("goal_pos", self._goal_pos)):
            if xy is not None and not scene.is_usable(self._floor, xy, spec):
                raise ValueError(
                    f"{name} {list(xy)} is not usable on floor {self._floor} by robot "
                    f"{self._robot_idn} (radius {spec.radius} m): it is off the map, on an "
                    f"obstacle or void, or closer than the radius to one"
                )
        self._spec = spec
        self._floor_height = float(scene.get_floor_height(self._floor))
        self._waypoint_spacing = float(scene.waypoint_spacing)
        # Observation bounds are finite, so that Gymnasium's checker accepts the spaces.
        self._obs_layout = ObservationLayout.from_terms(tuple(self._observations.values()), self, env)
        self._frame.task, self._frame.env = self, env
        self._env = env

    def reset(
        self, env: TaskEnv, goal_constraint: GoalConstraint | None = None, episode: Any = None
    ) -> dict[str, Any]:
        """Start a new episode: sample (or take) a start and a goal, land the robot.

        Parameters
        ----------
        env : TaskEnv
            The environment (its backend already reset). Randomness comes from
            ``env.np_random`` only, so a seeded env gives the same episode.
        goal_constraint : callable, optional
            ``goal_constraint(gx, gy)`` returns None to accept a sampled goal, else the
            constraint it breaks (named in a :class:`SamplingError`); a multi-robot env
            keeps goals apart with it. Not applied to a fixed ``goal_pos``. See
            :mod:`~pointnav_core.sampling`.
        episode : PointNavEpisode, optional
            Play this dataset episode (:mod:`pointnav_core.datasets`): its start, start
            orientation and goal replace the task's fixed or sampled ones for this episode.

        Returns
        -------
        dict
            The episode's initial ``info`` (the keys of :meth:`step`'s info, at step 0).

        Raises
        ------
        SamplingError
            If no valid start/goal pair was found in :attr:`max_trials` attempts; the
            message names the constraint that failed. The task is then in ERROR.
        ValueError
            If a fixed ``initial_pos`` or ``goal_pos`` does not suit the env (see
            :meth:`load`), or the fixed start is occupied by another robot.
        """
        try:
            self._clear_markers()
            if env is not self._env:
                self.load(env)
            self._bind(env.backend)  # every episode: a backend patched since is seen
            self._sample_episode(env, goal_constraint, episode)
            pos, quat = env.backend.get_pose(self._robot_idn)
            x, y, z = pos.tolist()
            self._robot_xyz = (x, y, z)
            self._robot_quat = quat.tolist()
            self._path_length = 0.0
            self._collisions = 0
            self._in_contact = False
            self._steps = 0
            self._success = False
            self._distance_to_goal = self._geodesic_at(x, y)
            self._potential = self._potential_at(x, y, self._distance_to_goal, self._geodesic_dist)
            self._results = {name: (False, False) for name in self._terminations}
            for condition in self._terminations.values():
                condition.reset(self, env)
            for reward in self._rewards.values():
                reward.reset(self, env)
            for term in self._observations.values():
                term.reset(self, env)
            if self._visualize_goal or self._visualize_path:
                self._place_markers(x, y)
        except BaseException:
            self._move(_Event.FAIL)
            raise
        self._move(_Event.RESET)
        return self._info(
            False,
            False,
            {name: 0.0 for name in self._rewards},
            {name: {"done": False, "success": False} for name in self._terminations},
        )

    def _sample_episode(self, env: TaskEnv, goal_constraint: GoalConstraint | None, given: Any = None) -> None:
        start, quat, goal = self._initial_pos, self._initial_quat, self._goal_pos
        if given is not None:  # a dataset episode: checked here, named in every error
            from pointnav_core.datasets.playback import episode_poses

            start, quat, goal = episode_poses(given, env.scene, self._floor, self._spec, self._robot_idn)
        try:
            episode = sample_episode(
                env,
                robot_idn=self._robot_idn,
                floor=self._floor,
                spec=self._spec,
                floor_height=self._floor_height,
                initial_pos=start,
                initial_quat=quat,
                goal_pos=goal,
                goal_tolerance=self._goal_tolerance,
                path_range=self._path_range,
                max_trials=self.max_trials,
                goal_constraint=goal_constraint,
            )
        except ValueError as err:
            if given is None:
                raise
            raise ValueError(f"episode {given.episode_id!r}: field 'start_position': {err}") from None
        # The robot stands at the start: it was landed there in the accepted trial.
        self._start_xy = episode.start_xy
        self._start_quat = episode.start_quat
        self._goal_xy = episode.goal_xy
        self._goal_field = episode.field
        self._field_distance = episode.field.distance
        self._geodesic_dist = geodesic = episode.geodesic
        # Decided once per episode, so the potential never jumps between metrics.
        geodesic_metric = self._reward_type == "geodesic" and geodesic < math.inf
        self._metric = "geodesic" if geodesic_metric else "l2"

    # ------------------------------------------------------------------ per step
    def _geodesic_at(self, x: float, y: float) -> float:
        """Geodesic distance (m) from (x, y) to the goal: the goal field's O(1) lookup.

        ``inf`` where the robot's centre cannot reach the goal (over void, off the map).
        """
        return self._field_distance(x, y)

    def _potential_at(self, x: float, y: float, geodesic: float, held: float) -> float:
        if self._metric == "l2":
            gx, gy = self._goal_xy  # type: ignore[misc]
            return math.hypot(gx - x, gy - y)
        # No geodesic here (e.g. over void): keep the last potential (see Notes).
        return geodesic if geodesic < math.inf else held

    def step(
        self, env: TaskEnv, action: Any, *, contact: bool | None = None
    ) -> tuple[float, bool, bool, dict[str, Any]]:
        """Account for one control step the environment has just taken.

        In order: the path length grows by the planar distance moved; every termination
        condition is evaluated (none short-circuits); every reward function is evaluated;
        ``info`` is filled; the waypoint markers move (only with ``visualize_path``).

        Parameters
        ----------
        env : TaskEnv
            The environment, whose backend has already advanced one control step.
        action : array_like
            The action that was applied (passed on to conditions and rewards).
        contact : bool, optional
            Whether the robot touched something during the step; default: ask the backend
            (``in_contact``). An env that runs one action as several control steps (discrete
            actions) passes whether any of them touched.

        Returns
        -------
        reward : float
            Sum of ``info["reward_breakdown"]``.
        terminated : bool
            A condition other than the timeout ended the episode.
        truncated : bool
            The timeout ended the episode (both flags can be True on the same step).
        info : dict
            ``success``, ``done``, ``path_length`` (m), ``spl``, ``soft_spl``,
            ``geodesic_dist`` (m, at the start), ``distance_to_goal`` (m, geodesic now),
            ``collisions``, ``reward_breakdown`` (name -> float), ``termination_conditions``
            (name -> {"done", "success"}), ``episode_length``, ``potential_metric``.

        Raises
        ------
        TaskStateError
            If no episode is running (before reset, or after the episode ended); the task
            is then unchanged.
        """
        if not allows(self._state, _Event.STEP):
            self.check_step()
        try:
            backend = env.backend
            if backend is not self._backend:
                self._bind(backend)
            idn = self._robot_idn
            if self._pose_floats is not None:
                x, y, z, *quat = self._pose_floats(idn)
            else:
                pos, orientation = backend.get_pose(idn)
                x, y, z = pos.tolist()
                quat = orientation.tolist()
            px, py, _ = self._robot_xyz
            self._path_length += math.hypot(x - px, y - py)
            self._robot_xyz = (x, y, z)
            self._robot_quat = quat
            self._steps += 1
            contact = bool(backend.in_contact(idn)) if contact is None else bool(contact)
            self._in_contact = contact
            if contact:
                self._collisions += 1
            geodesic = self._geodesic_at(x, y)
            self._distance_to_goal = geodesic
            self._potential = self._potential_at(x, y, geodesic, self._potential)

            # Each condition's result, and the same as info["termination_conditions"].
            results: dict[str, tuple[bool, bool]] = {}
            conditions: dict[str, dict[str, bool]] = {}
            done = success = terminated = truncated = False
            for name, condition in self._termination_items:
                result = condition.step(self, env, action)
                results[name] = result
                is_done, is_success = result
                conditions[name] = {"done": is_done, "success": is_success}
                if is_done:
                    done = True
                    if is_success:
                        success = True
                    if condition.is_truncation:
                        truncated = True
                    else:
                        terminated = True
            self._results = results
            self._success = success

            breakdown: dict[str, float] = {}
            for name, fn in self._reward_items:
                breakdown[name] = fn.step(self, env, action)
            reward = sum(breakdown.values(), 0.0)  # the sum a user gets from the breakdown
            info = self._info(success, done, breakdown, conditions)
            if self._visualize_path:
                self._place_waypoints(x, y)
        except BaseException:
            self._move(_Event.FAIL)
            raise
        self._state = move(self._state, _Event.END if done else _Event.STEP)
        return reward, terminated, truncated, info

    def _bind(self, backend: Any) -> None:
        """Remember ``backend`` and its float twins of get_pose and get_velocity, if any.

        Done at every reset, and by a step or an observation that meets another backend.
        """
        self._pose_floats = float_twin(backend, "get_pose_floats")
        self._velocity_floats = float_twin(backend, "get_velocity_floats")
        self._backend = backend

    # ------------------------------------------------------------------ markers
    def _clear_markers(self) -> None:
        self._goal_markers = ()
        self._waypoint_xy = self._waypoint_visible = None
        self._markers = ()

    def _place_markers(self, x: float, y: float) -> None:
        """Set this episode's markers, the robot standing at (x, y) (reset)."""
        gx, gy = self._goal_xy  # type: ignore[misc]
        if self._visualize_goal:
            sx, sy = self._start_xy  # type: ignore[misc]
            z = self._floor_height + self._goal_height
            radius = self._goal_tolerance
            self._goal_markers = (
                VisualMarker(kind="start", position=(sx, sy, z), radius=radius),
                VisualMarker(kind="goal", position=(gx, gy, z), radius=radius),
            )
        if self._visualize_path:
            n = self._n_vis_waypoints
            self._waypoint_xy = np.tile((gx, gy), (n, 1))
            self._waypoint_visible = np.zeros(n, dtype=bool)
            self._place_waypoints(x, y)
        self._markers = None

    def _place_waypoints(self, x: float, y: float) -> None:
        """Move the waypoint markers onto the path from (x, y); hide them if there is none."""
        # The goal field's cheap path (the source cell's root when the source sees it).
        points, _ = self._goal_field.path((x, y), exact=False)  # type: ignore[union-attr]
        if points is None:
            self._waypoint_visible = np.zeros(self._n_vis_waypoints, dtype=bool)
        else:
            # The placement of markers.place_waypoints, without its checks.
            self._waypoint_xy, self._waypoint_visible = _waypoints_along(
                points, self._n_vis_waypoints, self._waypoint_spacing
            )
        self._markers = None

    def _info(
        self,
        success: bool,
        done: bool,
        breakdown: dict[str, float],
        conditions: dict[str, dict[str, bool]],
    ) -> dict[str, Any]:
        d0, length, d_t = self._geodesic_dist, self._path_length, self._distance_to_goal
        return {
            "success": success,
            "done": done,
            "path_length": length,
            "spl": _spl(success, d0, length),
            "soft_spl": _soft_spl(d_t, d0, length),
            "geodesic_dist": d0,
            "distance_to_goal": d_t,
            "collisions": self._collisions,
            "reward_breakdown": breakdown,
            "termination_conditions": conditions,
            "episode_length": self._steps,
            "potential_metric": self._metric,
        }

    # ------------------------------------------------------------------ observations
    def _require_episode(self, what: str) -> None:
        if self._state is IDLE or self._state is ERROR:
            raise TaskStateError(
                f"{what} needs an episode, but the task is {self._state.name}: "
                f"{ILLEGAL_HINT[self._state]}"
            )

    def _obs_values(self, env: TaskEnv) -> list[float]:
        """Every observation term's values at this step, in order, clipped to the bounds."""
        backend = env.backend
        if backend is not self._backend:
            self._bind(backend)
        frame = self._frame
        if self._velocity_floats is not None:
            vx, vy, vz, wx, wy, wz = self._velocity_floats(self._robot_idn)
            frame.lin_vel, frame.ang_vel = (vx, vy, vz), (wx, wy, wz)
        else:
            lin, ang = backend.get_velocity(self._robot_idn)
            frame.lin_vel, frame.ang_vel = tuple(lin.tolist()), tuple(ang.tolist())
        # The pose recorded at the last reset or step: the one the metrics saw.
        x, y, z = self._robot_xyz
        frame.set_pose(x, y, z, self._robot_quat)
        frame.goal_x, frame.goal_y = self._goal_xy  # type: ignore[misc]
        frame.env = env
        return self._obs_layout.values(frame)  # type: ignore[union-attr]

    @property
    def observation_terms(self) -> Mapping[str, ObservationTerm]:
        """Name -> observation term, in observation order (read-only mapping)."""
        return self._observations

    @property
    def observation_layout(self) -> ObservationLayout:
        """Slices and bounds of the terms in the flat observation (after :meth:`load`).

        Raises
        ------
        TaskStateError
            Before the task has met an environment (:meth:`load`).
        """
        if self._obs_layout is None:
            raise TaskStateError("observation_layout needs an environment: call load(env) first")
        return self._obs_layout

    @property
    def observation_bounds(self) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
        """``(low, high)`` of every observation value in flat order, float32 arrays.

        With the built-in terms (see :mod:`~pointnav_core.observations`): the goal lies
        within the floor's diagonal plus 1 m (``rho`` in ``[0, that]`` and ``phi`` in
        ``[-pi, pi]`` when polar); linear velocities within ``sqrt(2) * max_linear_velocity``
        and angular ones within ``max_angular_velocity``. Observations are clipped to these
        bounds (a falling robot's vertical speed can exceed them).

        Raises
        ------
        TaskStateError
            Before the task has met an environment (:meth:`load`).
        """
        if self._obs_layout is None:
            raise TaskStateError("observation_bounds needs an environment: call load(env) first")
        return (
            np.array(self._obs_layout.low, dtype=np.float32),
            np.array(self._obs_layout.high, dtype=np.float32),
        )

    def get_obs(self, env: TaskEnv) -> dict[str, NDArray[np.float32]]:
        """Return the task's observation: one fresh float32 array per term, by name.

        Returns
        -------
        dict
            With the built-in terms: ``xy_pos_to_goal`` (2,): the goal minus the robot's
            position in the robot's heading frame (+x ahead, +y left), in metres; or
            ``(rho, phi)`` (m, rad in (-pi, pi]) when ``goal_in_polar``. ``robot_lin_vel``
            (3,) m/s and ``robot_ang_vel`` (3,) rad/s: world velocities rotated into the
            robot frame. Then any added terms. Values are clipped to
            :attr:`observation_bounds`.

        Notes
        -----
        The pose is the one the task recorded at the last reset or step (what its
        rewards and metrics saw; the environment has not moved the robot since), the
        velocities are read from the backend.

        Raises
        ------
        TaskStateError
            Before the first reset (there is no goal yet).
        """
        self._require_episode("get_obs()")
        # One fresh buffer per call, split by term (cheaper than one array per term).
        flat = np.array(self._obs_values(env), dtype=np.float32)
        return self._obs_layout.split(flat)  # type: ignore[union-attr]

    def get_low_dim_obs(self, env: TaskEnv) -> NDArray[np.float32]:
        """Return OmniGibson's flat ``low_dim`` observation: :meth:`get_obs`'s arrays
        concatenated in term order (with the built-in terms ``xy_pos_to_goal``,
        ``robot_lin_vel``, ``robot_ang_vel``: 8 float32 values), a fresh array."""
        self._require_episode("get_low_dim_obs()")
        return np.array(self._obs_values(env), dtype=np.float32)

    # ------------------------------------------------------------------ OmniGibson API
    def get_goal_pos(self) -> NDArray[np.float64] | None:
        """Return this episode's goal (x, y, z) in metres, z the floor height (fresh array).

        Before the first reset: the fixed goal, or None when the goal is sampled.
        """
        if self._goal_xy is None:
            return None
        return np.array((*self._goal_xy, self._floor_height))

    def get_start_pos(self) -> NDArray[np.float64] | None:
        """Return this episode's start (x, y, z) in metres (None before the first reset)."""
        if self._start_xy is None:
            return None
        return np.array((*self._start_xy, self._floor_height))

    def get_current_pos(self, env: TaskEnv) -> NDArray[np.float64]:
        """Return the robot's current position (x, y, z) in metres (fresh array)."""
        pos, _ = env.backend.get_pose(self._robot_idn)
        return np.array(pos, dtype=np.float64)

    def get_potential(self, env: TaskEnv) -> float:
        """Return the potential (m) at the robot's current position.

        The xy L2 distance to the goal, or the geodesic distance when ``reward_type`` is
        ``"geodesic"`` and the goal is reachable (``potential_metric``).
        """
        self._require_episode("get_potential()")
        x, y, _ = env.backend.get_pose(self._robot_idn)[0].tolist()
        return self._potential_at(x, y, self._geodesic_at(x, y), self._potential)

    def get_shortest_path_to_goal(
        self, env: TaskEnv, start_xy_pos: ArrayLike | None = None, entire_path: bool = False
    ) -> tuple[NDArray[np.float64], float] | tuple[None, None]:
        """Return the shortest path to the goal and its geodesic length.

        Parameters
        ----------
        env : TaskEnv
        start_xy_pos : array_like, shape (2,), optional
            Where the path starts (m); default: the robot's current position.
        entire_path : bool
            True: the whole any-angle polyline. False: ``scene.num_waypoints`` waypoints
            ``scene.waypoint_spacing`` apart (OmniGibson's convention).

        Returns
        -------
        waypoints : ndarray (N, 2) or None
            World (x, y) in metres.
        geodesic_distance : float or None
            Metres; ``(None, None)`` when the goal is not reachable from the start.
        """
        self._require_episode("get_shortest_path_to_goal()")
        if start_xy_pos is None:
            start_xy_pos = env.backend.get_pose(self._robot_idn)[0][:2]
        return env.scene.get_shortest_path(
            self._floor, start_xy_pos, self._goal_xy, entire_path=entire_path, robot=self._spec
        )

    def __repr__(self) -> str:
        return (
            f"PointNavigationTask(robot_idn={self._robot_idn}, floor={self._floor}, "
            f"reward_type={self._reward_type!r}, state={self._state.name})"
        )
