"""Argument checks and the planar quaternion, for backend authors.

Each check raises the error that :class:`~pointnav_core.backends.protocol.Backend` promises and names
the parameter, so that every backend reports a bad argument the same way.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.errors import ArgumentError, ArgumentTypeError

__all__ = [
    "check_index",
    "check_load",
    "parse_orientation",
    "parse_position",
    "planar_quat",
    "planar_quat_floats",
]


def _is_index(value: Any) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def check_index(value: Any, count: int, *, name: str, what: str) -> int:
    """Return ``value`` as an index into ``count`` things, or raise naming the parameter.

    Parameters
    ----------
    value : int
        The index given by the caller; a Python or numpy integer, not a bool.
    count : int
        How many things there are; valid indices are ``0 .. count - 1``.
    name : str
        The parameter's name, for the error message (``"idn"``, ``"floor"``).
    what : str
        What it indexes, for the error message (``"robot"``, ``"floor"``).

    Returns
    -------
    int
        ``value`` as a Python int.

    Raises
    ------
    TypeError
        If ``value`` is not an integer (bools are not).
    ValueError
        If ``value`` is outside ``[0, count)``.

    Examples
    --------
    >>> check_index(1, 2, name="floor", what="floor")
    1
    >>> check_index(2, 2, name="floor", what="floor")
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: floor must be in [0, 2), got 2
    >>> check_index(True, 2, name="idn", what="robot")
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentTypeError: idn must be an int robot index, got True
    """
    if not _is_index(value):
        raise ArgumentTypeError(f"{name} must be an int {what} index, got {value!r}")
    if not 0 <= value < count:
        raise ArgumentError(f"{name} must be in [0, {count}), got {value}")
    return int(value)


def check_load(
    scene: Any, robots: Sequence[RobotSpec], action_frequency: Any
) -> tuple[list[RobotSpec], int, float]:
    """Check the arguments of :meth:`Backend.load` and return what a backend builds from.

    Parameters
    ----------
    scene : Scene
        Must have ``n_floors >= 1`` and as many ``floors``.
    robots : sequence of RobotSpec
        One spec per robot.
    action_frequency : float
        Control steps per second (Hz), finite and > 0.

    Returns
    -------
    specs : list of RobotSpec
        ``robots`` as a list.
    n_floors : int
        The scene's number of floors.
    dt : float
        Duration of one control step in seconds, ``1 / action_frequency``.

    Raises
    ------
    ValueError
        If ``action_frequency`` is not a finite number > 0, or the scene has no floors or
        a floor count that does not match its maps.
    TypeError
        If an item of ``robots`` is not a :class:`RobotSpec`.

    Examples
    --------
    >>> import types
    >>> scene = types.SimpleNamespace(floors=["map"], n_floors=1)
    >>> check_load(scene, (RobotSpec(),), 4.0)[1:]
    (1, 0.25)
    >>> check_load(scene, [RobotSpec(), "robot"], 10.0)
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentTypeError: robots[1] must be a RobotSpec, got str
    """
    freq = float(action_frequency)
    if not math.isfinite(freq) or freq <= 0.0:
        raise ArgumentError(
            f"action_frequency must be a finite number > 0 (Hz), got {action_frequency!r}"
        )
    specs = list(robots)
    for i, spec in enumerate(specs):
        if not isinstance(spec, RobotSpec):
            raise ArgumentTypeError(f"robots[{i}] must be a RobotSpec, got {type(spec).__name__}")
    n_floors = int(scene.n_floors)
    if n_floors < 1 or len(scene.floors) != n_floors:
        raise ArgumentError(
            f"scene must have n_floors >= 1 floors, got n_floors={n_floors} "
            f"and {len(scene.floors)} maps"
        )
    return specs, n_floors, 1.0 / freq


def parse_position(
    position: ArrayLike, *, allow_2d: bool = False, name: str = "position"
) -> tuple[float, ...]:
    """Check a world position and return its coordinates as floats.

    Parameters
    ----------
    position : array_like, shape (3,), or (2,) when ``allow_2d``
        World ``(x, y, z)`` (or ``(x, y)``) in metres, finite.
    allow_2d : bool
        Whether ``(x, y)`` without a z is accepted.
    name : str
        The parameter's name, for the error message.

    Returns
    -------
    tuple of float
        The coordinates, 2 or 3 of them as given.

    Raises
    ------
    ValueError
        If ``position`` has another shape or holds NaN or infinity.

    Examples
    --------
    >>> parse_position(np.array([1.0, 2.0]), allow_2d=True)
    (1.0, 2.0)
    >>> parse_position([1.0, 2.0])
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: position must be finite (x, y, z) in metres, got [1.0, 2.0]
    """
    p = np.asarray(position, dtype=np.float64)
    shapes = ((2,), (3,)) if allow_2d else ((3,),)
    if p.shape not in shapes or not np.isfinite(p).all():
        want = "(x, y) or (x, y, z)" if allow_2d else "(x, y, z)"
        raise ArgumentError(f"{name} must be finite {want} in metres, got {position!r}")
    return tuple(p.tolist())


def parse_orientation(orientation: ArrayLike, *, name: str = "orientation") -> float:
    """Check an ``(x, y, z, w)`` quaternion and return its heading (yaw) in radians.

    The heading is that of the rotated +x axis, ``atan2(2 (w z + x y), w² + x² - y² - z²)``;
    it does not depend on the quaternion's scale, so a non-unit quaternion is fine.

    Parameters
    ----------
    orientation : array_like, shape (4,)
        A finite, non-zero quaternion ``(x, y, z, w)``.
    name : str
        The parameter's name, for the error message.

    Returns
    -------
    float
        The yaw in ``[-pi, pi]``.

    Raises
    ------
    ValueError
        If ``orientation`` has another shape, holds NaN or infinity, or is zero.

    See Also
    --------
    pointnav_core.transforms.quat2yaw : The same heading for arrays of quaternions.
    planar_quat : The inverse, for a planar robot.

    Examples
    --------
    >>> round(parse_orientation([0.0, 0.0, 1.0, 1.0]), 6)  # not unit: still 90 degrees
    1.570796
    >>> parse_orientation((0.0, 0.0, 0.0, 0.0))
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: orientation must be a non-zero quaternion, got (0.0, 0.0, 0.0, 0.0)
    """
    q = np.asarray(orientation, dtype=np.float64)
    if q.shape != (4,) or not np.isfinite(q).all():
        raise ArgumentError(
            f"{name} must be a finite (x, y, z, w) quaternion of shape (4,), "
            f"got {orientation!r}"
        )
    x, y, z, w = q.tolist()
    if x * x + y * y + z * z + w * w < 1e-12:
        raise ArgumentError(f"{name} must be a non-zero quaternion, got {orientation!r}")
    return math.atan2(2.0 * (w * z + x * y), w * w + x * x - y * y - z * z)


def planar_quat(yaw: float) -> NDArray[np.float64]:
    """Return the quaternion of a heading, with the heading wrapped so that ``w >= 0``.

    Parameters
    ----------
    yaw : float
        Heading about +z in radians, any finite value.

    Returns
    -------
    ndarray of float64, shape (4,)
        ``(0, 0, sin(a / 2), cos(a / 2))`` with ``a`` = ``yaw`` wrapped into
        ``[-pi, pi]``: what :meth:`Backend.get_pose` returns for a planar robot.

    See Also
    --------
    pointnav_core.transforms.yaw2quat : The same for arrays, without the wrapping (its
        ``w`` is negative for ``|yaw| > pi``) and with ``-0.0`` made ``+0.0``.
    parse_orientation : The inverse.

    Examples
    --------
    >>> planar_quat(math.pi / 2).round(6).tolist()
    [0.0, 0.0, 0.707107, 0.707107]
    >>> planar_quat(2 * math.pi).tolist()  # a full turn: the identity, w = +1
    [0.0, 0.0, 0.0, 1.0]
    """
    return np.array(planar_quat_floats(yaw))


def planar_quat_floats(yaw: float) -> tuple[float, float, float, float]:
    """:func:`planar_quat` as a tuple of four Python floats, without an array.

    What a ``get_pose_floats`` fast path returns after the position (see
    :data:`~pointnav_core.backends.protocol.FLOAT_TWINS`).

    Examples
    --------
    >>> planar_quat_floats(2 * math.pi)  # a full turn: the identity, w = +1
    (0.0, 0.0, 0.0, 1.0)
    """
    half = 0.5 * math.remainder(yaw, 2.0 * math.pi)
    return 0.0, 0.0, math.sin(half), math.cos(half)

