"""A task's configuration: one frozen, keyword-only value, checked when it is built.

:class:`TaskConfig` holds every constructor argument of
:class:`~pointnav_core.task.PointNavigationTask` but the term objects, normalised (positions
as ``(x, y)`` tuples, the quaternion unit length, the two config dicts merged over their
defaults and read-only). Every check goes through :mod:`pointnav_core.utils.validation`, so a
bool is not a number and a string is not a sequence of numbers; an invalid field raises a
``ValueError`` that starts with its name. The two settable task parameters
(``path_range``, ``max_steps``) are changed by building a new value with
:func:`dataclasses.replace`, which checks again.

:func:`merge_config` and :func:`compose_terms` are the two rules for what a user adds to
the defaults: config keys must be known ones, and a term named like a built-in one
replaces it in place while any other is appended.

Examples
--------
>>> config = TaskConfig(goal_tolerance=0.3, path_range=[1, 5])
>>> config.goal_tolerance, config.path_range
(0.3, (1.0, 5.0))
>>> TaskConfig(path_range="12")
Traceback (most recent call last):
...
pointnav_core.errors.ArgumentError: path_range must be None or (min, max) geodesic distances in metres, got '12'
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from typing import Any

from pointnav_core.errors import ArgumentError
from pointnav_core.utils import validation
from pointnav_core.utils.frozen import FrozenMapping

__all__ = ["REWARD_TYPES", "TaskConfig", "compose_terms", "merge_config"]

#: Valid values of ``reward_type``: the distance the potential reward is measured in.
REWARD_TYPES = ("l2", "geodesic")

# How far from 1 the norm of a fixed initial_quat may be (it is then normalised).
_QUAT_NORM_TOL = 1e-3


def _check_position(name: str, value: Any) -> tuple[float, float] | None:
    if value is None:
        return None
    try:
        arr = validation.vector(name, value, sizes=(2, 3))
    except ValueError:
        raise ArgumentError(
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
        raise ArgumentError(
            f"{name} must be None or a finite unit quaternion (x, y, z, w), got {value!r}"
        ) from None
    norm = math.sqrt(float(arr @ arr))
    if abs(norm - 1.0) > _QUAT_NORM_TOL:
        raise ArgumentError(
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
        raise ArgumentError(
            f"path_range must be None or (min, max) geodesic distances in metres, got {value!r}"
        ) from None
    if not (math.isfinite(lo) and lo >= 0.0 and hi > lo):  # hi may be inf; NaN fails
        raise ArgumentError(
            f"path_range must be (min, max) with 0 <= min < max (m), min finite, got {value!r}"
        )
    return float(lo), float(hi)


def _check_length(name: str, value: Any) -> float:
    return validation.real(name, value, minimum=0.0, unit="m")


def merge_config(
    name: str, defaults: Mapping[str, Any], overrides: Mapping[str, Any] | None
) -> Mapping[str, Any]:
    """Return ``defaults`` updated with ``overrides`` as a read-only mapping.

    Raises
    ------
    ValueError
        Naming ``name`` when ``overrides`` is not None or a dict, or has a key that
        ``defaults`` lacks (the valid keys are listed).

    Examples
    --------
    >>> dict(merge_config("reward_config", {"a": 1, "b": 2}, {"b": 3}))
    {'a': 1, 'b': 3}
    >>> merge_config("reward_config", {"a": 1}, {"c": 3})
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: reward_config has an unknown key 'c'; valid keys are ['a']
    """
    merged = dict(defaults)
    if overrides is None:
        return FrozenMapping(merged)
    if not isinstance(overrides, Mapping):
        raise ArgumentError(f"{name} must be None or a dict, got {overrides!r}")
    validation.known_keys(name, overrides, defaults)
    merged.update(overrides)
    return FrozenMapping(merged)


def compose_terms(kind: str, base: type, defaults: Sequence[Any], extra: Any) -> dict[str, Any]:
    """Return name -> term: ``defaults``, then ``extra`` by name.

    A term of ``extra`` named like a default replaces it in place; any other is appended.

    Parameters
    ----------
    kind : str
        The argument ``extra`` came from, named in errors.
    base : type
        The class every extra term must be an instance of.
    defaults : sequence
        The built-in terms, in order (each has a ``name``).
    extra : sequence or None
        The user's terms.

    Raises
    ------
    ValueError
        Naming ``kind`` when ``extra`` is not a sequence of ``base`` objects with
        distinct non-empty ``str`` names.
    """
    terms = {t.name: t for t in defaults}
    if extra is None:
        return terms
    if isinstance(extra, (str, bytes, Mapping)) or not isinstance(extra, Sequence):
        raise ArgumentError(f"{kind} must be None or a sequence of {base.__name__} objects, got {extra!r}")
    seen: set[str] = set()
    for term in extra:
        if not isinstance(term, base):
            raise ArgumentError(f"{kind} must hold {base.__name__} objects, got {term!r}")
        name = term.name
        if not isinstance(name, str) or not name:
            raise ArgumentError(f"{kind}: {term!r} must have a non-empty str name, got {name!r}")
        if name in seen:
            raise ArgumentError(f"{kind} has two terms named {name!r}")
        seen.add(name)
        terms[name] = term
    return terms


@dataclasses.dataclass(frozen=True, kw_only=True)
class TaskConfig:
    """The checked parameters of a :class:`~pointnav_core.task.PointNavigationTask`.

    The fields are the task's constructor arguments of the same names (units and meaning
    are documented there), normalised when the value is built: ``initial_pos`` and
    ``goal_pos`` become ``(x, y)`` tuples of floats (a z is dropped: the floor height
    replaces it), ``initial_quat`` a unit ``(x, y, z, w)`` tuple, ``path_range`` a
    ``(min, max)`` tuple, and ``termination_config`` / ``reward_config`` read-only
    mappings (merge them over the defaults first: :func:`merge_config`; None is an empty
    mapping).

    Raises
    ------
    ValueError
        For any invalid field, naming it; fields are checked in declaration order.
    """

    robot_idn: int = 0
    floor: int = 0
    initial_pos: Any = None
    initial_quat: Any = None
    goal_pos: Any = None
    goal_tolerance: float = 0.5
    goal_in_polar: bool = False
    path_range: Any = None
    visualize_goal: bool = False
    visualize_path: bool = False
    goal_height: float = 0.06
    waypoint_height: float = 0.05
    waypoint_width: float = 0.1
    n_vis_waypoints: int = 10
    reward_type: str = "l2"
    termination_config: Mapping[str, Any] | None = None
    reward_config: Mapping[str, Any] | None = None

    def __post_init__(self) -> None:
        set_ = object.__setattr__  # frozen: the normalised values replace the given ones
        set_(self, "robot_idn", validation.integer("robot_idn", self.robot_idn, minimum=0))
        set_(self, "floor", validation.integer("floor", self.floor, minimum=0))
        set_(self, "initial_pos", _check_position("initial_pos", self.initial_pos))
        set_(self, "initial_quat", _check_quat("initial_quat", self.initial_quat))
        set_(self, "goal_pos", _check_position("goal_pos", self.goal_pos))
        set_(self, "goal_tolerance", validation.goal_tolerance("goal_tolerance", self.goal_tolerance))
        set_(self, "goal_in_polar", validation.boolean("goal_in_polar", self.goal_in_polar))
        set_(self, "path_range", _check_path_range(self.path_range))
        set_(self, "visualize_goal", validation.boolean("visualize_goal", self.visualize_goal))
        set_(self, "visualize_path", validation.boolean("visualize_path", self.visualize_path))
        set_(self, "goal_height", _check_length("goal_height", self.goal_height))
        set_(self, "waypoint_height", _check_length("waypoint_height", self.waypoint_height))
        width = _check_length("waypoint_width", self.waypoint_width)
        if width == 0.0:
            raise ArgumentError(
                f"waypoint_width must be a finite number > 0 (m), got {self.waypoint_width!r}"
            )
        set_(self, "waypoint_width", width)
        set_(self, "n_vis_waypoints",
             validation.integer("n_vis_waypoints", self.n_vis_waypoints, minimum=1))
        if not isinstance(self.reward_type, str) or self.reward_type not in REWARD_TYPES:
            raise ArgumentError(
                f"reward_type must be one of {list(REWARD_TYPES)}, got {self.reward_type!r}"
            )
        for name in ("termination_config", "reward_config"):
            value = getattr(self, name)
            if value is None:
                value = {}
            if not isinstance(value, Mapping):
                raise ArgumentError(f"{name} must be None or a dict, got {value!r}")
            set_(self, name, value if isinstance(value, FrozenMapping) else FrozenMapping(value))
