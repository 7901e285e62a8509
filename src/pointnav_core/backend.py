"""The Backend protocol: the only door between the core and the world it drives.

The core (task, envs, metrics) never touches a simulator. It asks a *backend* to build the
world from a scene and some robot specs, to place robots, to advance one control step, and
to report poses, velocities and contacts. Backends register under a name in the entry-point
group ``pointnav_core.backends`` (``"kinematic"`` ships with the library), so a third party
can add one without touching the core. This module imports no backend package.

==============================================  ==========================================
Method                                          What it does
==============================================  ==========================================
``load(scene, robots, action_frequency)``       build the world; robots present, unplaced
``reset()``                                     zero velocities and contact flags
``n_robots``                                    number of robots (property)
``land(idn, floor, position, orientation)``     place a robot on a floor, z = floor height
``set_pose(idn, position, orientation)``        teleport a robot (world xyz, xyzw quat)
``get_pose(idn)``                               world position (3,) and xyzw quaternion (4,)
``get_velocity(idn)``                           world linear (3,) and angular (3,) velocity
``step(actions)``                               apply actions, advance one control step
``in_contact(idn)``                             touched an obstacle or robot last step?
``is_valid_pose(idn, position, orientation)``   could the robot stand there?
``set_present(idn, present)``                   take a robot out of (or back into) the world
``is_present(idn)``                             whether the robot is in the world
``get_robot_floor(idn)``                        the floor the robot was landed on
==============================================  ==========================================

Units are metres, seconds and radians; the world frame has x, y on the floor and z up;
quaternions are ``(x, y, z, w)``. Actions are in ``[-1, 1]`` and are turned into velocities
by :meth:`RobotSpec.scale_action`.

Outside the protocol, a backend may offer a fast path for the task's per-step reads:
``get_pose_floats(idn)`` and ``get_velocity_floats(idn)``, the numbers of ``get_pose`` and
``get_velocity`` as one flat tuple of Python floats (no arrays). The task uses such a *float
twin* only if it is defined at least as far down the class hierarchy as the method it
mirrors (so a subclass that overrides ``get_pose`` alone is still read through it), and
falls back to the protocol method otherwise. Both shipped backends have them.

For backend authors, the module also holds what the shipped backends share and a new one
may reuse: :class:`RobotStateBackend` (a base class with the robot index checks, the
simple accessors, presence and the fall of a robot over VOID), and the argument checks
:func:`check_load`, :func:`check_index`, :func:`parse_position` and
:func:`parse_orientation`, and :func:`planar_quat`, whose errors name the parameter.
"""

from __future__ import annotations

import inspect
import math
import types
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from importlib.metadata import entry_points
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.errors import BackendError

__all__ = [
    "DRIVES",
    "ENTRY_POINT_GROUP",
    "Backend",
    "RobotSpec",
    "RobotStateBackend",
    "UnknownBackendError",
    "available_backends",
    "check_backend",
    "check_index",
    "check_load",
    "get_backend",
    "make_backend",
    "parse_orientation",
    "parse_position",
    "planar_quat",
]

#: Drive types and the meaning of their action vector (robot frame: +x ahead, +y left).
DRIVES = types.MappingProxyType({"differential": ("v", "w"), "holonomic": ("vx", "vy", "w")})

#: Entry-point group under which backends register ``name = "module:Class"``.
ENTRY_POINT_GROUP = "pointnav_core.backends"


class UnknownBackendError(BackendError, ValueError):
    """No backend is installed under the requested name.

    It is both a :class:`~pointnav_core.errors.BackendError` (what went wrong) and a
    :class:`ValueError` (a bad argument value), so either ``except`` clause catches it.
    """


# Dtypes whose ndarray.tolist() gives exactly the float64 values of asarray(float64).
_FLOAT_DTYPES = frozenset((np.dtype(np.float32), np.dtype(np.float64)))


