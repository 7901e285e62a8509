"""One env configuration: what a policy was trained with, saved and reused.

An :class:`EnvConfig` holds everything that decides an env's observation and action
spaces and its episodes' rules: the sensors, the action space (continuous, or Habitat's
discrete actions with or without STOP), the robot, the backend, the task's settings, the
step limit ``max_steps`` (counted in actions, as Habitat counts them), ``flatten_obs`` and
the control rate. It is a frozen value that writes and reads YAML or JSON, so the config a
policy was trained with can travel with it and rebuild the same envs:

- ``gymnasium.make("pointnav_core/PointNav-v0", config=cfg)`` or ``PointNavEnv(config=cfg)``;
- ``parallel_env(config=cfg, n_robots=3)`` (each robot gets the config's robot and task);
- ``VectorPointNavEnv(num_envs=64, config=cfg)`` (kinematic backend, flat observations);
- ``pointnav eval --env-config FILE``.

The keyword is ``config``, as in Habitat (``habitat.Env(config=...)``). Beside it an env
takes the arguments the config does not hold (``scene``, ``render_mode``, ``num_envs``,
``seed``, ...); an argument the config holds (``robot``, ``task``, ``sensors``, ...) given
as well is refused, naming it: change the config instead, with ``dataclasses.replace``.

Examples
--------
>>> cfg = EnvConfig(sensors={"scan": {"n_rays": 16}}, action_space="discrete",
...                 discrete_actions={"stop": False}, max_steps=150)
>>> EnvConfig.from_dict(cfg.to_dict()) == cfg
True
>>> cfg.to_dict()["sensors"], cfg.robot.radius
({'scan': {'n_rays': 16}}, 0.18)
>>> EnvConfig(max_step=150)
Traceback (most recent call last):
...
TypeError: EnvConfig.__init__() got an unexpected keyword argument 'max_step'
>>> EnvConfig.from_dict({"max_step": 150})  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
pointnav_core.errors.ArgumentError: env config has an unknown key 'max_step'; valid keys are ['robot', ...]
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import json
import math
import os
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.errors import ArgumentError
from pointnav_core.utils import validation
from pointnav_core.utils.frozen import FrozenMapping

__all__ = ["CONFIG_FORMATS", "EnvConfig", "multi_robot_arguments", "read_config_file", "takes_config",
           "vector_arguments", "vector_fleet_arguments"]

#: File suffixes :meth:`EnvConfig.load` and :meth:`EnvConfig.save` read and write.
CONFIG_FORMATS = (".yaml", ".yml", ".json")
# Task arguments a config cannot hold: term objects do not serialise, and the env sets
# robot_idn itself.
_NOT_IN_TASK = ("robot_idn", "termination_conditions", "reward_functions", "observation_terms")


def _plain(name: str, value: Any) -> Any:
    """``value`` as frozen JSON-like data (FrozenMapping, tuple, str, int, float, bool,
    None); ValueError naming ``name`` for anything else (term objects, arrays)."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    if validation.is_real(value):
        number = value.item() if isinstance(value, np.generic) else value
        if isinstance(number, float) and not math.isfinite(number):
            raise ArgumentError(f"{name} must be a finite number, got {value!r}")
        return number
    if isinstance(value, Mapping):
        for key in value:
            if not isinstance(key, str):
                raise ArgumentError(f"{name} must have string keys, got {key!r}")
        return FrozenMapping({k: _plain(f"{name}[{k!r}]", v) for k, v in value.items()})
    if isinstance(value, (list, tuple)):
        return tuple(_plain(f"{name}[{i}]", v) for i, v in enumerate(value))
    raise ArgumentError(
        f"{name} must hold only numbers, strings, booleans, None, lists and dicts (what YAML "
        f"and JSON store), got {value!r}"
    )


def _thaw(value: Any) -> Any:
    """Frozen data as plain dicts and lists (what ``json.dump`` and ``yaml.safe_dump`` take)."""
    if isinstance(value, Mapping):
        return {k: _thaw(v) for k, v in value.items()}
    if isinstance(value, tuple):
        return [_thaw(v) for v in value]
    return value


