"""Argument checks and space building shared by the single- and multi-robot environments.

:class:`~pointnav_core.envs.pointnav.PointNavEnv` and :class:`~pointnav_core.envs.multi_pointnav.MultiPointNavEnv`
take the same kinds of arguments (a robot spec or a dict of its fields, a task or a dict of
its arguments, an action frequency) and give a robot the same action and observation spaces,
so both build them here. ``name`` arguments say what to call the value in an error message
(``"robot"``, ``"task[2]"``, ``"action for robot_1"``).
"""

from __future__ import annotations

import copy
import dataclasses
import inspect
import math
import warnings
from collections import OrderedDict
from collections.abc import Mapping
from typing import Any

import numpy as np
from gymnasium import spaces

from pointnav_core import scenes
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.errors import ArgumentError
from pointnav_core.task import PointNavigationTask
from pointnav_core.utils import validation

__all__ = [
    "ROBOT_KEYS",
    "TASK_KEYS",
    "action_space",
    "add_sensors",
    "check_action",
    "check_action_frequency",
    "derives_path_range",
    "fit_path_range",
    "make_robot",
    "make_task",
    "observation_space",
    "step_length",
]

#: Keyword arguments of :class:`PointNavigationTask`, in signature order.
TASK_KEYS = tuple(inspect.signature(PointNavigationTask).parameters)
#: Task arguments holding term objects (copied for every task built from a dict).
TERM_KEYS = ("termination_conditions", "reward_functions", "observation_terms")
#: Fields of :class:`RobotSpec`, in declaration order.
ROBOT_KEYS = tuple(f.name for f in dataclasses.fields(RobotSpec))


def make_robot(robot: RobotSpec | Mapping[str, Any] | None, name: str = "robot") -> RobotSpec:
    """Return a :class:`RobotSpec` from a spec, a dict of its fields, or None (the default).

    Raises
    ------
    ValueError
        For an unknown key (naming it and the valid ones), an invalid field, or a value of
        another type.

    Examples
    --------
    >>> make_robot({"radius": 0.2}).radius
    0.2
    >>> make_robot({"size": 1})  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: robot has an unknown key 'size'; valid keys are ['radius', ...]
    """
    if robot is None:
        return RobotSpec()
    if isinstance(robot, RobotSpec):
        return robot
    if isinstance(robot, Mapping):
        validation.known_keys(name, robot, ROBOT_KEYS)
        return RobotSpec(**robot)
    raise ArgumentError(f"{name} must be a RobotSpec, a dict of its fields, or None, got {robot!r}")


def make_task(
    task: PointNavigationTask | Mapping[str, Any] | None,
    name: str = "task",
    **fixed: Any,
) -> PointNavigationTask:
    """Return a :class:`PointNavigationTask` from a task, a dict of its arguments, or None.

    Parameters
    ----------
    task : PointNavigationTask or dict or None
        The task itself, its keyword arguments, or None for the defaults.
    name : str
        What to call ``task`` in error messages.
    **fixed
        Arguments the caller sets itself (a multi-robot env sets ``robot_idn``); a dict that
        also gives one of them must give the same value.

    Examples
    --------
    >>> make_task({"goal_tolerance": 0.3}, robot_idn=2).robot_idn
    2
    >>> make_task({"robot_idn": 1}, name="task[0]", robot_idn=0)
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: task[0] sets robot_idn=1, but the environment sets robot_idn=0 for it
    """
    if task is None:
        return PointNavigationTask(**fixed)
    if isinstance(task, PointNavigationTask):
        for key, value in fixed.items():
            if getattr(task, key) != value:
                raise ArgumentError(
                    f"{name} has {key}={getattr(task, key)!r}, but the environment needs "
                    f"{key}={value!r} for it"
                )
        return task
    if isinstance(task, Mapping):
        validation.known_keys(name, task, TASK_KEYS)
        for key, value in fixed.items():
            if key in task and task[key] != value:
                raise ArgumentError(
                    f"{name} sets {key}={task[key]!r}, but the environment sets "
                    f"{key}={value!r} for it"
                )
        # Terms keep per-episode state: every task built from a dict gets its own copies
        # (a multi-robot env builds one task per robot from the same dict).
        args = {k: copy.deepcopy(v) if k in TERM_KEYS else v for k, v in task.items()}
        return PointNavigationTask(**{**args, **fixed})
    raise ArgumentError(
        f"{name} must be a PointNavigationTask, a dict of its arguments, or None, got {task!r}"
    )


