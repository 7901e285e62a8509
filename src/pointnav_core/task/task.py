"""The point-goal navigation task: OmniGibson's ``PointNavigationTask`` as a state machine.

:class:`PointNavigationTask` owns one robot's episode: it samples a start and a goal,
lands the robot, and after every control step measures progress, decides whether the
episode is over (:mod:`~pointnav_core.task.terminations`), pays rewards
(:mod:`~pointnav_core.task.rewards`) and reports metrics (:mod:`~pointnav_core.task.metrics`). It
never moves anything itself: the environment steps the backend, then calls
:meth:`PointNavigationTask.step`.

The task orchestrates parts that each live in their own module:

=====================================  ==================================================
module                                 part
=====================================  ==================================================
:mod:`~pointnav_core.task.lifecycle`        states, events and the transition table
:mod:`~pointnav_core.task.config`      the frozen, checked configuration; term composition
:mod:`~pointnav_core.task.sampling`         episode sampling, with a goal-constraint hook
:mod:`~pointnav_core.task.episode_state`    the per-step snapshot every term reads, and ``info``
:mod:`~pointnav_core.task.observations`     observation terms, their frame and layout
:mod:`~pointnav_core.task.markers`          the start, goal and waypoint markers
:mod:`~pointnav_core.task.omnigibson_api`         the OmniGibson-compatible properties and queries
:mod:`~pointnav_core.task.task_env`         what the task reads of the env; the termination pass
=====================================  ==================================================

Lifecycle
---------
The task is a small state machine (h11 style, :mod:`~pointnav_core.task.lifecycle`): its states
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

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

from numpy.typing import ArrayLike

from pointnav_core.backends.protocol import float_twin
from pointnav_core.errors import ArgumentError
from pointnav_core.task.config import (
    TaskConfig,
    compose_terms,
    merge_config,
)
from pointnav_core.task.episode_state import EpisodeState
from pointnav_core.task.lifecycle import IDLE, allows, move
from pointnav_core.task.lifecycle import Event as _Event
from pointnav_core.task.markers import TaskMarkers
from pointnav_core.task.observations import (
    Frame,
    ObservationLayout,
    ObservationTerm,
    default_observation_terms,
)
from pointnav_core.task.omnigibson_api import OmniGibsonTaskAPI
from pointnav_core.task.rewards import (
    CollisionReward,
    PointGoalReward,
    PotentialReward,
    RewardFunction,
    SlackReward,
)
from pointnav_core.task.sampling import GoalConstraint, sample_task_episode
from pointnav_core.task.task_env import TaskEnv, check_fits, evaluate_terminations
from pointnav_core.task.terminations import (
    Falling,
    MaxCollision,
    PointGoal,
    TerminationCondition,
    Timeout,
)
from pointnav_core.utils.frozen import FrozenMapping

__all__ = ["PointNavigationTask"]


class PointNavigationTask(OmniGibsonTaskAPI):
    """Drive robot ``robot_idn`` to a goal position on floor ``floor``.

    A faithful, bug-fixed port of OmniGibson's ``PointNavigationTask`` (same parameters,
    rewards, terminations, observations and metrics) that runs on any
    :class:`~pointnav_core.backends.protocol.Backend`.

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
        Extra :class:`~pointnav_core.task.terminations.TerminationCondition`,
        :class:`~pointnav_core.task.rewards.RewardFunction` and
        :class:`~pointnav_core.task.observations.ObservationTerm` objects. One named like a
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
    pointnav_core.errors.ArgumentError: reward_type must be one of ['l2', 'geodesic'], got 'manhattan'
    """

    #: Attempts at sampling a valid start and goal before :class:`SamplingError`.
    max_trials: ClassVar[int] = 100

    #: Termination defaults (read-only; pass ``termination_config`` to override).
    default_termination_config: ClassVar[Mapping[str, Any]] = FrozenMapping(
        {"max_collisions": 500, "max_steps": 500, "fall_height": 0.03}
    )
    #: Reward defaults (read-only; pass ``reward_config`` to override).
    default_reward_config: ClassVar[Mapping[str, Any]] = FrozenMapping(
        {"r_potential": 1.0, "r_collision": 0.1, "r_pointgoal": 10.0, "r_slack": 0.0}
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
        config = TaskConfig(
            robot_idn=robot_idn, floor=floor, initial_pos=initial_pos,
            initial_quat=initial_quat, goal_pos=goal_pos, goal_tolerance=goal_tolerance,
            goal_in_polar=goal_in_polar, path_range=path_range,
            visualize_goal=visualize_goal, visualize_path=visualize_path,
            goal_height=goal_height, waypoint_height=waypoint_height,
            waypoint_width=waypoint_width, n_vis_waypoints=n_vis_waypoints,
            reward_type=reward_type,
        )
        # Merged over the class's defaults (a subclass may change them), then checked.
        self._config = dataclasses.replace(
            config,
            termination_config=merge_config(
                "termination_config", self.default_termination_config, termination_config
            ),
            reward_config=merge_config("reward_config", self.default_reward_config, reward_config),
        )
        try:
            terminations = dict(self._create_termination_conditions())
        except ValueError as err:
            raise ArgumentError(f"termination_config: {err}") from None
        try:
            rewards = dict(self._create_reward_functions())
        except ValueError as err:
            raise ArgumentError(f"reward_config: {err}") from None
        terminations = compose_terms("termination_conditions", TerminationCondition, list(terminations.values()), termination_conditions)
        rewards = compose_terms("reward_functions", RewardFunction, list(rewards.values()), reward_functions)
        observations = compose_terms(
            "observation_terms", ObservationTerm,
            default_observation_terms(self._config.goal_in_polar), observation_terms,
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
        self._idn = self._config.robot_idn  # read on every step
        # Bound at the first meeting with an env (load): caches for the per-step path.
        self._env: Any = None
        self._spec: Any = None
        # The backend last stepped with, and its float twins of get_pose / get_velocity
        # (None: read the protocol methods); see backend.float_twin.
        self._backend: Any = None
        self._pose_floats: Any = None
        self._velocity_floats: Any = None
        self._floor_height = 0.0
        self._ep = EpisodeState(goal_xy=self._config.goal_pos)
        # Touched only when visualize_goal or visualize_path is on.
        self._marks = TaskMarkers(self._config)
        self._show_markers = self._config.visualize_goal or self._config.visualize_path

    # ------------------------------------------------------------------ composition
    def _create_termination_conditions(self) -> dict[str, TerminationCondition]:
        """Build the termination conditions, in evaluation order (override to change them)."""
        cfg = self._config.termination_config
        conditions: list[TerminationCondition] = [
            MaxCollision(max_collisions=cfg["max_collisions"]),
            Timeout(max_steps=cfg["max_steps"]),
            Falling(fall_height=cfg["fall_height"]),
            PointGoal(goal_tolerance=self._config.goal_tolerance),
        ]
        return {c.name: c for c in conditions}

    def _create_reward_functions(self) -> dict[str, RewardFunction]:
        """Build the reward functions, in evaluation order (override to change them)."""
        cfg = self._config.reward_config
        rewards: list[RewardFunction] = [
            PotentialReward(r_potential=cfg["r_potential"]),
            CollisionReward(r_collision=cfg["r_collision"]),
            PointGoalReward(r_pointgoal=cfg["r_pointgoal"]),
        ]
        slack = SlackReward(r_slack=cfg["r_slack"])  # checked even when 0
        if slack.r_slack > 0:  # Habitat's time cost; without it the task is OmniGibson's
            rewards.append(slack)
        return {r.name: r for r in rewards}

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
        scene = env.scene
        spec = check_fits(self._config, env)
        floor = self._config.floor
        self._spec = spec
        self._floor_height = self._marks.floor_height = float(scene.get_floor_height(floor))
        self._marks.spacing = float(scene.waypoint_spacing)
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
            :mod:`~pointnav_core.task.sampling`.
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
            marks = self._marks
            marks.clear()
            if env is not self._env:
                self.load(env)
            self._bind(env.backend)  # every episode: a backend patched since is seen
            sampled = sample_task_episode(
                env, self._config, spec=self._spec, floor_height=self._floor_height,
                max_trials=self.max_trials, goal_constraint=goal_constraint, given=episode,
            )
            # The robot stands at the start: it was landed there in the accepted trial.
            pos, quat = env.backend.get_pose(self._idn)
            ep = self._ep
            ep.begin(sampled, self._config.reward_type, tuple(pos.tolist()), quat.tolist(),
                     self._terminations)
            for condition in self._terminations.values():
                condition.reset(self, env)
            for reward in self._rewards.values():
                reward.reset(self, env)
            for term in self._observations.values():
                term.reset(self, env)
            if self._show_markers:
                x, y, _ = ep.robot_xyz
                marks.place(ep.start_xy, ep.goal_xy, ep.field, x, y)  # type: ignore[arg-type]
        except BaseException:
            self._move(_Event.FAIL)
            raise
        self._move(_Event.RESET)
        return ep.info(
            False,
            False,
            {name: 0.0 for name in self._rewards},
            {name: {"done": False, "success": False} for name in self._terminations},
        )

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
            idn = self._idn
            if self._pose_floats is not None:
                x, y, z, *quat = self._pose_floats(idn)
            else:
                pos, orientation = backend.get_pose(idn)
                x, y, z = pos.tolist()
                quat = orientation.tolist()
            contact = bool(backend.in_contact(idn)) if contact is None else bool(contact)
            ep = self._ep
            ep.advance(x, y, z, quat, contact)

            results, conditions, done, success, terminated, truncated = evaluate_terminations(
                self._termination_items, self, env, action
            )
            ep.results = results
            ep.success = success

            breakdown: dict[str, float] = {}
            for name, fn in self._reward_items:
                breakdown[name] = fn.step(self, env, action)
            reward = sum(breakdown.values(), 0.0)  # the sum a user gets from the breakdown
            info = ep.info(success, done, breakdown, conditions)
            if self._config.visualize_path:
                self._marks.move_waypoints(ep.field, x, y)
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

    def __repr__(self) -> str:
        return (
            f"PointNavigationTask(robot_idn={self._idn}, floor={self._config.floor}, "
            f"reward_type={self._config.reward_type!r}, state={self._state.name})"
        )

