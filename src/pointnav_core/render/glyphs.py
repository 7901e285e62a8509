"""What a top-down picture shows besides the floor: robots, markers and range scans, and
their colours. Each glyph checks its fields when built; :class:`~pointnav_core.render.top_down.TopDownRenderer`
draws them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.utils import validation

__all__ = [
    "RGB",
    "START_COLOR",
    "GOAL_COLOR",
    "WAYPOINT_COLOR",
    "MARKER_COLORS",
    "SCAN_RAY_COLOR",
    "SCAN_HIT_COLOR",
    "RobotGlyph",
    "Marker",
    "ScanGlyph",
    "check_color",
    "check_number",
    "check_xy",
]

RGB = tuple[int, int, int]
"""An opaque colour: red, green, blue, each an int in [0, 255]."""

START_COLOR: RGB = (220, 40, 40)
"""Start marker (red), a translucent disc of radius ``goal_tolerance``."""
GOAL_COLOR: RGB = (30, 90, 230)
"""Goal marker (blue), a translucent disc of radius ``goal_tolerance``."""
WAYPOINT_COLOR: RGB = (30, 170, 60)
"""Path waypoint markers (green), translucent discs of radius ``waypoint_width``."""

MARKER_COLORS: Mapping[str, RGB] = {"start": START_COLOR, "goal": GOAL_COLOR, "waypoint": WAYPOINT_COLOR}
"""Marker colour by :attr:`~pointnav_core.task.markers.VisualMarker.kind`."""

PEDESTRIAN_COLOR: RGB = (120, 120, 120)
"""Pedestrians (grey), opaque discs with a heading tick, drawn below the robots."""

SCAN_RAY_COLOR: RGB = (250, 200, 140)
"""Range scan rays (light orange), one-pixel lines from the robot's centre to each reading."""
SCAN_HIT_COLOR: RGB = (200, 0, 200)
"""Range scan hits (magenta), a 3 x 3 pixel dot where a reading below ``max_range`` ends."""


def check_color(value: object, name: str) -> RGB:
    """``value`` as an RGB triple of ints in [0, 255], else ValueError naming ``name``."""
    try:
        channels = tuple(value)  # type: ignore[arg-type]
    except TypeError:
        channels = ()
    if len(channels) != 3 or not all(
        isinstance(c, (int, np.integer)) and not isinstance(c, bool) and 0 <= c <= 255 for c in channels
    ):
        raise ArgumentError(f"{name} must be three ints in [0, 255] (r, g, b), got {value!r}")
    return (int(channels[0]), int(channels[1]), int(channels[2]))


def check_xy(value: object, name: str) -> tuple[float, float]:
    """The (x, y) in metres of a finite 2- or 3-vector, else ValueError naming ``name``."""
    arr = np.asarray(value, dtype=np.float64).reshape(-1) if value is not None else np.empty(0)
    if arr.shape not in ((2,), (3,)) or not np.isfinite(arr).all():
        raise ArgumentError(f"{name} must be a finite (x, y) or (x, y, z) point in metres, got {value!r}")
    return (float(arr[0]), float(arr[1]))


def check_number(
    value: object, name: str, unit: str, *, low: float, high: float = math.inf, strict: bool = False
) -> float:
    """``value`` as a float in [low, high] (in (low, high] when ``strict``), else ValueError;
    a bool or a string is not a number (:func:`pointnav_core.utils.validation.is_real`)."""
    number = float(value) if validation.is_real(value) else math.nan  # type: ignore[arg-type]
    above = number > low if strict else number >= low
    if not (math.isfinite(number) and above and number <= high):
        if high < math.inf:
            bounds = f" in [{low:g}, {high:g}]"
        elif low > -math.inf:
            bounds = f" {'>' if strict else '>='} {low:g}"
        else:
            bounds = ""
        raise ArgumentError(f"{name} must be a finite number{bounds}{unit}, got {value!r}")
    return number