def edit_task(task: Any, name: str, edit: Any, ready: str) -> Any:
    """``task`` (None, a dict of task arguments, a task, or a list of them) changed by
    ``edit(dict, name) -> dict``: each entry of a list (named ``name[i]``), and ``{}`` for
    None. A ready ``PointNavigationTask`` cannot change: a ValueError saying ``ready`` (with
    the name). Anything else is returned as it is, for ``make_task`` to name."""
    if isinstance(task, (list, tuple)):
        return [edit_task(entry, f"{name}[{i}]", edit, ready) for i, entry in enumerate(task)]
    if task is None:
        task = {}
    if isinstance(task, PointNavigationTask):
        raise ArgumentError(ready.format(name=name))
    if not isinstance(task, Mapping):
        return task
    return edit(task, name)


def add_sensors(task: Any, sensors: Mapping[str, Any] | None, name: str = "task") -> Any:
    """``task`` (None, a dict of task arguments, a task, or a list of them) with the terms
    of ``sensors`` (:func:`pointnav_core.sensors.make_sensors`) added to its
    ``observation_terms``, before any given there.

    Raises
    ------
    ValueError
        For a bad ``sensors`` config (naming the sensor or key), for a ready
        ``PointNavigationTask`` (its terms are fixed: pass a dict), or for a sensor the task
        dict already has among its ``observation_terms``.
    """
    from pointnav_core.sensors import make_sensors

    terms = make_sensors(sensors)
    if not terms:
        return task

    def edit(entry: Mapping[str, Any], where: str) -> dict[str, Any]:
        given = list(entry.get("observation_terms") or ())
        names = {getattr(term, "name", None) for term in given}
        for term in terms:
            if term.name in names:
                raise ArgumentError(
                    f"sensors turns on {term.name!r}, which {where}['observation_terms'] already has"
                )
        return {**entry, "observation_terms": [*terms, *given]}

    return edit_task(task, name, edit, (
        "sensors cannot be added to a ready PointNavigationTask ({name}): pass the task "
        "as a dict of its arguments, or put the sensor terms in its observation_terms"
    ))


def check_world_args(
    scene: Any, flatten_obs: Any, action_frequency: Any, backend_kwargs: Any
) -> tuple[scenes.Scene, float]:
    """Check the constructor arguments both envs share; return the scene and the frequency.

    ``scene`` None means the default generated house (``scenes.rooms(seed=0)``).
    """
    if not isinstance(flatten_obs, (bool, np.bool_)):
        raise ArgumentError(f"flatten_obs must be True or False, got {flatten_obs!r}")
    frequency = check_action_frequency(action_frequency)
    if scene is None:
        scene = scenes.rooms(seed=0)
    elif not isinstance(scene, scenes.Scene):
        raise ArgumentError(f"scene must be a pointnav_core Scene or None, got {scene!r}")
    if backend_kwargs is not None and not isinstance(backend_kwargs, Mapping):
        raise ArgumentError(f"backend_kwargs must be None or a dict, got {backend_kwargs!r}")
    return scene, frequency


#: Control rates (Hz) the envs accept: a control step of at most 10 s (a slower rate lets
#: a robot cross a house in one step) and at least 0.1 ms.
MIN_FREQUENCY, MAX_FREQUENCY = 0.1, 10_000.0


