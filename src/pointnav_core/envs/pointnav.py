"""The single-robot Gymnasium environment ``pointnav_core/PointNav-v0``."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from pointnav_core import scenes
from pointnav_core.backends.protocol import Backend, make_backend
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.envs import _crowd
from pointnav_core.envs import common as _envcommon
from pointnav_core.envs.config import EnvConfig, takes_config
from pointnav_core.errors import ArgumentError
from pointnav_core.floor.maps import BoundedCache
from pointnav_core.task import PointNavigationTask
from pointnav_core.task.actions import check_discrete_action, make_discrete_actions

__all__ = ["PointNavEnv", "TaskStepLimit"]


class PointNavEnv(gym.Env[Any, np.ndarray]):
    """
    ## Description

    Point-goal navigation on a 2D floor map, without a physics engine: a disc-shaped robot
    must drive to a goal position, OmniGibson's `PointNavigationTask` re-implemented on
    traversability maps. The scene's floors have free floor, obstacles and void (holes the
    robot falls into); a kinematic backend integrates the robot's drive exactly and resolves
    contacts by sliding. The goal is given relative to the robot, so the agent must learn to
    steer towards it and around obstacles. By default the scene is a generated house
    (`scenes.rooms(seed=0)`: rooms, doors and furniture).

    ## Action Space

    The action is a `ndarray` of `float32` in `[-1, 1]`, scaled by the robot's maxima
    (`RobotSpec.max_linear_velocity`, 0.5 m/s, and `max_angular_velocity`, 1.5 rad/s) and
    held for one control step of `1 / action_frequency` s:

    | Num | Action (differential drive, shape `(2,)`) | Unit at 1 |
    |-----|-------------------------------------------|-----------|
    | 0   | forward speed                             | m/s       |
    | 1   | yaw rate (positive turns left)            | rad/s     |

    A holonomic robot (`RobotSpec(drive="holonomic")`) takes `(vx, vy, w)`, shape `(3,)`.
    Values outside `[-1, 1]` are clipped; NaN, infinity or a wrong shape raise `ValueError`.

    With `action_space="discrete"` the action is an integer, `Discrete(4)` (Habitat's
    actions; `pointnav_core.task.actions`):

    | Num | Action         | What the robot does                                          |
    |-----|----------------|--------------------------------------------------------------|
    | 0   | `MOVE_FORWARD` | drives `forward_step` m straight ahead (default 0.25)        |
    | 1   | `TURN_LEFT`    | turns in place by `turn_angle` rad (default 10 deg)          |
    | 2   | `TURN_RIGHT`   | turns in place by `-turn_angle`                              |
    | 3   | `STOP`         | stands still one control step and ends the episode           |

    Each runs as velocity commands over the fewest control steps the robot's top speeds
    allow (MOVE_FORWARD: 5 steps at 0.5 m/s; a turn: 2 steps), and ends early at a contact,
    which counts as one collision. `discrete_actions={"forward_step": ..., "turn_angle":
    ..., "stop": False}` changes them; without STOP the action space is `Discrete(3)`.

    ## Observation Space

    A `Dict` of one `float32` array per observation term (`pointnav_core.task.observations`;
    the table is generated from the terms), in the robot's frame (+x ahead, +y to the left).
    `D` is the diagonal of the task's floor plus 1 m, `v` is `sqrt(2)` times the robot's
    `max_linear_velocity` and `w` its `max_angular_velocity`:

    | Num | Key              | Observation                                    | Min | Max |
    |-----|------------------|------------------------------------------------|-----|-----|
    | 0   | `xy_pos_to_goal` | goal x relative to the robot (m)               | -D  | D   |
    | 1   | `xy_pos_to_goal` | goal y relative to the robot (m)               | -D  | D   |
    | 2   | `robot_lin_vel`  | linear velocity x (m/s)                        | -v  | v   |
    | 3   | `robot_lin_vel`  | linear velocity y (m/s)                        | -v  | v   |
    | 4   | `robot_lin_vel`  | linear velocity z (m/s, negative when falling) | -v  | v   |
    | 5   | `robot_ang_vel`  | angular velocity x (rad/s)                     | -w  | w   |
    | 6   | `robot_ang_vel`  | angular velocity y (rad/s)                     | -w  | w   |
    | 7   | `robot_ang_vel`  | angular velocity z, the yaw rate (rad/s)       | -w  | w   |

    With `goal_in_polar=True` in the task, indices 0 and 1 are the distance `rho` in
    `[0, D]` m and the bearing `phi` in `[-pi, pi]` rad (0 dead ahead, positive to the
    left). Values are clipped to these bounds (only a fall's vertical speed reaches them).
    With `flatten_obs=True` the observation is OmniGibson's flat `low_dim` vector: a `Box`
    of shape `(8,)` holding the numbers in the order of the table.

    Sensors (`pointnav_core.sensors`), turned on with `sensors={"scan": {...},
    "local_map": {...}}`, add their own keys after these, in this order whatever the order
    of the dict, and their values follow the eight above in the flat vector:

    | Key         | Shape, dtype                   | Values                                  |
    |-------------|--------------------------------|-----------------------------------------|
    | `scan`      | `(n_rays,)` float32            | range (m) along each ray, in `[0, max_range]`, in the order of `RangeScan.angles` (rad, robot frame, 0 ahead, positive left) |
    | `local_map` | `(cells, cells)` uint8 or float32 | the floor around the robot, heading up: 0 free, 1 obstacle, 2 void or off the map, 3 another robot; row by row in the flat vector |

    `scan` arguments: `n_rays` (64), `fov` (2 pi rad), `min_range` (0.05 m: a nearer
    return reads `max_range`), `max_range` (5.6 m), `noise_std` (0 m) and `dropout` (0).
    Rays see the floor's obstacle cells and polygons, the map's edge and the other robots;
    VOID (a hole) is not seen. Noise is seeded by `reset(seed=...)`. `local_map` arguments:
    `size` (5.0 m), `cells` (32), `dtype` (`"uint8"`). A bad sensor name, key or value
    raises `ValueError` naming it.

    ## Rewards

    The sum of these terms, reported in `info["reward_breakdown"]`:

    - `potential`: `r_potential * (previous potential - current potential)` (default 1.0
      per metre), the potential being the xy distance to the goal (`reward_type="l2"`) or
      the geodesic distance (`"geodesic"`);
    - `collision`: `-r_collision` (default 0.1) on every step the robot touches an obstacle;
    - `pointgoal`: `r_pointgoal` (default 10.0) on the step the goal is reached;
    - `slack`, only when `reward_config={"r_slack": c}` with `c > 0`: `-c` on every step,
      Habitat's time cost (not OmniGibson's; the default 0.0 leaves no `slack` key).

    ## Starting State

    The robot starts at rest at a point drawn uniformly from the free space its disc fits
    in, with a heading uniform in `[0, 2 pi)`; the goal is drawn uniformly from the part of
    the floor connected to the start, at least `goal_tolerance` away and within the task's
    `path_range` of geodesic distance. Both can be fixed instead (`initial_pos`,
    `initial_quat`, `goal_pos` in the task). All of it comes from the seed passed to
    `reset`.

    Every default episode can be finished in time: unless the task is given as an object
    or its dict sets `path_range`, the env sets `path_range = (1, 0.4 R)` m, where the reach
    `R = max_steps * max_linear_velocity / action_frequency` is the distance the robot
    drives straight at full speed in the step limit (25 m by default, so geodesics from
    1 m, as in Habitat, up to 10 m); the rest is time to turn. An explicit
    `path_range` beyond `R` warns.

    ## Episode End

    The episode ends if any one of the following occurs:

    1. Termination (success): the robot's centre is closer than `goal_tolerance` (0.5 m)
       to the goal (xy). With discrete actions and STOP: the robot calls STOP; a success
       within `goal_tolerance`, a failure otherwise (Habitat's rule).
    2. Termination: the robot has touched something on more than `max_collisions` (500)
       steps.
    3. Termination: the robot fell: its height dropped more than `fall_height` (0.03 m)
       below its floor (it drove over void).
    4. Truncation: the episode reached `max_steps` (500) steps; `gymnasium.make(...,
       max_episode_steps=N)` sets it to `N` (as does setting `env.max_episode_steps`).

    When the step limit coincides with another end, both `terminated` and `truncated` are
    True. Stepping after the end raises `TaskStateError`: call `reset`.

    `info` holds `success`, `done`, `spl`, `soft_spl`, `path_length`, `geodesic_dist`,
    `distance_to_goal`, `collisions`, `reward_breakdown`, `termination_conditions`,
    `episode_length` and `potential_metric` after every step (and at reset).

    ## Arguments

    ```python
    >>> import gymnasium as gym
    >>> from pointnav_core.envs.pointnav import PointNavEnv
    >>> env = PointNavEnv(task={"reward_type": "geodesic", "goal_tolerance": 0.3})
    >>> obs, info = env.reset(seed=0)
    >>> sorted(obs), obs["xy_pos_to_goal"].dtype
    (['robot_ang_vel', 'robot_lin_vel', 'xy_pos_to_goal'], dtype('float32'))
    >>> obs, reward, terminated, truncated, info = env.step(np.zeros(2, dtype=np.float32))
    >>> type(reward), terminated, truncated, info["episode_length"]
    (<class 'float'>, False, False, 1)

    ```

    | Parameter          | Type                         | Default           | Description          |
    |--------------------|------------------------------|-------------------|----------------------|
    | `scene`            | **Scene**                    | `scenes.rooms(0)` | floors to navigate   |
    | `robot`            | **RobotSpec** or **dict**    | `RobotSpec()`     | radius, speeds, drive|
    | `task`             | **PointNavigationTask**/dict | `{}`              | task or its arguments|
    | `backend`          | **str**, class or instance   | `"kinematic"`     | the world simulator  |
    | `backend_kwargs`   | **dict** or `None`           | `None`            | backend's arguments  |
    | `render_mode`      | **str** or `None`            | `None`            | `"rgb_array"` or None|
    | `flatten_obs`      | **bool**                     | `False`           | flat `(8,)` `low_dim`|
    | `action_frequency` | **float**                    | `10.0`            | 0.1 to 10,000 Hz     |
    | `sensors`          | **dict** or `None`           | `None`            | `scan`, `local_map`  |
    | `action_space`     | **str**                      | `"continuous"`    | or `"discrete"`      |
    | `discrete_actions` | **dict** or `None`           | `None`            | step, angle, STOP    |
    | `pedestrians`      | **dict** or `None`           | `None`            | a crowd (see below)  |
    | `config`           | **EnvConfig** or `None`      | `None`            | all of the above but |
    |                    |                              |                   | scene, render_mode   |

    `config` (:class:`~pointnav_core.envs.config.EnvConfig`, read from YAML or JSON with
    `EnvConfig.load`) gives `robot`, `task` (with its `max_steps`), `backend`,
    `flatten_obs`, `action_frequency`, `sensors`, `action_space` and `discrete_actions`;
    giving one of those beside it is a `ValueError` naming it. The batched engine and the
    multi-robot env take the same config and give the same spaces.

    ```python
    >>> env = PointNavEnv(sensors={"scan": {"n_rays": 32}}, action_space="discrete")
    >>> obs, info = env.reset(seed=0)
    >>> obs["scan"].shape, env.action_space
    ((32,), Discrete(4))
    >>> obs, reward, terminated, truncated, info = env.step(0)  # MOVE_FORWARD
    >>> round(info["path_length"], 6)
    0.25

    ```

    ## Pedestrians

    `pedestrians={"count": 10}` (or `{"density": 1 / 8}`, pedestrians per m² of free floor,
    iGibson's social navigation density) puts a crowd on the robot's floor at every reset
    (`pointnav_core.crowds`): discs of `radius` m (default a range, `(0.2, 0.3)`, drawn per
    pedestrian) that walk at `speed` m/s (`(0.5, 1.0)`) along the scene's exact shortest
    paths between goals drawn on their part of the floor, with `behaviour` `"orca"`
    (the default: RVO2's ORCA among the pedestrians and, with `sees_robots=True`, the
    robot), `"social_force"` (pysocialforce's model), `"static"` or a callable. They start
    clear of the walls, the robot and each other, never enter a wall, and are drawn from
    the reset's seed; `starts` and `goals` fix them (`pointnav_core.crowds.presets`), and a
    dataset episode that records a crowd places exactly it (with the default settings in an
    env built without `pedestrians`; `pointnav_core.datasets.format`). The scan and the local
    map (code 4) see them and `render()` draws them, grey with a heading tick. The robot is
    not pushed by them: a step on which its disc overlaps a pedestrian's adds one to
    `info["pedestrian_collisions"]` (not to `collisions`), and with
    `end_on_collision=True` ends the episode as a failure (`"pedestrian_collision"` in
    `termination_conditions`). At the episode's end `info["social"]` holds its social
    metrics (`pointnav_core.task.social_metrics`, defined in `docs/social_metrics.md`): PSC,
    STL, the minimum distance, time in personal space, minimum time-to-collision, path
    irregularity, and speed, acceleration and jerk, over every control step.

    ```python
    >>> env = PointNavEnv(pedestrians={"count": 5, "end_on_collision": True})
    >>> obs, info = env.reset(seed=0)
    >>> env.crowd.positions.shape, info["pedestrian_collisions"]
    ((5, 2), 0)

    ```

    ## Version History

    * v0: Initial version; range scan and local map sensors, and discrete actions with
      STOP, added as options (the defaults are unchanged).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    @takes_config()
    def __init__(
        self,
        scene: scenes.Scene | None = None,
        robot: RobotSpec | Mapping[str, Any] | None = None,
        task: PointNavigationTask | Mapping[str, Any] | None = None,
        backend: str | type | Backend = "kinematic",
        backend_kwargs: Mapping[str, Any] | None = None,
        render_mode: str | None = None,
        flatten_obs: bool = False,
        action_frequency: float = 10.0,
        sensors: Mapping[str, Any] | None = None,
        action_space: str = "continuous",
        discrete_actions: Mapping[str, Any] | None = None,
        pedestrians: Mapping[str, Any] | None = None,
        config: EnvConfig | None = None,
    ) -> None:
        #: The :class:`~pointnav_core.envs.config.EnvConfig` this env was built from, or None.
        self.config = config
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ArgumentError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, "
                f"got {render_mode!r}"
            )
        scene, frequency = _envcommon.check_world_args(
            scene, flatten_obs, action_frequency, backend_kwargs
        )
        self.robot = _envcommon.make_robot(robot)
        self._derive_path_range = _envcommon.derives_path_range(task)
        self.discrete_actions = make_discrete_actions(action_space, discrete_actions)
        #: The pedestrians (:class:`~pointnav_core.crowds.Crowd`), or None without them.
        self.crowd = self._own_crowd = _crowd.make_crowd(pedestrians, scene)
        self._touched, self._pedestrian_steps = False, 0
        self._track: _crowd.CrowdTrack | None = None
        self._robots: _crowd.CrowdRobots | None = None
        task = _envcommon.add_stop(_envcommon.add_sensors(task, sensors), self.discrete_actions)
        task = _crowd.add_pedestrian_termination(task, self.crowd)
        self.task = _envcommon.make_task(task)
        self.scene = scene
        self.robots = (self.robot,)
        self.render_mode = render_mode
        self._renderers = BoundedCache(2)  # floor pictures prepared for render()
        self.flatten_obs = bool(flatten_obs)
        self.action_frequency = frequency
        self._fit_path_range()
        self.backend = make_backend(backend, **dict(backend_kwargs or {}))
        self.backend.load(scene, self.robots, frequency)
        # Fails here, naming the parameter, if the task does not fit this scene and robot.
        self.task.load(self)
        self._idn = self.task.robot_idn

        self._action_shape = (self.robot.action_dim,)
        self.action_space = _envcommon.action_space(self.robot, self.discrete_actions)
        self._plan = (
            None if self.discrete_actions is None
            else self.discrete_actions.commands(self.robot, frequency)
        )
        self.observation_space = _envcommon.observation_space(self.task, self.flatten_obs)

    # ------------------------------------------------------------------ Gymnasium API
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        """Start a new episode; the same ``seed`` gives the same episode.

        ``options={"episode": episode}`` plays a dataset episode (its start, orientation and
        goal, and its recorded crowd if it has one, with the env's pedestrian settings or
        the defaults; see :mod:`pointnav_core.datasets.playback`); other options are not used.
        """
        super().reset(seed=seed)
        if options is not None and not isinstance(options, Mapping):
            raise ArgumentError(f"options must be None or a dict, got {options!r}")
        self.backend.reset()
        episode = (options or {}).get("episode")
        info = self.task.reset(self, episode=episode)
        # An episode's recorded crowd is placed as recorded, in an env without pedestrians too.
        record = getattr(episode, "pedestrians", None)
        self.crowd = _crowd.episode_crowd(self._own_crowd, record, self.scene)
        if self.crowd is not None:
            _crowd.spawn_crowd(self, record)
            self._touched, self._pedestrian_steps = False, 0
            self._track, self._robots = _crowd.CrowdTrack(self), _crowd.CrowdRobots(self)
            info["pedestrian_collisions"] = 0
        return self._get_obs(), info

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Apply ``action`` for one control step; see the class docstring for the rest."""
        self.task.check_step()  # before anything moves: an illegal step changes nothing
        if self._plan is not None:
            return self._step_discrete(action)
        action = self._check_action(action)
        self.backend.step({self._idn: action})
        if self.crowd is None:
            reward, terminated, truncated, info = self.task.step(self, action)
            return self._get_obs(), reward, terminated, truncated, info
        contact = self._step_crowd()
        reward, terminated, truncated, info = self.task.step(self, action)
        return self._get_obs(), reward, terminated, truncated, self._count_contact(info, contact)

    def render(self) -> NDArray[np.uint8] | None:
        """Return a top-down RGB image (H, W, 3) uint8 when ``render_mode="rgb_array"``."""
        if self.render_mode is None:
            gym.logger.warn(
                "You are calling render method without specifying any render mode. "
                'You can specify the render_mode at initialization, e.g. '
                'gymnasium.make("pointnav_core/PointNav-v0", render_mode="rgb_array")'
            )
            return None
        # Imported here: drawing is only needed when rendering.
        from pointnav_core.render.recording import render_env

        return render_env(self, renderers=self._renderers)

    def close(self) -> None:
        """Release the backend's resources (if it holds any)."""
        close = getattr(self.backend, "close", None)
        if callable(close):
            close()

    @property
    def max_episode_steps(self) -> int:
        """The task's step limit (``max_steps``); setting it also refits a derived
        ``path_range``. ``gymnasium.make(..., max_episode_steps=N)`` sets it to ``N``."""
        return self.task.max_steps

    @max_episode_steps.setter
    def max_episode_steps(self, value: int) -> None:
        self.task.max_steps = value
        self._fit_path_range()

    # ------------------------------------------------------------------ helpers
    def _fit_path_range(self) -> None:
        _envcommon.fit_path_range(
            self.task,
            _envcommon.step_length(self.robot, self.action_frequency, self.discrete_actions),
            self.task.max_steps,
            self._derive_path_range,
        )

    def _step_discrete(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """One discrete action: its command for its control steps, ending at a contact
        (:mod:`pointnav_core.task.actions`)."""
        index = check_discrete_action(action, len(self._plan))  # type: ignore[arg-type]
        command, steps = self._plan[index]  # type: ignore[index]
        idn, backend = self._idn, self.backend
        contact = touched = False
        for _ in range(steps):
            backend.step({idn: command})
            if self.crowd is not None:
                touched = self._step_crowd() or touched
            if backend.in_contact(idn):
                contact = True
                break
        self._touched = touched
        reward, terminated, truncated, info = self.task.step(self, index, contact=contact)
        if self.crowd is None:
            return self._get_obs(), reward, terminated, truncated, info
        return self._get_obs(), reward, terminated, truncated, self._count_contact(info, touched)

    def pedestrian_contact(self, idn: int) -> bool:
        """Whether robot ``idn`` touched a pedestrian during the last step (for
        :class:`~pointnav_core.task.terminations.PedestrianCollision`)."""
        return bool(self._touched) and idn == self._idn

    def _step_crowd(self) -> bool:
        """Move the pedestrians one control step beside the robot; whether they touch it."""
        _, robots, velocities = self._robots.read(self)  # type: ignore[union-attr]
        # One call steps the crowd and finds its contacts (one compiled call for ORCA).
        contacts = self.crowd.step_contacts(1.0 / self.action_frequency, robots, velocities)  # type: ignore[union-attr]
        self._touched = touched = bool(contacts.any())  # none when the robot left the floor
        self._track.record(self, self._robots.poses[self._idn])  # type: ignore[union-attr]
        return touched

    def _count_contact(self, info: dict[str, Any], touched: bool) -> dict[str, Any]:
        self._pedestrian_steps += int(touched)
        info["pedestrian_collisions"] = self._pedestrian_steps
        if info["done"]:
            info["social"] = self._track.metrics(self, info)
        return info

    def _check_action(self, action: Any) -> Any:
        # Finiteness is the backend's check: a rejected step moves nothing (conformance).
        return _envcommon.check_action(action, self._action_shape, self.robot.drive, finite=False)

    def _get_obs(self) -> Any:
        if self.flatten_obs:
            return self.task.get_low_dim_obs(self)
        return self.task.get_obs(self)



class TaskStepLimit(gym.Wrapper[Any, np.ndarray, Any, np.ndarray], gym.utils.RecordConstructorArgs):
    """Hands the step limit of a ``TimeLimit`` below it to the :class:`PointNavEnv` it wraps.

    The registered ids add it after ``gymnasium.make``'s ``TimeLimit``, so that
    ``gymnasium.make("pointnav_core/PointNav-v0", max_episode_steps=1000)`` sets the task's
    own ``max_steps`` (and the derived ``path_range``) rather than leaving the task to end
    episodes at its default 500. Without a ``TimeLimit`` below it, it changes nothing.
    """

    def __init__(self, env: gym.Env[Any, np.ndarray]) -> None:
        gym.utils.RecordConstructorArgs.__init__(self)
        gym.Wrapper.__init__(self, env)
        inner: Any = env
        while isinstance(inner, gym.Wrapper):
            if isinstance(inner, gym.wrappers.TimeLimit):
                # TimeLimit keeps its limit only privately: its spec shows the limit only
                # when the env it wraps has a spec, which a directly built env has not.
                limit = inner._max_episode_steps  # noqa: SLF001
                config = getattr(env.unwrapped, "config", None)
                if config is not None and limit != config.max_steps:
                    raise ArgumentError(
                        f"max_episode_steps={limit} given beside config, which sets "
                        f"max_steps={config.max_steps}: change the config instead"
                    )
                env.unwrapped.max_episode_steps = limit
                break
            inner = inner.env