def _check_task(task: Mapping[str, Any]) -> None:
    from pointnav_core.envs.common import TASK_KEYS
    from pointnav_core.task import PointNavigationTask

    validation.known_keys("task", task, [k for k in TASK_KEYS if k not in _NOT_IN_TASK])
    if "max_steps" in (task.get("termination_config") or {}):
        raise ArgumentError(
            "task['termination_config'] sets max_steps; give it as the config's own max_steps "
            "field (actions per episode)"
        )
    try:
        PointNavigationTask(**_thaw(task))  # the task's own checks, naming the parameter
    except ValueError as err:
        raise ArgumentError(f"task: {err}") from None


@dataclasses.dataclass(frozen=True, kw_only=True)
class EnvConfig:
    """What an env is built from, besides its scene: a frozen, serialisable value.

    Parameters
    ----------
    robot : RobotSpec or dict
        Radius (m), top speeds (m/s, rad/s) and drive; default ``RobotSpec()``.
    sensors : dict, optional
        Sensor name -> its arguments, as the envs' ``sensors`` (``{"scan": {"n_rays": 64}}``,
        ``"local_map"``); None or ``{}``: no sensors.
    action_space : {"continuous", "discrete"}
        Velocity commands in ``[-1, 1]``, or Habitat's discrete actions.
    discrete_actions : dict, optional
        ``forward_step`` (m), ``turn_angle`` (rad), ``stop`` (bool); discrete actions only.
    task : dict, optional
        ``PointNavigationTask`` keyword arguments (``goal_tolerance``, ``goal_in_polar``,
        ``reward_type``, ``path_range``, ``reward_config``, ``termination_config`` without
        ``max_steps``, ...); no term objects and no ``robot_idn``.
    max_steps : int
        Steps per episode, >= 1: actions, whether continuous or discrete (default 500).
    flatten_obs : bool
        The flat ``Box`` observation (default True: what MLP policies and the batched engine
        take), or the ``Dict`` of the single env.
    action_frequency : float
        Control rate (Hz), from 0.1 to 10,000 (default 10).
    backend : str
        A registered backend name (default ``"kinematic"``).
    pedestrians : dict, optional
        The crowd, as the envs' ``pedestrians`` (:mod:`pointnav_core.crowds.config`; a
        callable behaviour cannot be saved); None: no pedestrians. The single and the
        multi-robot envs take it, and the batched engine
        (:mod:`pointnav_core.vector.crowd`: ORCA or static crowds).

    Raises
    ------
    ValueError
        For a bad field, naming it (``sensors['scan']: n_rays must be ...``).
    """

    robot: RobotSpec = dataclasses.field(default_factory=RobotSpec)
    sensors: Mapping[str, Any] = dataclasses.field(default_factory=lambda: FrozenMapping())
    action_space: str = "continuous"
    discrete_actions: Mapping[str, Any] | None = None
    task: Mapping[str, Any] = dataclasses.field(default_factory=lambda: FrozenMapping())
    max_steps: int = 500
    flatten_obs: bool = True
    action_frequency: float = 10.0
    backend: str = "kinematic"
    pedestrians: Mapping[str, Any] | None = None

    def __post_init__(self) -> None:
        from pointnav_core.backends.protocol import available_backends
        from pointnav_core.crowds import make_pedestrians
        from pointnav_core.envs.common import check_action_frequency, make_robot
        from pointnav_core.sensors import make_sensors
        from pointnav_core.task.actions import make_discrete_actions

        set_ = object.__setattr__  # frozen: the checked, normalised values replace the given ones
        set_(self, "robot", make_robot(self.robot))
        sensors = _plain("sensors", {} if self.sensors is None else self.sensors)
        make_sensors(sensors)  # names a bad sensor, key or value
        # None and {} both mean "the sensor's defaults": one form, so equal configs compare equal.
        set_(self, "sensors", FrozenMapping({k: v or FrozenMapping() for k, v in sensors.items()}))
        discrete = _plain("discrete_actions", self.discrete_actions)
        make_discrete_actions(self.action_space, discrete)
        set_(self, "discrete_actions", discrete)
        task = _plain("task", {} if self.task is None else self.task)
        _check_task(task)
        set_(self, "task", task)
        set_(self, "max_steps", validation.integer("max_steps", self.max_steps, minimum=1))
        set_(self, "flatten_obs", validation.boolean("flatten_obs", self.flatten_obs))
        set_(self, "action_frequency", check_action_frequency(self.action_frequency))
        if not isinstance(self.backend, str) or self.backend not in available_backends():
            raise ArgumentError(f"backend must be one of {available_backends()}, got {self.backend!r}")
        pedestrians = _plain("pedestrians", self.pedestrians)
        make_pedestrians(_thaw(pedestrians))  # names a bad key or value
        set_(self, "pedestrians", pedestrians)

    def __hash__(self) -> int:
        return hash(json.dumps(self.to_dict(), sort_keys=True))

    # ------------------------------------------------------------------ data
    def to_dict(self) -> dict[str, Any]:
        """The config as plain dicts, lists, strings and numbers (``json.dumps`` takes it);
        :meth:`from_dict` gives back an equal config."""
        out = {f.name: _thaw(getattr(self, f.name)) for f in dataclasses.fields(self)}
        out["robot"] = dataclasses.asdict(self.robot)
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], name: str = "env config") -> EnvConfig:
        """The config of a dict (:meth:`to_dict`'s, or a YAML or JSON file's); missing keys
        take their defaults. ValueError for an unknown key or a bad value, naming it."""
        if not isinstance(data, Mapping):
            raise ArgumentError(f"{name} must be a mapping of its fields, got {data!r}")
        validation.known_keys(name, data, [f.name for f in dataclasses.fields(cls)])
        return cls(**data)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> EnvConfig:
        """Read a config from a ``.yaml``/``.yml`` or ``.json`` file.

        Raises
        ------
        ValueError
            For another suffix, a file that is not valid YAML or JSON, or a bad config;
            the message names the file.
        OSError
            For a file that cannot be read.
        """
        path = os.fspath(path)
        data = read_config_file(path)
        try:
            return cls.from_dict(data)
        except ValueError as err:
            raise ArgumentError(f"env config {path!r}: {err}") from None

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the config as YAML (``.yaml``/``.yml``) or JSON (``.json``), atomically."""
        from pointnav_core.utils.outputs import atomic_writer

        path = os.fspath(path)
        suffix = _suffix(path)
        if suffix == ".json":
            text = json.dumps(self.to_dict(), indent=2) + "\n"
        else:
            import yaml

            text = yaml.safe_dump(self.to_dict(), sort_keys=False)
        with atomic_writer(path, "w", encoding="utf-8") as fh:
            fh.write(text)

    # ------------------------------------------------------------------ env arguments
    def task_arguments(self) -> dict[str, Any]:
        """The task's keyword arguments, with ``max_steps`` in its ``termination_config``."""
        task = _thaw(self.task)
        task["termination_config"] = {**task.get("termination_config", {}), "max_steps": self.max_steps}
        return task

    def env_arguments(self) -> dict[str, Any]:
        """The :class:`~pointnav_core.envs.pointnav.PointNavEnv` keyword arguments of this config."""
        out = {
            "robot": self.robot,
            "task": self.task_arguments(),
            "backend": self.backend,
            "flatten_obs": self.flatten_obs,
            "action_frequency": self.action_frequency,
            "sensors": _thaw(self.sensors) or None,
            "action_space": self.action_space,
            "discrete_actions": _thaw(self.discrete_actions),
        }
        if self.pedestrians is not None:
            out["pedestrians"] = _thaw(self.pedestrians)
        return out


