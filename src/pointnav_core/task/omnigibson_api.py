"""The OmniGibson-compatible face of a task: its parameters, episode readings and queries.

:class:`OmniGibsonTaskAPI` is the read side of
:class:`~pointnav_core.task.PointNavigationTask`: the properties named like OmniGibson's
task attributes (``goal_tolerance``, ``path_range``, ``n_vis_waypoints``...), read from
the task's :class:`~pointnav_core.task.config.TaskConfig`; the episode readings the terms
use (``robot_xyz``, ``in_contact``, ``collisions``, ``potential``...), read from its
:class:`~pointnav_core.task.episode_state.EpisodeState`; and OmniGibson's query methods
(``get_goal_pos``, ``get_potential``, ``get_shortest_path_to_goal``...), with the
observations (``get_obs``, ``get_low_dim_obs``) built from the task's observation terms.
It changes nothing but the two settable parameters; the lifecycle (``load``, ``reset``,
``step``) lives in the task.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.errors import TaskStateError
from pointnav_core.task.lifecycle import ERROR, IDLE, ILLEGAL_HINT, TaskState
from pointnav_core.task.terminations import Timeout
from pointnav_core.utils import validation
from pointnav_core.utils.frozen import FrozenMapping

if TYPE_CHECKING:
    from pointnav_core.task import TaskEnv
    from pointnav_core.task.config import TaskConfig
    from pointnav_core.task.episode_state import EpisodeState
    from pointnav_core.task.markers import TaskMarkers, VisualMarker
    from pointnav_core.task.observations import (
        Frame,
        ObservationLayout,
        ObservationTerm,
    )
    from pointnav_core.task.rewards import RewardFunction
    from pointnav_core.task.terminations import TerminationCondition

__all__ = ["OmniGibsonTaskAPI"]


class OmniGibsonTaskAPI:
    """Parameters, episode readings and OmniGibson's queries of a task (a mixin).

    The class using it sets the attributes annotated below.
    """

    _config: TaskConfig
    _ep: EpisodeState
    _marks: TaskMarkers
    _state: TaskState
    _floor_height: float
    _spec: Any
    _idn: int
    _backend: Any
    _velocity_floats: Any
    _frame: Frame
    _obs_layout: ObservationLayout | None
    _observations: Mapping[str, ObservationTerm]
    _terminations: Mapping[str, TerminationCondition]
    _rewards: Mapping[str, RewardFunction]

    _bind: Callable[[Any], None]  # the task's backend binding, which get_obs may redo

    # ------------------------------------------------------------------ parameters
    @property
    def config(self) -> TaskConfig:
        """The task's checked parameters (frozen; see :mod:`~pointnav_core.task.config`)."""
        return self._config

    @property
    def robot_idn(self) -> int:
        """Index of the robot this task drives."""
        return self._config.robot_idn

    @property
    def floor(self) -> int:
        """Floor the task navigates on."""
        return self._config.floor

    @property
    def initial_pos(self) -> NDArray[np.float64] | None:
        """The fixed start (x, y, z) in metres with z = 0 until loaded, or None (sampled)."""
        xy = self._config.initial_pos
        return None if xy is None else np.array((*xy, self._floor_height))

    @property
    def initial_quat(self) -> NDArray[np.float64] | None:
        """The fixed start orientation (x, y, z, w), or None (random heading)."""
        quat = self._config.initial_quat
        return None if quat is None else np.array(quat)

    @property
    def goal_pos(self) -> NDArray[np.float64] | None:
        """The fixed goal (x, y, z) in metres, or None (sampled); see :meth:`get_goal_pos`."""
        xy = self._config.goal_pos
        return None if xy is None else np.array((*xy, self._floor_height))

    @property
    def goal_tolerance(self) -> float:
        """Success radius (m)."""
        return self._config.goal_tolerance

    @property
    def goal_in_polar(self) -> bool:
        """Whether the goal observation is (rho, phi)."""
        return self._config.goal_in_polar

    @property
    def path_range(self) -> tuple[float, float] | None:
        """(min, max) geodesic of sampled start/goal pairs (m), or None; settable, used
        from the next reset (the envs set it to what the robot can drive in time)."""
        return self._config.path_range

    @path_range.setter
    def path_range(self, value: tuple[float, float] | None) -> None:
        self._config = dataclasses.replace(self._config, path_range=value)
        self._marks.config = self._config

    @property
    def max_steps(self) -> int:
        """Steps after which the episode is truncated (``termination_config["max_steps"]``);
        settable, used from the next step (``gymnasium.make(max_episode_steps=...)`` sets it)."""
        return int(self._config.termination_config["max_steps"])

    @max_steps.setter
    def max_steps(self, value: int) -> None:
        steps = validation.integer("max_steps", value, minimum=1)
        merged = FrozenMapping({**self._config.termination_config, "max_steps": steps})
        self._config = dataclasses.replace(self._config, termination_config=merged)
        self._marks.config = self._config
        current = self._terminations.get("timeout")
        if isinstance(current, Timeout):
            current.max_steps = steps

    @property
    def visualize_goal(self) -> bool:
        """Whether renderers draw the start and goal markers."""
        return self._config.visualize_goal

    @property
    def visualize_path(self) -> bool:
        """Whether renderers draw the shortest path's waypoint markers."""
        return self._config.visualize_path

    @property
    def goal_height(self) -> float:
        """Goal marker height (m)."""
        return self._config.goal_height

    @property
    def waypoint_height(self) -> float:
        """Waypoint marker height (m)."""
        return self._config.waypoint_height

    @property
    def waypoint_width(self) -> float:
        """Waypoint marker radius (m)."""
        return self._config.waypoint_width

    @property
    def n_vis_waypoints(self) -> int:
        """Number of waypoint markers."""
        return self._config.n_vis_waypoints

    @property
    def reward_type(self) -> str:
        """``"l2"`` or ``"geodesic"``."""
        return self._config.reward_type

    @property
    def termination_config(self) -> Mapping[str, Any]:
        """The merged termination configuration (read-only)."""
        return self._config.termination_config  # type: ignore[return-value]

    @property
    def reward_config(self) -> Mapping[str, Any]:
        """The merged reward configuration (read-only)."""
        return self._config.reward_config  # type: ignore[return-value]

    @property
    def termination_conditions(self) -> Mapping[str, TerminationCondition]:
        """Name -> termination condition, in evaluation order (read-only mapping)."""
        return self._terminations

    @property
    def reward_functions(self) -> Mapping[str, RewardFunction]:
        """Name -> reward function, in evaluation order (read-only mapping)."""
        return self._rewards

    @property
    def markers(self) -> tuple[VisualMarker, ...]:
        """The markers this task shows now, as :class:`~pointnav_core.task.markers.VisualMarker`.

        In order: the ``start`` and ``goal`` markers (radius ``goal_tolerance``, at
        ``goal_height`` above the floor) when ``visualize_goal``, then ``n_vis_waypoints``
        ``waypoint`` markers (radius ``waypoint_width``, at ``waypoint_height``) when
        ``visualize_path``, placed along the shortest path from the robot to the goal at
        reset and after every step (spacing and hiding rules:
        :func:`~pointnav_core.task.markers.place_waypoints`; all hidden when the robot has no
        path to the goal). Empty when both flags are off, and until a reset succeeds.
        Markers are data for renderers: nothing collides with them.
        """
        return self._marks.markers

    # ------------------------------------------------------------------ episode readings
    @property
    def state(self) -> TaskState:
        """Where the task is in its lifecycle."""
        return self._state

    @property
    def robot_xyz(self) -> tuple[float, float, float]:
        """Robot position (m) at the last reset or step, refreshed before the conditions run."""
        return self._ep.robot_xyz

    @property
    def in_contact(self) -> bool:
        """Whether the robot touched an obstacle or another robot in this step (backend's word)."""
        return self._ep.in_contact

    @property
    def floor_height(self) -> float:
        """Height (m) of the task's floor (0.0 until the task has met an env)."""
        return self._floor_height

    @property
    def goal_xy(self) -> tuple[float, float] | None:
        """This episode's goal (x, y) in metres (None before the first reset of a sampled goal)."""
        return self._ep.goal_xy

    @property
    def potential(self) -> float:
        """Potential (m) at the last reset or step: the distance the potential reward uses."""
        return self._ep.potential

    @property
    def distance_to_goal(self) -> float:
        """Geodesic distance (m) from the robot to the goal at the last reset or step
        (``inf`` where none is defined, e.g. over void); ``info["distance_to_goal"]``."""
        return self._ep.distance_to_goal

    @property
    def potential_metric(self) -> str:
        """``"l2"`` or ``"geodesic"``: the potential's metric this episode (fixed at reset)."""
        return self._ep.metric

    @property
    def termination_results(self) -> Mapping[str, tuple[bool, bool]]:
        """Name -> ``(done, success)`` of every condition at this step (read it, don't write)."""
        return self._ep.results

    @property
    def geodesic_dist(self) -> float:
        """Geodesic distance (m) from this episode's start to the goal; ``inf`` if unreachable."""
        return self._ep.geodesic_dist

    @property
    def path_length(self) -> float:
        """Planar distance (m) driven in this episode, including the last step."""
        return self._ep.path_length

    @property
    def collisions(self) -> int:
        """Steps with a contact in this episode."""
        return self._ep.collisions

    @property
    def episode_length(self) -> int:
        """Steps taken in this episode."""
        return self._ep.steps

    @property
    def success(self) -> bool:
        """Whether the episode has ended in success."""
        return self._ep.success

    @property
    def goal_field(self) -> Any:
        """This episode's goal field (None before the first reset)."""
        return self._ep.field

    # ------------------------------------------------------------------ observations
    def _obs_values(self, env: TaskEnv) -> list[float]:
        """Every observation term's values at this step, in order, clipped to the bounds."""
        backend = env.backend
        if backend is not self._backend:
            self._bind(backend)
        frame = self._frame
        if self._velocity_floats is not None:
            vx, vy, vz, wx, wy, wz = self._velocity_floats(self._idn)
            frame.lin_vel, frame.ang_vel = (vx, vy, vz), (wx, wy, wz)
        else:
            lin, ang = backend.get_velocity(self._idn)
            frame.lin_vel, frame.ang_vel = tuple(lin.tolist()), tuple(ang.tolist())
        # The pose recorded at the last reset or step: the one the metrics saw.
        ep = self._ep
        x, y, z = ep.robot_xyz
        frame.set_pose(x, y, z, ep.robot_quat)
        frame.goal_x, frame.goal_y = ep.goal_xy  # type: ignore[misc]
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
        return self._loaded_layout("observation_layout")

    @property
    def observation_bounds(self) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
        """``(low, high)`` of every observation value in flat order, float32 arrays.

        With the built-in terms (see :mod:`~pointnav_core.task.observations`): the goal lies
        within the floor's diagonal plus 1 m (``rho`` in ``[0, that]`` and ``phi`` in
        ``[-pi, pi]`` when polar); linear velocities within ``sqrt(2) * max_linear_velocity``
        and angular ones within ``max_angular_velocity``. Observations are clipped to these
        bounds (a falling robot's vertical speed can exceed them).

        Raises
        ------
        TaskStateError
            Before the task has met an environment (:meth:`load`).
        """
        layout = self._loaded_layout("observation_bounds")
        return np.array(layout.low, dtype=np.float32), np.array(layout.high, dtype=np.float32)

    def _loaded_layout(self, what: str) -> ObservationLayout:
        if self._obs_layout is None:
            raise TaskStateError(f"{what} needs an environment: call load(env) first")
        return self._obs_layout

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

    # ------------------------------------------------------------------ OmniGibson queries
    def _require_episode(self, what: str) -> None:
        if self._state is IDLE or self._state is ERROR:
            raise TaskStateError(
                f"{what} needs an episode, but the task is {self._state.name}: "
                f"{ILLEGAL_HINT[self._state]}"
            )

    def get_goal_pos(self) -> NDArray[np.float64] | None:
        """Return this episode's goal (x, y, z) in metres, z the floor height (fresh array).

        Before the first reset: the fixed goal, or None when the goal is sampled.
        """
        xy = self._ep.goal_xy
        return None if xy is None else np.array((*xy, self._floor_height))

    def get_start_pos(self) -> NDArray[np.float64] | None:
        """Return this episode's start (x, y, z) in metres (None before the first reset)."""
        xy = self._ep.start_xy
        return None if xy is None else np.array((*xy, self._floor_height))

    def get_current_pos(self, env: TaskEnv) -> NDArray[np.float64]:
        """Return the robot's current position (x, y, z) in metres (fresh array)."""
        pos, _ = env.backend.get_pose(self._config.robot_idn)
        return np.array(pos, dtype=np.float64)

    def get_potential(self, env: TaskEnv) -> float:
        """Return the potential (m) at the robot's current position.

        The xy L2 distance to the goal, or the geodesic distance when ``reward_type`` is
        ``"geodesic"`` and the goal is reachable (``potential_metric``).
        """
        self._require_episode("get_potential()")
        x, y, _ = env.backend.get_pose(self._config.robot_idn)[0].tolist()
        ep = self._ep
        return ep.potential_at(x, y, ep.field_distance(x, y), ep.potential)

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
        geodesic_distance : float
            Metres; ``(None, math.inf)`` when the goal is not reachable from the start.
        """
        self._require_episode("get_shortest_path_to_goal()")
        if start_xy_pos is None:
            start_xy_pos = env.backend.get_pose(self._config.robot_idn)[0][:2]
        return env.scene.get_shortest_path(
            self._config.floor, start_xy_pos, self._ep.goal_xy, entire_path=entire_path,
            robot=self._spec,
        )