@dataclass(frozen=True, kw_only=True)
class RobotGlyph:
    """One robot to draw: an opaque disc with a heading tick.

    Parameters
    ----------
    position_xy : (float, float)
        World position of the robot's centre in metres; an (x, y, z) position is accepted
        and its z ignored. Stored as a tuple of two floats.
    yaw : float
        Heading in radians about +z (0 along +x, pi/2 along +y).
    radius : float
        Disc radius in metres, >= 0.
    color : (int, int, int), optional
        Disc colour; None takes ``ROBOT_PALETTE[i % len(ROBOT_PALETTE)]`` for the robot's
        index ``i`` in the sequence given to :meth:`TopDownRenderer.draw`.

    Raises
    ------
    ValueError
        When a field is not finite, the radius is negative or the colour is not RGB.

    Examples
    --------
    >>> RobotGlyph(position_xy=(1, 2, 0.0), yaw=0.5, radius=0.18)
    RobotGlyph(position_xy=(1.0, 2.0), yaw=0.5, radius=0.18, color=None)
    """

    position_xy: tuple[float, float]
    yaw: float
    radius: float
    color: RGB | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "position_xy", check_xy(self.position_xy, "position_xy"))
        object.__setattr__(self, "yaw", check_number(self.yaw, "yaw", " (rad)", low=-math.inf))
        object.__setattr__(self, "radius", check_number(self.radius, "radius", " (m)", low=0.0))
        if self.color is not None:
            object.__setattr__(self, "color", check_color(self.color, "color"))


@dataclass(frozen=True, kw_only=True)
class Marker:
    """A translucent disc on the floor: the start, the goal, or a path waypoint.

    Parameters
    ----------
    position_xy : (float, float)
        World position of the centre in metres; an (x, y, z) position is accepted and its
        z ignored (markers are drawn flat).
    radius : float
        Disc radius in metres, >= 0.
    color : (int, int, int)
        Disc colour, e.g. :data:`START_COLOR`, :data:`GOAL_COLOR` or :data:`WAYPOINT_COLOR`.
    alpha : float, default 0.5
        Opacity in [0, 1]: a covered pixel becomes ``(1 - alpha) * below + alpha * color``.

    Raises
    ------
    ValueError
        When a field is not finite or out of range, or the colour is not RGB.

    Examples
    --------
    >>> Marker(position_xy=(0.0, 1.0), radius=0.5, color=GOAL_COLOR)
    Marker(position_xy=(0.0, 1.0), radius=0.5, color=(30, 90, 230), alpha=0.5)
    """

    position_xy: tuple[float, float]
    radius: float
    color: RGB
    alpha: float = 0.5

    def __post_init__(self) -> None:
        object.__setattr__(self, "position_xy", check_xy(self.position_xy, "position_xy"))
        object.__setattr__(self, "radius", check_number(self.radius, "radius", " (m)", low=0.0))
        object.__setattr__(self, "color", check_color(self.color, "color"))
        object.__setattr__(self, "alpha", check_number(self.alpha, "alpha", "", low=0.0, high=1.0))


@dataclass(frozen=True, kw_only=True)
class ScanGlyph:
    """A range scan to draw: a line per ray, and a dot where a ray hit something.

    Parameters
    ----------
    origin_xy : (float, float)
        World position (m) the rays start from (the robot's centre).
    ends_xy : array_like, shape (R, 2)
        World position (m) where each ray's reading ends.
    hit : array_like of bool, shape (R,)
        Whether each reading is a return (below ``max_range``); those get a dot.

    Examples
    --------
    >>> g = ScanGlyph(origin_xy=(0.0, 0.0), ends_xy=[[1.0, 0.0]], hit=[True])
    >>> g.ends_xy.shape, g.hit.tolist()
    ((1, 2), [True])
    """

    origin_xy: tuple[float, float]
    ends_xy: NDArray[np.float64]
    hit: NDArray[np.bool_]

    def __post_init__(self) -> None:
        object.__setattr__(self, "origin_xy", check_xy(self.origin_xy, "origin_xy"))
        ends = np.array(self.ends_xy, dtype=np.float64).reshape(-1, 2)
        hit = np.array(self.hit, dtype=bool).reshape(-1)
        if len(hit) != len(ends) or not np.isfinite(ends).all():
            raise ArgumentError(
                f"ends_xy must be finite (R, 2) points and hit R flags, got shapes {ends.shape} and {hit.shape}"
            )
        ends.flags.writeable = False
        hit.flags.writeable = False
        object.__setattr__(self, "ends_xy", ends)
        object.__setattr__(self, "hit", hit)