def _suffix(path: str, what: str = "env config") -> str:
    suffix = os.path.splitext(path)[1].lower()
    if suffix not in CONFIG_FORMATS:
        raise ArgumentError(f"{what} {path!r} must be a {', '.join(CONFIG_FORMATS)} file")
    return suffix


def read_config_file(path: str | os.PathLike[str], what: str = "env config") -> Any:
    """The data of a ``.yaml``/``.yml`` (``yaml.safe_load``) or ``.json`` file.

    Raises
    ------
    ValueError
        For another suffix or a file that is not valid YAML or JSON, naming ``what`` and
        the file.
    OSError
        For a file that cannot be read.
    """
    path = os.fspath(path)
    suffix = _suffix(path, what)
    import yaml

    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    try:
        return json.loads(text) if suffix == ".json" else yaml.safe_load(text)
    except (ValueError, yaml.YAMLError) as err:  # json.JSONDecodeError is a ValueError
        kind = "JSON" if suffix == ".json" else "YAML"
        raise ArgumentError(f"{what} {path!r} is not valid {kind}: {err}") from None


#: What each engine does with the config's fields: None if they become constructor
#: arguments as they are, or a function (config, explicitly given arguments) -> arguments.
_Adapt = Callable[[EnvConfig, Mapping[str, Any]], dict[str, Any]]