def check_action_frequency(action_frequency: Any) -> float:
    """Return ``action_frequency`` (Hz) as a float in ``[MIN_FREQUENCY, MAX_FREQUENCY]``,
    or raise ArgumentError (a ValueError) naming it."""
    return validation.real(
        "action_frequency", action_frequency, minimum=MIN_FREQUENCY, maximum=MAX_FREQUENCY, unit="Hz"
    )


#: Share of the robot's reach (the distance it covers driving straight at full speed for the
#: whole step limit) that a default episode's geodesic may take. The oracle needs more time
#: than the geodesic at full speed: it turns in place where no clear arc reaches its next
#: point. With half the reach (12.5 m by default) it timed out on 7 of 200 default episodes,
#: all over 10 m, needing up to 2.4x the geodesic's full-speed time there; with 0.4 (10 m)
#: it finished all 200 (``benchmarks/bench_default_episodes.py``).
SOLVABLE_SHARE = 0.4


#: Shortest default episode (m of geodesic), Habitat's minimum: shorter ones teach little
#: and are often won by chance in a few steps.
MIN_GEODESIC = 1.0


def derives_path_range(task: Any) -> bool:
    """Whether the env chooses the task's ``path_range``: the task was not given as an
    object and its dict (if any) sets no ``path_range``."""
    return task is None or (isinstance(task, Mapping) and "path_range" not in task)


def step_length(robot: RobotSpec, frequency: float, discrete: Any = None) -> float:
    """The farthest (m) one env step takes the robot: a control step at full speed, or a
    discrete action's ``forward_step``."""
    if discrete is not None:
        return float(discrete.forward_step)
    return robot.max_linear_velocity / frequency


def fit_path_range(
    task: PointNavigationTask,
    length: float,
    steps: int,
    derive: bool,
    name: str = "task",
) -> None:
    """Make the task's episodes drivable within ``steps`` env steps of at most ``length`` m.

    The robot's reach is ``steps * length`` metres (:func:`step_length`). With
    ``derive``, the task's ``path_range`` becomes ``(MIN_GEODESIC, max(SOLVABLE_SHARE *
    reach, MIN_GEODESIC + 1))``; otherwise a ``path_range`` whose maximum exceeds the reach
    gets a ``UserWarning``, as some of its episodes cannot be finished in time.
    """
    reach = steps * length
    if derive:
        task.path_range = (MIN_GEODESIC, max(SOLVABLE_SHARE * reach, MIN_GEODESIC + 1.0))
        return
    if task.path_range is not None and task.path_range[1] > reach:
        warnings.warn(
            f"{name}: path_range={task.path_range} allows start-goal geodesics up to "
            f"{task.path_range[1]:g} m, but in max_steps={steps} steps of at most "
            f"{length:g} m the robot drives at most {reach:.4g} m, so some episodes "
            f"cannot be solved; lower path_range or raise max_steps",
            UserWarning,
            stacklevel=_stacklevel_outside_package(),
        )


def _stacklevel_outside_package() -> int:
    """The ``stacklevel`` that points a warning at the first caller outside this package
    and the env libraries (``gymnasium.make`` may sit in between)."""
    here = inspect.currentframe()
    frame, level = (here.f_back if here is not None else None), 1
    while frame is not None and frame.f_globals.get("__name__", "").partition(".")[0] in _SKIPPED:
        frame, level = frame.f_back, level + 1
    return level


_SKIPPED = frozenset({"pointnav_core", "gymnasium", "pettingzoo"})


def action_space(robot: RobotSpec, discrete: Any = None) -> spaces.Space[Any]:
    """The robot's action space: a float32 ``Box`` in ``[-1, 1]`` of shape ``(action_dim,)``,
    or ``Discrete(discrete.n)`` for a :class:`~pointnav_core.task.actions.DiscreteActions` set."""
    if discrete is not None:
        return spaces.Discrete(discrete.n)
    return spaces.Box(-1.0, 1.0, (robot.action_dim,), dtype=np.float32)