def _positive(name: str, value: Any, *, strict: bool, unit: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number ({unit}), got {value!r}") from None
    bound_ok = number > 0.0 if strict else number >= 0.0
    if not math.isfinite(number) or not bound_ok:
        relation = "> 0" if strict else ">= 0"
        raise ValueError(f"{name} must be a finite number {relation} ({unit}), got {value!r}")
    return number


@dataclass(frozen=True, kw_only=True)
class RobotSpec:
    """What a backend needs to know about one robot: its size, speed limits and drive.

    Parameters
    ----------
    radius : float
        Radius of the robot's footprint disc in metres, >= 0 (0 is a point robot).
    max_linear_velocity : float
        Speed in m/s that an action component of 1 maps to, > 0.
    max_angular_velocity : float
        Yaw rate in rad/s that an action component of 1 maps to, > 0.
    drive : {"differential", "holonomic"}
        ``"differential"``: action ``(v, w)``, forward speed and yaw rate.
        ``"holonomic"``: action ``(vx, vy, w)``, velocities in the robot frame (+x ahead,
        +y to the left) and yaw rate.

    Examples
    --------
    >>> spec = RobotSpec(radius=0.2, drive="holonomic")
    >>> spec.action_dim
    3
    >>> spec.scale_action([1.0, -2.0, 0.5]).tolist()  # -2 is clipped to -1
    [0.5, -0.5, 0.75]
    >>> RobotSpec(drive="tank")
    Traceback (most recent call last):
    ...
    ValueError: drive must be one of ['differential', 'holonomic'], got 'tank'
    """

    radius: float = 0.18
    max_linear_velocity: float = 0.5
    max_angular_velocity: float = 1.5
    drive: str = "differential"

    if TYPE_CHECKING:
        # Set in __post_init__; declared here for type checkers only, so not a field.
        _maxima: tuple[float, ...]

    def __post_init__(self) -> None:
        # Store floats, so that a spec built from numpy scalars or ints compares and hashes
        # like one built from Python floats.
        set_ = object.__setattr__
        set_(self, "radius", _positive("radius", self.radius, strict=False, unit="metres"))
        set_(
            self,
            "max_linear_velocity",
            _positive("max_linear_velocity", self.max_linear_velocity, strict=True, unit="m/s"),
        )
        set_(
            self,
            "max_angular_velocity",
            _positive(
                "max_angular_velocity", self.max_angular_velocity, strict=True, unit="rad/s"
            ),
        )
        if not isinstance(self.drive, str) or self.drive not in DRIVES:
            raise ValueError(f"drive must be one of {sorted(DRIVES)}, got {self.drive!r}")
        lin, ang = self.max_linear_velocity, self.max_angular_velocity
        # Velocity each action component maps to: derived, so not a field (asdict, eq).
        set_(self, "_maxima", (lin, ang) if self.drive == "differential" else (lin, lin, ang))

    @property
    def action_dim(self) -> int:
        """Length of an action vector: 2 for differential drive, 3 for holonomic."""
        return len(self._maxima)

    def scale_action(self, action: ArrayLike) -> NDArray[np.float64]:
        """Turn an action in ``[-1, 1]`` into velocities.

        Parameters
        ----------
        action : array_like, shape (action_dim,)
            ``(v, w)`` for differential drive or ``(vx, vy, w)`` for holonomic drive, each
            in ``[-1, 1]``; values outside are clipped.

        Returns
        -------
        ndarray of float64, shape (action_dim,)
            Velocities: linear components in m/s (robot frame), the yaw rate in rad/s.

        Raises
        ------
        ValueError
            If ``action`` has the wrong shape or holds NaN or infinity.

        Examples
        --------
        >>> RobotSpec().scale_action([0.5, -1.0]).tolist()
        [0.25, -1.5]
        >>> RobotSpec().scale_action([float("nan"), 0.0])
        Traceback (most recent call last):
        ...
        ValueError: action must be finite, got [nan, 0.0]
        """
        return np.array(self._scaled(action))

    def _scaled(self, action: ArrayLike) -> tuple[float, ...]:
        # Hot path (once per robot per step): plain floats beat numpy for 2-3 numbers.
        maxima = self._maxima
        if type(action) is np.ndarray and action.ndim == 1 and action.dtype in _FLOAT_DTYPES:
            # What env.step passes: tolist gives the float64 values, without a copy first.
            values = action.tolist()
            ok = len(values) == len(maxima)
        else:
            try:
                values = np.asarray(action, dtype=np.float64).tolist()
            except (TypeError, ValueError):
                values = None
            ok = (
                isinstance(values, list)
                and len(values) == len(maxima)
                and not any(isinstance(v, list) for v in values)
            )
        if not ok:
            shape = getattr(np.asarray(action, dtype=object), "shape", None)
            raise ValueError(
                f"action must have shape ({len(maxima)},) for a {self.drive} drive "
                f"({', '.join(DRIVES[self.drive])}), got shape {shape}"
            )
        out = []
        for v, m in zip(values, maxima):
            if not -math.inf < v < math.inf:  # also False for NaN
                raise ValueError(f"action must be finite, got {values}")
            out.append(m if v >= 1.0 else -m if v <= -1.0 else v * m)
        return tuple(out)


@runtime_checkable
class Backend(Protocol):
    """The world as the core sees it: robots on the floors of a scene.

    Robots are numbered ``idn = 0 .. n_robots - 1`` in the order their specs were given to
    :meth:`load`. Positions are world ``(x, y, z)`` in metres, orientations ``(x, y, z, w)``
    quaternions, velocities world-frame m/s and rad/s. Every returned array is a fresh
    object. A robot that is not *present* is out of the world: ``step`` does not move it and
    nothing collides with it.
    """

    @property
    def n_robots(self) -> int:
        """Number of robots loaded (0 before :meth:`load`)."""
        ...

    def load(
        self, scene: Any, robots: Sequence[RobotSpec], action_frequency: float = 10.0
    ) -> None:
        """Build the world: the scene's floors and one robot per spec.

        Parameters
        ----------
        scene : Scene
            Anything with ``floors`` (list of TraversableMap), ``n_floors`` and
            ``get_floor_height(floor)``.
        robots : sequence of RobotSpec
            One spec per robot; robot ``idn`` is ``robots[idn]``.
        action_frequency : float
            Control steps per second (Hz), > 0; one :meth:`step` lasts
            ``1 / action_frequency`` seconds.

        Notes
        -----
        All robots start present but unplaced: they take part in no collision until
        :meth:`land` or :meth:`set_pose` places them.
        """
        ...

    def reset(self) -> None:
        """Zero every robot's velocity and contact flag; poses are then set by the task."""
        ...

    def land(self, idn: int, floor: int, position: ArrayLike, orientation: ArrayLike) -> None:
        """Place robot ``idn`` standing on ``floor``, at rest.

        Parameters
        ----------
        idn : int
            Robot index.
        floor : int
            Floor index in ``[0, scene.n_floors)``.
        position : array_like, shape (2,) or (3,)
            World x, y in metres; any z is replaced by the floor's height.
        orientation : array_like, shape (4,)
            ``(x, y, z, w)`` quaternion.
        """
        ...

    def set_pose(self, idn: int, position: ArrayLike, orientation: ArrayLike) -> None:
        """Teleport robot ``idn`` to world ``position`` (x, y, z in m) and xyzw ``orientation``."""
        ...

    def get_pose(self, idn: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Return robot ``idn``'s world position (3,) in metres and xyzw quaternion (4,)."""
        ...

    def get_velocity(self, idn: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Return robot ``idn``'s world velocity: linear (3,) in m/s, angular (3,) in rad/s.

        These are the effective velocities of the last step (displacement over its
        duration), about the world axes.
        """
        ...

    def step(self, actions: Mapping[int, ArrayLike]) -> None:
        """Apply each given robot's action and advance one control step for all robots.

        Parameters
        ----------
        actions : mapping of int to array_like
            Robot index -> action in ``[-1, 1]`` units, scaled by that robot's
            :meth:`RobotSpec.scale_action`. Robots without an entry get a zero command.
            The step lasts ``1 / action_frequency`` seconds.
        """
        ...

    def in_contact(self, idn: int) -> bool:
        """Whether robot ``idn`` touched an obstacle or another robot during the last step.

        The floor never counts, and VOID (a hole) is not an obstacle.
        """
        ...

    def is_valid_pose(
        self,
        idn: int,
        position: ArrayLike,
        orientation: ArrayLike | None = None,
        *,
        floor: int | None = None,
    ) -> bool:
        """Whether robot ``idn`` could stand at ``position``.

        Valid means: the robot's disc overlaps no OBSTACLE cell and no other present,
        placed robot on the same floor (touching is allowed), and its centre is on the
        map and not over VOID. ``position`` is world (x, y) or (x, y, z) in metres;
        ``floor`` defaults to the robot's floor (:meth:`get_robot_floor`).
        """
        ...

    def set_present(self, idn: int, present: bool) -> None:
        """Take robot ``idn`` out of the world (``False``) or bring it back (``True``)."""
        ...

    def is_present(self, idn: int) -> bool:
        """Whether robot ``idn`` is in the world."""
        ...

    def get_robot_floor(self, idn: int) -> int:
        """The floor index robot ``idn`` was last landed on (0 until then)."""
        ...


def _protocol_members() -> tuple[str, ...]:
    return tuple(
        name
        for name, value in vars(Backend).items()
        if not name.startswith("_") and (callable(value) or isinstance(value, property))
    )


def check_backend(obj: Any) -> Any:
    """Raise :class:`BackendError` unless ``obj`` (a class or an instance) is a Backend.

    Parameters
    ----------
    obj : object
        A backend class or instance.

    Returns
    -------
    object
        ``obj`` itself, unchanged.

    Raises
    ------
    BackendError
        Listing every protocol member that ``obj`` lacks or has in a non-callable form.

    Examples
    --------
    >>> class Half:
    ...     def load(self, scene, robots, action_frequency=10.0): ...
    >>> check_backend(Half)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pointnav_core.errors.BackendError: Half does not implement the Backend protocol; missing: ...
    """
    cls = obj if isinstance(obj, type) else type(obj)
    missing = []
    for name in _protocol_members():
        # Look on the class, so that checking never runs a property or __getattr__.
        attr = inspect.getattr_static(cls, name, None)
        if attr is None:
            missing.append(name)
        elif name == "n_robots":
            continue
        elif not callable(attr) and not isinstance(attr, (staticmethod, classmethod)):
            missing.append(name)
    if missing:
        raise BackendError(
            f"{cls.__name__} does not implement the Backend protocol; missing: "
            f"{', '.join(missing)}"
        )
    return obj


def available_backends() -> list[str]:
    """Names of the installed backends (entry-point group ``pointnav_core.backends``).

    Examples
    --------
    >>> "kinematic" in available_backends()
    True
    """
    return sorted({ep.name for ep in entry_points(group=ENTRY_POINT_GROUP)})


def get_backend(name: str) -> type:
    """Return the backend class registered under ``name``.

    Parameters
    ----------
    name : str
        An entry-point name in the group ``pointnav_core.backends``, e.g. ``"kinematic"``.

    Raises
    ------
    UnknownBackendError
        (a BackendError and a ValueError) if no backend has that name; the message lists
        the installed ones.

    Examples
    --------
    >>> get_backend("kinematic").__name__
    'KinematicBackend'
    """
    matches = [ep for ep in entry_points(group=ENTRY_POINT_GROUP) if ep.name == name]
    if not matches:
        raise UnknownBackendError(
            f"backend must be one of {available_backends()}, got {name!r}"
        )
    cls = matches[0].load()
    if not isinstance(cls, type):
        raise BackendError(
            f"backend entry point {name!r} ({matches[0].value}) must name a class, got {cls!r}"
        )
    return cls


def make_backend(backend: str | type | Backend = "kinematic", **kwargs: Any) -> Backend:
    """Return a backend instance from a name, a class, or an instance.

    Parameters
    ----------
    backend : str or type or Backend
        A registered name (see :func:`available_backends`), a backend class (instantiated
        with ``kwargs``), or an instance (returned as is).
    **kwargs
        Constructor arguments, for a name or a class only.

    Raises
    ------
    UnknownBackendError
        If ``backend`` is a name that is not registered.
    BackendError
        If the result does not implement the Backend protocol, or ``backend`` is of
        another type.
    ValueError
        If ``kwargs`` are given along with an instance.

    Examples
    --------
    >>> make_backend("kinematic", collision_mode="stop").collision_mode
    'stop'
    """
    if isinstance(backend, str):
        cls = get_backend(backend)
        check_backend(cls)
        return cls(**kwargs)
    if isinstance(backend, type):
        check_backend(backend)
        return backend(**kwargs)
    check_backend(backend)
    if kwargs:
        raise ValueError(
            f"backend arguments {sorted(kwargs)} only apply when backend is a name or a "
            f"class, got an instance of {type(backend).__name__}"
        )
    return backend


# ----------------------------------------------------------------- for backend authors

_GRAVITY = 9.81  # m/s^2
_MIN_FIRST_DROP = 0.05  # m: a fall must be visible on the step it starts, at any rate


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
    ValueError: floor must be in [0, 2), got 2
    >>> check_index(True, 2, name="idn", what="robot")
    Traceback (most recent call last):
    ...
    TypeError: idn must be an int robot index, got True
    """
    if not _is_index(value):
        raise TypeError(f"{name} must be an int {what} index, got {value!r}")
    if not 0 <= value < count:
        raise ValueError(f"{name} must be in [0, {count}), got {value}")
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
    >>> scene = types.SimpleNamespace(floors=["map"], n_floors=1)
    >>> check_load(scene, (RobotSpec(),), 4.0)[1:]
    (1, 0.25)
    >>> check_load(scene, [RobotSpec(), "robot"], 10.0)
    Traceback (most recent call last):
    ...
    TypeError: robots[1] must be a RobotSpec, got str
    """
    freq = float(action_frequency)
    if not math.isfinite(freq) or freq <= 0.0:
        raise ValueError(
            f"action_frequency must be a finite number > 0 (Hz), got {action_frequency!r}"
        )
    specs = list(robots)
    for i, spec in enumerate(specs):
        if not isinstance(spec, RobotSpec):
            raise TypeError(f"robots[{i}] must be a RobotSpec, got {type(spec).__name__}")
    n_floors = int(scene.n_floors)
    if n_floors < 1 or len(scene.floors) != n_floors:
        raise ValueError(
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
    ValueError: position must be finite (x, y, z) in metres, got [1.0, 2.0]
    """
    p = np.asarray(position, dtype=np.float64)
    shapes = ((2,), (3,)) if allow_2d else ((3,),)
    if p.shape not in shapes or not np.isfinite(p).all():
        want = "(x, y) or (x, y, z)" if allow_2d else "(x, y, z)"
        raise ValueError(f"{name} must be finite {want} in metres, got {position!r}")
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
    ValueError: orientation must be a non-zero quaternion, got (0.0, 0.0, 0.0, 0.0)
    """
    q = np.asarray(orientation, dtype=np.float64)
    if q.shape != (4,) or not np.isfinite(q).all():
        raise ValueError(
            f"{name} must be a finite (x, y, z, w) quaternion of shape (4,), "
            f"got {orientation!r}"
        )
    x, y, z, w = q.tolist()
    if x * x + y * y + z * z + w * w < 1e-12:
        raise ValueError(f"{name} must be a non-zero quaternion, got {orientation!r}")
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
    return np.array(_planar_quat_floats(yaw))


def _planar_quat_floats(yaw: float) -> tuple[float, float, float, float]:
    """:func:`planar_quat` as a tuple of floats (for ``get_pose_floats``)."""
    half = 0.5 * math.remainder(yaw, 2.0 * math.pi)
    return 0.0, 0.0, math.sin(half), math.cos(half)


class RobotStateBackend:
    """Base class for a backend that keeps one state object per robot.

    It holds what the shipped backends share and a new backend may reuse: the robot and
    floor index checks, the :attr:`n_robots` and :attr:`action_frequency` properties, the
    accessors :meth:`get_velocity`, :meth:`get_robot_floor`, :meth:`in_contact` and
    :meth:`is_present`, :meth:`set_present`, and the fall of a robot whose centre is over
    VOID (:meth:`_fall`). A subclass implements the rest of the :class:`Backend` protocol
    (``load``, ``reset``, ``land``, ``set_pose``, ``get_pose``, ``step``,
    ``is_valid_pose``); :func:`check_backend` still checks that it does.

    Parameters
    ----------
    fall_speed : float
        Downward speed in m/s with which a fall starts, > 0; gravity (9.81 m/s^2) then
        accelerates it.

    Notes
    -----
    The subclass's ``load`` fills these attributes (empty, and ``0.1`` s, until then):

    ``_robots`` : list
        One state object per robot, index ``idn``, with the attributes ``floor`` (int),
        ``present``, ``falling`` and ``contact`` (bool), ``z`` (m), ``fall_speed`` (m/s)
        and ``vel``, the world velocity of the last step ``(vx, vy, vz, wz)`` in m/s and
        rad/s, as a tuple of floats.
    ``_floors`` : list
        One object per floor, index ``floor``.
    ``_dt`` : float
        Duration of one control step in seconds.

    Examples
    --------
    >>> class Points(RobotStateBackend):
    ...     def load(self, scene, robots, action_frequency=10.0):
    ...         specs, n_floors, self._dt = check_load(scene, robots, action_frequency)
    ...         self._floors = list(range(n_floors))
    ...         self._robots = [
    ...             types.SimpleNamespace(floor=0, present=True, falling=False, contact=False,
    ...                                   z=0.0, fall_speed=0.0, vel=(0.0, 0.0, 0.0, 0.0))
    ...             for _ in specs
    ...         ]
    >>> backend = Points()
    >>> backend.load(types.SimpleNamespace(floors=["map"], n_floors=1), [RobotSpec()])
    >>> backend.n_robots, backend.is_present(0), backend.get_velocity(0)[0].tolist()
    (1, True, [0.0, 0.0, 0.0])
    >>> backend.in_contact(1)
    Traceback (most recent call last):
    ...
    ValueError: idn must be in [0, 1), got 1
    """

    _robots: list[Any]
    _floors: list[Any]
    _dt: float

    def __init__(self, *, fall_speed: float = 1.0) -> None:
        fall_speed_f = float(fall_speed)
        if not math.isfinite(fall_speed_f) or fall_speed_f <= 0.0:
            raise ValueError(f"fall_speed must be a finite number > 0 (m/s), got {fall_speed!r}")
        self.fall_speed = fall_speed_f
        self._floors = []
        self._robots = []
        self._dt = 0.1

    @property
    def n_robots(self) -> int:
        """Number of robots loaded (0 before :meth:`load`)."""
        return len(self._robots)

    @property
    def action_frequency(self) -> float:
        """Control steps per second (Hz)."""
        return 1.0 / self._dt

    def _robot(self, idn: int) -> Any:
        """Robot ``idn``'s state; raises naming ``idn`` (RuntimeError before :meth:`load`)."""
        robots = self._robots
        if type(idn) is int and 0 <= idn < len(robots):
            return robots[idn]  # the common case, checked without a call
        if not robots and _is_index(idn):
            raise RuntimeError("no robots: call load(scene, robots) first")
        return robots[check_index(idn, len(robots), name="idn", what="robot")]

    def _floor(self, floor: int) -> Any:
        """Floor ``floor``'s object from ``_floors``; raises naming ``floor``."""
        return self._floors[check_index(floor, len(self._floors), name="floor", what="floor")]

    def get_velocity(self, idn: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Return robot ``idn``'s world linear (3,) m/s and angular (3,) rad/s velocity.

        These are the effective velocities of the last step: displacement and yaw change
        divided by the step's duration (zero after load, reset, land and set_pose).
        """
        rb = self._robot(idn)
        vx, vy, vz, wz = rb.vel
        return np.array((vx, vy, vz)), np.array((0.0, 0.0, wz))

    def get_velocity_floats(self, idn: int) -> tuple[float, ...]:
        """Return :meth:`get_velocity`'s six numbers as a tuple of floats, without arrays.

        ``(vx, vy, vz, wx, wy, wz)``. Not part of the :class:`Backend` protocol: an optional
        fast path that the task reads on every step instead of :meth:`get_velocity`, only
        when no subclass has overridden ``get_velocity`` below this class.
        """
        vx, vy, vz, wz = self._robot(idn).vel
        return vx, vy, vz, 0.0, 0.0, wz

    def get_robot_floor(self, idn: int) -> int:
        """The floor robot ``idn`` was last landed on (0 until then)."""
        return self._robot(idn).floor

    def in_contact(self, idn: int) -> bool:
        """Whether robot ``idn`` hit or pushed against an obstacle or robot in the last step."""
        return self._robot(idn).contact

    def set_present(self, idn: int, present: bool) -> None:
        """Take robot ``idn`` out of the world (``False``) or bring it back (``True``).

        An absent robot keeps its pose (and a fall in progress) but is not moved by
        :meth:`step`, has no velocity and collides with nothing; bringing it back does not
        check whether its pose is still free.
        """
        rb = self._robot(idn)
        rb.present = bool(present)
        if not rb.present:
            rb.contact = False
            rb.vel = (0.0, 0.0, 0.0, 0.0)

    def is_present(self, idn: int) -> bool:
        """Whether robot ``idn`` is in the world."""
        return self._robot(idn).present

    def _fall(self, rb: Any, *, first: bool) -> None:
        """Advance robot ``rb``'s fall by one control step: z drops, ``vel`` is the drop's.

        On the ``first`` step the robot starts falling at ``fall_speed`` and drops at
        least 0.05 m (so the fall shows at any rate); then gravity accelerates it.
        """
        dt = self._dt
        if first:
            rb.falling = True
            rb.fall_speed = self.fall_speed
        v0 = rb.fall_speed
        drop = v0 * dt + 0.5 * _GRAVITY * dt * dt
        if first and drop < _MIN_FIRST_DROP:
            drop = _MIN_FIRST_DROP
        rb.fall_speed = v0 + _GRAVITY * dt
        rb.z -= drop
        rb.vel = (0.0, 0.0, -drop / dt, 0.0)
