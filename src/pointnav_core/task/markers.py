"""Visual markers: the start, the goal and the path waypoints a task shows (SPEC section 8).

A :class:`~pointnav_core.task.PointNavigationTask` built with ``visualize_goal`` or
``visualize_path`` keeps its markers as part of its state, as :class:`VisualMarker` values
(``task.markers``); renderers draw the visible ones
(:func:`pointnav_core.render.recording.render_env`). Markers are pure data: the backend never sees
them, so they never collide with anything, and a task with both flags off does no marker
work at all.

========  ==========================  ===================  ==================================
kind      where                       radius               when
========  ==========================  ===================  ==================================
start     the episode's start         ``goal_tolerance``   ``visualize_goal``; set at reset
goal      the episode's goal          ``goal_tolerance``   ``visualize_goal``; set at reset
waypoint  along the shortest path     ``waypoint_width``   ``visualize_path``; ``n_vis_waypoints``
          from the robot to the goal                       of them, placed at reset and after
                                                           every step
========  ==========================  ===================  ==================================

A marker's z is the floor's height plus ``goal_height`` (start and goal) or
``waypoint_height`` (waypoints).

Waypoint spacing
----------------
:func:`place_waypoints` spreads ``count`` waypoints over the path *between* the robot and
the goal, on neither: waypoint ``k = 1 .. count`` sits at arc length ``k * s`` from the
robot, with ``s = max(min_spacing, L / (count + 1))`` for a path of length ``L`` (the task
passes ``scene.waypoint_spacing``, 0.2 m by default). A long path is therefore marked
evenly along its whole length; on a path shorter than ``(count + 1) * min_spacing`` the
waypoints stay ``min_spacing`` apart, and those that would lie at or past the goal are
hidden. When there is no path (the goal is unreachable from where the robot stands, e.g.
over void or in another component), every waypoint is hidden. Hidden waypoints sit at the
path's end (the goal); when there is no path they stay where they last were (at the goal
right after a reset).

The path is the goal field's cheap one (``FloorGoalField.path(xy, exact=False)``: the
robot's cell's root when the robot sees it), from the robot's position after the step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.errors import ArgumentError

__all__ = ["MARKER_KINDS", "TaskMarkers", "VisualMarker", "place_waypoints"]

#: Valid values of :attr:`VisualMarker.kind`.
MARKER_KINDS = ("start", "goal", "waypoint")


@dataclass(frozen=True, kw_only=True)
class VisualMarker:
    """One marker a task shows: a flat disc floating just above its floor.

    Parameters
    ----------
    kind : {"start", "goal", "waypoint"}
        What it marks (renderers colour it by kind).
    position : (float, float, float)
        World centre (x, y, z) in metres; z is the floor's height plus the marker's
        configured height. Stored as a tuple of three floats.
    radius : float
        Disc radius in metres, >= 0.
    visible : bool, default True
        Whether it is shown; a hidden marker's position means nothing.

    Raises
    ------
    ValueError
        When ``kind`` is not one of :data:`MARKER_KINDS` (the message lists them), the
        position is not three finite numbers, the radius is negative or not finite, or
        ``visible`` is not a bool.

    Examples
    --------
    >>> VisualMarker(kind="goal", position=(1, 2.5, 0.06), radius=0.5)
    VisualMarker(kind='goal', position=(1.0, 2.5, 0.06), radius=0.5, visible=True)
    >>> VisualMarker(kind="flag", position=(0, 0, 0), radius=0.5)
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: kind must be one of ['start', 'goal', 'waypoint'], got 'flag'
    """

    kind: str
    position: tuple[float, float, float]
    radius: float
    visible: bool = True

    def __post_init__(self) -> None:
        if not isinstance(self.kind, str) or self.kind not in MARKER_KINDS:
            raise ArgumentError(f"kind must be one of {list(MARKER_KINDS)}, got {self.kind!r}")
        try:
            position = tuple(float(c) for c in self.position)
        except (TypeError, ValueError):
            position = ()
        if len(position) != 3 or not all(math.isfinite(c) for c in position):
            raise ArgumentError(
                f"position must be a finite (x, y, z) point in metres, got {self.position!r}"
            )
        object.__setattr__(self, "position", position)
        try:
            radius = float(self.radius)
        except (TypeError, ValueError):
            radius = math.nan
        if isinstance(self.radius, bool) or not (math.isfinite(radius) and radius >= 0.0):
            raise ArgumentError(f"radius must be a finite number >= 0 (m), got {self.radius!r}")
        object.__setattr__(self, "radius", radius)
        if not isinstance(self.visible, (bool, np.bool_)):
            raise ArgumentError(f"visible must be True or False, got {self.visible!r}")
        object.__setattr__(self, "visible", bool(self.visible))


def place_waypoints(
    path: ArrayLike, count: int, min_spacing: float
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Place ``count`` waypoint markers along a path, and say which are shown.

    Waypoint ``k = 1 .. count`` lies at arc length ``k * s`` from the path's start, with
    ``s = max(min_spacing, L / (count + 1))`` for a path of length ``L``; it is shown when
    it lies strictly before the path's end. Hidden ones sit at the path's end.

    Parameters
    ----------
    path : array_like, shape (N, 2)
        The polyline from the robot to the goal (m), N >= 1.
    count : int
        Number of waypoints, >= 1.
    min_spacing : float
        Smallest arc-length gap between waypoints (m), > 0.

    Returns
    -------
    positions : ndarray of float64, shape (count, 2)
        World (x, y) of each waypoint in metres, nearest the robot first.
    visible : ndarray of bool, shape (count,)
        Which waypoints are shown: a prefix of them, all of them on a path longer than
        ``(count + 1) * min_spacing``, none on a path no longer than ``min_spacing``.

    See Also
    --------
    pointnav_core.geodesic.paths.resample_path : The interpolation used, at spacing ``s``.

    Examples
    --------
    A 6 m path and 5 waypoints: 1 m apart, none on either end.

    >>> xy, shown = place_waypoints([[0.0, 0.0], [6.0, 0.0]], 5, 0.2)
    >>> xy[:, 0].tolist(), shown.tolist()
    ([1.0, 2.0, 3.0, 4.0, 5.0], [True, True, True, True, True])

    A 0.5 m path: 0.2 m apart, only the two before the goal are shown.

    >>> xy, shown = place_waypoints([[0.0, 0.0], [0.0, 0.5]], 4, 0.2)
    >>> xy[:, 1].round(6).tolist(), shown.tolist()
    ([0.2, 0.4, 0.5, 0.5], [True, True, False, False])

    A path of one point (the robot is at the goal): all hidden.

    >>> place_waypoints([[1.0, 1.0]], 2, 0.2)[1].tolist()
    [False, False]
    """
    pts = np.asarray(path, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[0] < 1 or pts.shape[1] != 2 or not np.isfinite(pts).all():
        raise ArgumentError(
            f"path must be a finite (N, 2) polyline in metres with N >= 1, got shape {pts.shape}"
        )
    if isinstance(count, bool) or int(count) != count or count < 1:
        raise ArgumentError(f"count must be an integer >= 1, got {count!r}")
    count = int(count)
    if not (math.isfinite(min_spacing) and min_spacing > 0.0):
        raise ArgumentError(f"min_spacing must be a finite number > 0 (m), got {min_spacing!r}")
    return _waypoints_along(pts, count, float(min_spacing))


def _waypoints_along(
    pts: NDArray[np.float64], count: int, min_spacing: float
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """:func:`place_waypoints` without the checks (the task's per-step call, on paths it
    trusts): the same interpolation as :func:`~pointnav_core.geodesic.paths.resample_path` at
    spacing ``s``, with the arc lengths computed once."""
    d = pts[1:] - pts[:-1]
    arc = np.zeros(len(pts))
    np.cumsum(np.sqrt(np.einsum("ij,ij->i", d, d)), out=arc[1:])
    length = float(arc[-1])
    spacing = max(min_spacing, length / (count + 1))
    s = np.arange(1, count + 1) * spacing
    positions = np.empty((count, 2))
    positions[:, 0] = np.interp(s, arc, pts[:, 0])  # clamped to the end past it
    positions[:, 1] = np.interp(s, arc, pts[:, 1])
    # Strictly before the end, with room for rounding in k * s (k * s = L * k / (count + 1)
    # can only reach L through rounding when the path is long).
    visible = s < length - 1e-9 * max(1.0, length)
    return positions, visible


class TaskMarkers:
    """The markers of one task's episode: set at reset, waypoints moved after each step.

    The task builds one from its configuration and calls :meth:`clear`, :meth:`place`
    and :meth:`move_waypoints` only when ``visualize_goal`` or ``visualize_path`` is on,
    so a task with both off does no marker work. :attr:`markers` is the tuple the
    task's ``markers`` returns, rebuilt only after the waypoints moved.

    Parameters
    ----------
    config : TaskConfig
        The task's configuration (the ``visualize_*`` flags, heights, widths, counts).
    """

    def __init__(self, config: Any) -> None:
        self.config = config
        self.floor_height = 0.0
        self.spacing = 0.2  # scene.waypoint_spacing, set when the task meets its env
        self.clear()

    def clear(self) -> None:
        """Forget the episode's markers (a reset that fails leaves none)."""
        self._goal_markers: tuple[VisualMarker, ...] = ()
        self._waypoint_xy: NDArray[np.float64] | None = None
        self._waypoint_visible: NDArray[np.bool_] | None = None
        self._markers: tuple[VisualMarker, ...] | None = ()

    def place(self, start_xy: tuple[float, float], goal_xy: tuple[float, float],
              field: Any, x: float, y: float) -> None:
        """Set this episode's markers, the robot standing at (x, y) (m), at reset."""
        cfg = self.config
        gx, gy = goal_xy
        if cfg.visualize_goal:
            sx, sy = start_xy
            z = self.floor_height + cfg.goal_height
            radius = cfg.goal_tolerance
            self._goal_markers = (
                VisualMarker(kind="start", position=(sx, sy, z), radius=radius),
                VisualMarker(kind="goal", position=(gx, gy, z), radius=radius),
            )
        if cfg.visualize_path:
            n = cfg.n_vis_waypoints
            self._waypoint_xy = np.tile((gx, gy), (n, 1))
            self._waypoint_visible = np.zeros(n, dtype=bool)
            self.move_waypoints(field, x, y)
        self._markers = None

    def move_waypoints(self, field: Any, x: float, y: float) -> None:
        """Move the waypoint markers onto ``field``'s path from (x, y); hide them if
        there is none (they then stay where they were)."""
        # The goal field's cheap path (the source cell's root when the source sees it).
        points, _ = field.path((x, y), exact=False)
        count = self.config.n_vis_waypoints
        if points is None:
            self._waypoint_visible = np.zeros(count, dtype=bool)
        else:
            # place_waypoints' placement, without its checks: the path is the field's.
            self._waypoint_xy, self._waypoint_visible = _waypoints_along(
                points, count, self.spacing
            )
        self._markers = None

    @property
    def markers(self) -> tuple[VisualMarker, ...]:
        """Start and goal markers, then the waypoints (see the task's ``markers``)."""
        if self._markers is None:
            markers = self._goal_markers
            if self._waypoint_xy is not None and self._waypoint_visible is not None:
                z = self.floor_height + self.config.waypoint_height
                radius = self.config.waypoint_width
                markers += tuple(
                    VisualMarker(kind="waypoint", position=(x, y, z), radius=radius, visible=shown)
                    for (x, y), shown in zip(
                        self._waypoint_xy.tolist(), self._waypoint_visible.tolist()
                    )
                )
            self._markers = markers
        return self._markers