def add_stop(task: Any, discrete: Any, name: str = "task") -> Any:
    """``task`` (as for :func:`add_sensors`) with the STOP success rule
    (:class:`~pointnav_core.task.actions.StopAtGoal` as its ``pointgoal`` condition) when the
    discrete action set ``discrete`` has STOP; unchanged otherwise.

    Raises
    ------
    ValueError
        For a ready ``PointNavigationTask`` whose ``pointgoal`` condition is not a
        ``StopAtGoal``.
    """
    from pointnav_core.task.actions import StopAtGoal

    if discrete is None or not discrete.stop:
        return task
    if isinstance(task, (list, tuple)):
        return [add_stop(entry, discrete, f"{name}[{i}]") for i, entry in enumerate(task)]
    if task is None:
        task = {}
    if isinstance(task, PointNavigationTask):
        if not isinstance(task.termination_conditions.get("pointgoal"), StopAtGoal):
            raise ArgumentError(
                f"{name} is a ready PointNavigationTask without the STOP rule: with discrete "
                f"actions and STOP, pass the task as a dict, or give it "
                f"termination_conditions=[StopAtGoal()]"
            )
        return task
    if not isinstance(task, Mapping):
        return task  # make_task names the problem
    given = list(task.get("termination_conditions") or ())
    if any(getattr(c, "name", None) == "pointgoal" for c in given):
        return task  # the caller chose its own success rule
    return {**task, "termination_conditions": [*given, StopAtGoal()]}


def observation_space(task: PointNavigationTask, flatten: bool) -> spaces.Space[Any]:
    """The task's observation space: a ``Dict`` of one ``Box`` per observation term, or
    the flat Box of them all end to end.

    ``task`` must have met its environment (:meth:`PointNavigationTask.load`).
    """
    layout = task.observation_layout
    low, high = task.observation_bounds
    if flatten:
        return spaces.Box(low, high, dtype=np.float32)
    # An OrderedDict keeps the terms' order (a plain dict would be sorted by key), so that
    # FlattenObservation gives the flat order too.
    boxes = OrderedDict()
    for name in layout.slices:
        lo, hi, shape, dtype = layout.space_bounds(name, low, high)
        boxes[name] = spaces.Box(lo, hi, shape, dtype=dtype)
    return spaces.Dict(boxes)


def check_action(
    action: Any, shape: tuple[int], drive: str, name: str = "action", *, finite: bool = True
) -> np.ndarray:
    """Return ``action`` as a float array of ``shape``, or raise ArgumentError (a ValueError) naming ``name``.

    A float ndarray of the right shape passes through as is (the per-step fast path);
    anything else is converted. Values outside ``[-1, 1]`` are kept (the backend clips
    them); NaN and infinity are rejected, unless ``finite`` is False: the envs leave that
    check to the backend's ``step``, which must reject such an action and move nothing
    (the conformance kit checks it), so that a step checks each value once.

    Examples
    --------
    >>> check_action([0.5, 2.0], (2,), "differential").tolist()
    [0.5, 2.0]
    >>> check_action([0.5], (2,), "differential", name="action for robot_1")
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: action for robot_1 must have shape (2,) for a differential drive, got shape (1,)
    """
    if not (type(action) is np.ndarray and action.shape == shape and action.dtype.kind == "f"):
        # Real numbers only: no strings ("1"), bools or complex values.
        raw = action
        if not isinstance(raw, (np.ndarray, list, tuple)) or not validation.is_real_array(raw):
            raise ArgumentError(
                f"{name} must be an array of {shape[0]} real numbers in [-1, 1], got {raw!r}"
            )
        action = np.asarray(raw, dtype=np.float64)
        if action.shape != shape:
            raise ArgumentError(
                f"{name} must have shape {shape} for a {drive} drive, got shape {action.shape}"
            )
    if finite:
        for value in action.tolist():
            if not -math.inf < value < math.inf:  # also False for NaN
                raise ArgumentError(f"{name} must be finite, got {action.tolist()}")
    return action
