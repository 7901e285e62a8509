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

Float twins
-----------
Beside the protocol, a backend may offer a fast path for the task's per-step reads: a
*float twin* of a protocol method returns that method's numbers as one flat tuple of
Python floats, without building arrays (:data:`FLOAT_TWINS`, :class:`FloatTwinBackend`):

================================  ================  ================================
Float twin                        mirrors           returns
================================  ================  ================================
``get_pose_floats(idn)``          ``get_pose``      ``(x, y, z, qx, qy, qz, qw)``
``get_velocity_floats(idn)``      ``get_velocity``  ``(vx, vy, vz, wx, wy, wz)``
================================  ================  ================================

A twin must give exactly the numbers of its method (the conformance check
``fast_paths`` compares them). The task reads a twin only where :func:`float_twin` binds
it: when it is defined at least as far down the class hierarchy as the method it mirrors
(so a subclass that overrides ``get_pose`` alone is still read through ``get_pose``) and
neither is set on the instance. Both shipped backends have both twins.

Writing a backend
-----------------
:mod:`pointnav_core.backends.kit` is the author's kit: :class:`RobotStateBackend` (a base
class that implements every method but ``load`` and ``step``, the twins included), the
robot state, the exact drive motion, the floor grid and the argument checks, with a guide.
"""

from __future__ import annotations

import inspect
import types
from collections.abc import Callable, Mapping, Sequence
from importlib.metadata import entry_points
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.errors import ArgumentError, BackendError

__all__ = [
    "ENTRY_POINT_GROUP",
    "FLOAT_TWINS",
    "Backend",
    "FloatTwinBackend",
    "UnknownBackendError",
    "available_backends",
    "check_backend",
    "float_twin",
    "get_backend",
    "make_backend",
]

#: Entry-point group under which backends register ``name = "module:Class"``.
ENTRY_POINT_GROUP = "pointnav_core.backends"


class UnknownBackendError(BackendError, ValueError):
    """No backend is installed under the requested name.

    It is both a :class:`~pointnav_core.errors.BackendError` (what went wrong) and a
    :class:`ValueError` (a bad argument value), so either ``except`` clause catches it.
    """


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


#: The optional float twins of protocol methods: twin name -> the method it mirrors.
FLOAT_TWINS = types.MappingProxyType(
    {"get_pose_floats": "get_pose", "get_velocity_floats": "get_velocity"}
)


@runtime_checkable
class FloatTwinBackend(Backend, Protocol):
    """A :class:`Backend` with both float twins (:data:`FLOAT_TWINS`), the task's fast path.

    Each twin returns the numbers of the method it mirrors, the same values, as one flat
    tuple of Python floats.
    """

    def get_pose_floats(self, idn: int) -> tuple[float, ...]:
        """``get_pose(idn)``'s position and quaternion: ``(x, y, z, qx, qy, qz, qw)``."""
        ...

    def get_velocity_floats(self, idn: int) -> tuple[float, ...]:
        """``get_velocity(idn)``'s linear and angular parts: ``(vx, vy, vz, wx, wy, wz)``."""
        ...


def float_twin(backend: Any, twin: str) -> Callable[[int], tuple[float, ...]] | None:
    """Return ``backend``'s bound float ``twin``, or None where the task must not use it.

    A twin (a key of :data:`FLOAT_TWINS`) stands in for its method only if the class that
    defines it is the class that defines the method or a subclass of it, and neither is
    set on the instance: a subclass or a patch that changes ``get_pose`` but not
    ``get_pose_floats`` is read through ``get_pose``.

    Examples
    --------
    >>> backend = make_backend("kinematic")
    >>> float_twin(backend, "get_pose_floats") is not None
    True
    >>> class Shifted(type(backend)):
    ...     def get_pose(self, idn):
    ...         position, orientation = super().get_pose(idn)
    ...         return position + 1.0, orientation
    >>> float_twin(Shifted(), "get_pose_floats") is None  # its twin is inherited: stale
    True
    """
    method = FLOAT_TWINS[twin]
    patched = getattr(backend, "__dict__", ())
    if twin in patched or method in patched:
        return None
    mro = type(backend).__mro__
    twin_owner = next((cls for cls in mro if twin in vars(cls)), None)
    method_owner = next((cls for cls in mro if method in vars(cls)), None)
    if twin_owner is None or method_owner is None or not issubclass(twin_owner, method_owner):
        return None
    return getattr(backend, twin)


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
        raise ArgumentError(
            f"backend arguments {sorted(kwargs)} only apply when backend is a name or a "
            f"class, got an instance of {type(backend).__name__}"
        )
    return backend


# The author's kit moved to pointnav_core.backends.kit, which builds on this module; its
# names stay importable from here, loaded on first use (PEP 562).
_KIT_NAMES = frozenset(
    {
        "RobotStateBackend",
        "check_index",
        "check_load",
        "parse_orientation",
        "parse_position",
        "planar_quat",
    }
)

if TYPE_CHECKING:
    pass


def __getattr__(name: str) -> Any:
    if name in _KIT_NAMES:
        from pointnav_core.backends import kit as backend_kit

        return getattr(backend_kit, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