def takes_config(adapt: _Adapt | None = None, extra: tuple[str, ...] = ()) -> Callable[[Any], Any]:
    """Decorate an env's ``__init__`` so that ``config=EnvConfig(...)`` supplies its
    arguments (:meth:`EnvConfig.env_arguments`, then ``adapt``).

    The arguments the config supplies, and ``extra``, must not be given beside it: that is
    a ValueError naming them (the config is the one place that says how the env is built).
    ``__init__`` keeps its own ``config`` parameter, for its signature and documentation.
    """

    def wrap(init: Any) -> Any:
        signature = inspect.signature(init)

        @functools.wraps(init)
        def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
            config = kwargs.get("config")
            if config is None:
                return init(self, *args, **kwargs)
            if not isinstance(config, EnvConfig):
                raise ArgumentError(f"config must be an EnvConfig or None, got {config!r}")
            given = signature.bind(self, *args, **kwargs).arguments
            supplied = config.env_arguments() if adapt is None else adapt(config, given)
            clash = [k for k in (*supplied, *extra) if k in given]
            if clash:
                raise ArgumentError(
                    f"{', '.join(clash)} given beside config, which sets "
                    f"{'it' if len(clash) == 1 else 'them'}: change the config instead "
                    f"(dataclasses.replace(config, ...))"
                )
            given.pop("self")
            return init(self, **{**given, **supplied})

        return __init__

    return wrap


def multi_robot_arguments(config: EnvConfig, given: Mapping[str, Any]) -> dict[str, Any]:
    """:func:`~pointnav_core.envs.multi_pointnav.parallel_env`'s arguments: every robot gets the
    config's robot and task, and ``max_cycles`` is the config's ``max_steps`` unless given."""
    out = config.env_arguments()
    if "max_cycles" not in given:
        out["max_cycles"] = config.max_steps
    return out


def vector_arguments(config: EnvConfig, given: Mapping[str, Any]) -> dict[str, Any]:
    """:class:`~pointnav_core.vector.VectorPointNavEnv`'s arguments. The batched engine
    reproduces the kinematic backend and gives flat observations: a config with another
    backend or ``flatten_obs=False`` is a ValueError naming the field."""
    out = config.env_arguments()
    if out.pop("backend") != "kinematic":
        raise ArgumentError(
            f"config.backend is {config.backend!r}, but the batched engine reproduces the "
            f"'kinematic' backend only"
        )
    if not out.pop("flatten_obs"):
        raise ArgumentError("config.flatten_obs is False, but the batched engine's observations are flat: set it True")
    return out


def vector_fleet_arguments(config: EnvConfig, given: Mapping[str, Any]) -> dict[str, Any]:
    """The batched multi-robot engine's arguments: :func:`vector_arguments`, with
    ``max_cycles`` the config's ``max_steps`` unless given (as :func:`multi_robot_arguments`)."""
    out = vector_arguments(config, given)
    if "max_cycles" not in given:
        out["max_cycles"] = config.max_steps
    return out
