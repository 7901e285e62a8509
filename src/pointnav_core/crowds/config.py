"""What a crowd of pedestrians is: how many, how large, how fast, how they decide.

:class:`PedestrianConfig` is the ``pedestrians={...}`` argument of the envs, checked once:

==================  ===============  ===========================================================
key                 default          what
==================  ===============  ===========================================================
``count``           (one of the two)  pedestrians per episode, an integer >= 0
``density``         (one of the two)  pedestrians per m² of the floor's free area, >= 0
``radius``          ``(0.2, 0.3)``   disc radius (m): a number, or a ``(min, max)`` range drawn
                                     uniformly per pedestrian
``speed``           ``(0.5, 1.0)``   preferred walking speed (m/s): a number or a range
``behaviour``       ``"orca"``       ``"orca"``, ``"social_force"``, ``"static"`` or a callable
``sees_robots``     ``True``         whether pedestrians avoid the robots
``end_on_collision`` ``False``       whether touching a pedestrian ends the robot's episode
``orca``            RVO2's/iGibson's ``neighbor_dist`` 5 m, ``max_neighbors`` 10,
                                     ``time_horizon`` 2 s (iGibson's social navigation task)
``starts``          drawn            fixed starts ``[[x, y], ...]`` (m), one per pedestrian
                                     (then ``count`` may be left out)
``goals``           drawn            fixed goals per pedestrian ``[[[x, y], ...], ...]`` (m),
                                     walked in turn, round and round
==================  ===============  ===========================================================

Fixed starts and goals make a scenario repeat exactly (:mod:`pointnav_core.crowds.presets`);
they are plain lists, so an :class:`~pointnav_core.envs.config.EnvConfig` saves them.

A callable behaviour is called once per control step with a :class:`CrowdView` and returns
the pedestrians' new velocities, shape ``(P, 2)`` (m/s); the crowd clips them to each
pedestrian's speed and keeps them off the walls as it does ORCA's.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.utils import validation

__all__ = ["BEHAVIOURS", "PATH_MARGIN", "CrowdView", "PedestrianConfig", "make_pedestrians"]

#: The built-in behaviours.
BEHAVIOURS = ("orca", "social_force", "static")

#: How much farther from the walls (m) the crowd's paths run than its largest radius needs.
PATH_MARGIN = 0.05

_KEYS = ("count", "density", "radius", "speed", "behaviour", "sees_robots", "end_on_collision", "orca", "starts", "goals")
_ORCA_DEFAULTS = {"neighbor_dist": 5.0, "max_neighbors": 10, "time_horizon": 2.0}


class CrowdView(NamedTuple):
    """What a callable behaviour sees at a step (arrays are copies; units m, m/s, s).

    ``positions``, ``velocities`` and ``preferred`` are ``(P, 2)``: the pedestrians' centres,
    current velocities and the velocities toward their next waypoints at their preferred
    speeds. ``radius`` and ``speed`` are ``(P,)``. ``robots`` is ``(M, 3)`` discs ``(x, y,
    radius)`` of the robots the pedestrians see and ``robot_velocities`` ``(M, 2)``.
    """

    positions: NDArray[np.float64]
    velocities: NDArray[np.float64]
    preferred: NDArray[np.float64]
    radius: NDArray[np.float64]
    speed: NDArray[np.float64]
    robots: NDArray[np.float64]
    robot_velocities: NDArray[np.float64]
    dt: float


def _range(name: str, value: Any, unit: str, strict: bool) -> tuple[float, float]:
    """A number or a ``(min, max)`` pair as a ``(min, max)`` of finite numbers > 0."""
    if isinstance(value, (list, tuple)) and len(value) == 2:
        lo = validation.real(f"{name}[0]", value[0], minimum=0.0, strict=strict, unit=unit)
        hi = validation.real(f"{name}[1]", value[1], minimum=0.0, strict=strict, unit=unit)
        if hi < lo:
            raise ArgumentError(f"{name} must be a number or a (min, max) pair with min <= max ({unit}), got {value!r}")
        return lo, hi
    if isinstance(value, (list, tuple)):
        raise ArgumentError(f"{name} must be a number or a (min, max) pair ({unit}), got {value!r}")
    number = validation.real(name, value, minimum=0.0, strict=strict, unit=unit)
    return number, number


@dataclasses.dataclass(frozen=True)
class PedestrianConfig:
    """The crowd of an env, checked (see the module notes for every field)."""

    count: int | None = None
    density: float | None = None
    radius: tuple[float, float] = (0.2, 0.3)
    speed: tuple[float, float] = (0.5, 1.0)
    behaviour: str | Callable[[CrowdView], Any] = "orca"
    sees_robots: bool = True
    end_on_collision: bool = False
    neighbor_dist: float = 5.0
    max_neighbors: int = 10
    time_horizon: float = 2.0
    starts: tuple[tuple[float, float], ...] | None = None
    goals: tuple[tuple[tuple[float, float], ...], ...] | None = None

    def number(self, free_area: float) -> int:
        """Pedestrians per episode on a floor of ``free_area`` m² (``density`` rounds to
        the nearest integer, halves up)."""
        if self.count is not None:
            return self.count
        return math.floor(float(self.density or 0.0) * free_area + 0.5)

    @property
    def plan_radius(self) -> float:
        """The radius the crowd's paths keep from the walls (m): the largest of the range
        plus :data:`PATH_MARGIN`, so one planner per floor serves the whole crowd, and a
        pedestrian pushed a little off its path still clears the walls."""
        return self.radius[1] + PATH_MARGIN


def make_pedestrians(value: Any, name: str = "pedestrians") -> PedestrianConfig | None:
    """``value`` (None, a dict of the keys above, or a :class:`PedestrianConfig`) checked.

    Raises
    ------
    ValueError
        Naming the key: an unknown key, both or neither of ``count`` and ``density``, a
        negative density, a bad range, an unknown behaviour.
    """
    if value is None or isinstance(value, PedestrianConfig):
        return value
    if not isinstance(value, Mapping):
        raise ArgumentError(f"{name} must be None or a dict of {list(_KEYS)}, got {value!r}")
    validation.known_keys(name, value, _KEYS)
    starts = _points(f"{name}['starts']", value["starts"]) if value.get("starts") is not None else None
    if starts is not None and "count" not in value and "density" not in value:
        value = {**value, "count": len(starts)}
    if ("count" in value) == ("density" in value):
        raise ArgumentError(f"{name} needs exactly one of 'count' (pedestrians) and 'density' (pedestrians per m²), got {dict(value)!r}")
    count = density = None
    if starts is not None and value.get("count") != len(starts):
        raise ArgumentError(f"{name}['count'] must be the number of starts ({len(starts)}) when 'starts' is given, got {value.get('count')!r}")
    goals = None
    if value.get("goals") is not None:
        raw = value["goals"]
        if not isinstance(raw, (list, tuple)) or (starts is not None and len(raw) != len(starts)) or (
            starts is None and "count" in value and len(raw) != value["count"]
        ):
            raise ArgumentError(f"{name}['goals'] must be a list of one goal list per pedestrian, got {raw!r}")
        goals = tuple(_points(f"{name}['goals'][{i}]", g) for i, g in enumerate(raw))
    if "count" in value:
        count = validation.integer(f"{name}['count']", value["count"], minimum=0)
    else:
        density = validation.real(f"{name}['density']", value["density"], minimum=0.0, unit="pedestrians per m²")
    behaviour = value.get("behaviour", "orca")
    if not callable(behaviour) and (not isinstance(behaviour, str) or behaviour not in BEHAVIOURS):
        raise ArgumentError(f"{name}['behaviour'] must be one of {list(BEHAVIOURS)} or a callable, got {behaviour!r}")
    orca = value.get("orca") or {}
    if not isinstance(orca, Mapping):
        raise ArgumentError(f"{name}['orca'] must be a dict of {list(_ORCA_DEFAULTS)}, got {orca!r}")
    validation.known_keys(f"{name}['orca']", orca, tuple(_ORCA_DEFAULTS))
    orca = {**_ORCA_DEFAULTS, **orca}
    return PedestrianConfig(
        count=count,
        density=density,
        radius=_range(f"{name}['radius']", value.get("radius", (0.2, 0.3)), "m", strict=True),
        speed=_range(f"{name}['speed']", value.get("speed", (0.5, 1.0)), "m/s", strict=False),
        behaviour=behaviour,
        sees_robots=validation.boolean(f"{name}['sees_robots']", value.get("sees_robots", True)),
        end_on_collision=validation.boolean(f"{name}['end_on_collision']", value.get("end_on_collision", False)),
        neighbor_dist=validation.real(f"{name}['orca']['neighbor_dist']", orca["neighbor_dist"], minimum=0.0),
        max_neighbors=validation.integer(f"{name}['orca']['max_neighbors']", orca["max_neighbors"], minimum=0),
        time_horizon=validation.real(f"{name}['orca']['time_horizon']", orca["time_horizon"], minimum=0.0, strict=True, unit="s"),
        starts=starts,
        goals=goals,
    )


def _points(name: str, value: Any) -> tuple[tuple[float, float], ...]:
    """A non-empty list of ``[x, y]`` points (m) as a tuple of float pairs."""
    if not isinstance(value, (list, tuple)) or not value:
        raise ArgumentError(f"{name} must be a non-empty list of [x, y] points (m), got {value!r}")
    return tuple(tuple(float(c) for c in validation.vector(f"{name}[{i}]", p, sizes=(2,))) for i, p in enumerate(value))  # type: ignore[misc]
