"""The registry of checks, and the ways to run them: pytest, code, the command line."""

from __future__ import annotations

import importlib
import time
import traceback
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

from pointnav_core.backends.protocol import get_backend
from pointnav_core.errors import ArgumentError, ArgumentTypeError
from pointnav_core.testing.conformance.common import BackendFactory, ConformanceError
from pointnav_core.testing.conformance.motion import (
    check_determinism,
    check_falling,
    check_no_tunnelling,
    check_open_space_motion,
    check_robot_contact,
    check_velocity_matches_motion,
    check_wall_contact,
)
from pointnav_core.testing.conformance.poses import (
    check_absent_robots,
    check_fast_paths,
    check_landing,
    check_pose_round_trip,
    check_protocol,
    check_reset,
    check_valid_pose,
)

__all__ = [
    "CHECKS",
    "Check",
    "CheckResult",
    "assert_conforms",
    "backend_factory",
    "format_report",
    "get_check",
    "run_checks",
]


@dataclass(frozen=True)
class Check:
    """One named conformance check.

    Parameters
    ----------
    name : str
        Short identifier, e.g. ``"wall_contact"``.
    func : callable
        ``func(factory)``: runs the check on backends made by ``factory()``; raises
        :class:`AssertionError` with a readable message when the backend fails it.

    Examples
    --------
    >>> check = get_check("pose_round_trip")
    >>> str(check)
    'pose_round_trip'
    >>> check.summary  # the first line of its docstring
    '``set_pose`` then ``get_pose`` returns the same position and rotation (1e-9).'
    >>> check(backend_factory("kinematic"))  # passes: returns None
    """

    name: str
    func: Callable[[BackendFactory], None]

    @property
    def summary(self) -> str:
        """The first line of the check's docstring."""
        return (self.func.__doc__ or self.name).strip().splitlines()[0]

    def __call__(self, factory: BackendFactory) -> None:
        self.func(factory)

    def __str__(self) -> str:
        return self.name


#: Every check, in the order they run.
CHECKS: tuple[Check, ...] = tuple(
    Check(name, func)
    for name, func in (
        ("protocol", check_protocol),
        ("pose_round_trip", check_pose_round_trip),
        ("open_space_motion", check_open_space_motion),
        ("velocity_matches_motion", check_velocity_matches_motion),
        ("wall_contact", check_wall_contact),
        ("robot_contact", check_robot_contact),
        ("no_tunnelling", check_no_tunnelling),
        ("valid_pose", check_valid_pose),
        ("landing", check_landing),
        ("falling", check_falling),
        ("absent_robots", check_absent_robots),
        ("reset", check_reset),
        ("fast_paths", check_fast_paths),
        ("determinism", check_determinism),
    )
)


def get_check(name: str) -> Check:
    """Return the check called ``name``.

    Raises
    ------
    ValueError
        If there is no such check; the message lists the valid names.

    Examples
    --------
    >>> get_check("falling").name
    'falling'
    >>> get_check("flying")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: check must be one of ['protocol', ..., 'determinism'], got 'flying'
    """
    for check in CHECKS:
        if check.name == name:
            return check
    raise ArgumentError(f"check must be one of {[c.name for c in CHECKS]}, got {name!r}")


def backend_factory(backend: str | type | Callable[[], Any]) -> BackendFactory:
    """Turn a backend name, class or factory into a factory of fresh backends.

    Parameters
    ----------
    backend : str or type or callable
        A registered name (see :func:`~pointnav_core.backends.protocol.available_backends`), a
        ``"package.module:Class"`` path, a backend class (built with no arguments), or a
        callable returning a fresh, unloaded backend each time it is called.

    Returns
    -------
    callable
        ``factory()`` returns a new backend.

    Raises
    ------
    UnknownBackendError
        For a name that is not registered (a ValueError; the message lists the names).
    TypeError
        For anything else.

    Examples
    --------
    >>> factory = backend_factory("kinematic")
    >>> type(factory()).__name__
    'KinematicBackend'
    >>> factory() is factory()
    False
    """
    if isinstance(backend, str):
        if ":" in backend:
            module, _, attr = backend.partition(":")
            target = importlib.import_module(module)
            for part in attr.split("."):
                target = getattr(target, part)
            return backend_factory(target)
        cls = get_backend(backend)
        return cls
    if callable(backend):
        return backend
    raise ArgumentTypeError(
        "backend must be a backend name, a class or a factory callable, got "
        f"{type(backend).__name__}"
    )


@dataclass(frozen=True)
class CheckResult:
    """The outcome of one check on one backend.

    Attributes
    ----------
    name : str
        The check's name.
    passed : bool
        Whether the backend passed.
    message : str
        Empty when passed; otherwise why it failed (an unexpected exception is reported
        with its type and where it was raised).
    seconds : float
        How long the check ran, in seconds.
    """

    name: str
    passed: bool
    message: str
    seconds: float


def _describe(exc: BaseException) -> str:
    if isinstance(exc, AssertionError):
        return str(exc) or "assertion failed"
    # Point at the innermost frame outside numpy: the backend's or the check's own line.
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if "/numpy/" not in f.filename]
    if not frames:
        return f"raised {type(exc).__name__}: {exc}"
    last = frames[-1]
    where = f" (at {last.filename}:{last.lineno} in {last.name})"
    return f"raised {type(exc).__name__}: {exc}{where}"


def run_checks(
    backend: str | type | Callable[[], Any], checks: Iterable[Check | str] | None = None
) -> list[CheckResult]:
    """Run conformance checks on a backend and return one result per check.

    Parameters
    ----------
    backend : str or type or callable
        See :func:`backend_factory`.
    checks : iterable of Check or str, optional
        Which checks to run (default: all of :data:`CHECKS`, in order).

    Returns
    -------
    list of CheckResult

    Examples
    --------
    >>> results = run_checks("kinematic", ["protocol", "falling"])
    >>> [(r.name, r.passed) for r in results]
    [('protocol', True), ('falling', True)]
    """
    factory = backend_factory(backend)
    chosen = CHECKS if checks is None else checks
    selected = [get_check(c) if isinstance(c, str) else c for c in chosen]
    results = []
    for check in selected:
        start = time.perf_counter()
        try:
            check(factory)
        except Exception as exc:  # a check fails on any error, and the run goes on
            seconds = time.perf_counter() - start
            results.append(CheckResult(check.name, False, _describe(exc), seconds))
        else:
            results.append(CheckResult(check.name, True, "", time.perf_counter() - start))
    return results


def format_report(results: Sequence[CheckResult], title: str = "") -> str:
    """Render results as text: an optional title, one line per check, then a summary.

    Examples
    --------
    >>> print(format_report([CheckResult("falling", False, "it floats", 0.01),
    ...                      CheckResult("reset", True, "", 0.002)]))
    FAIL  falling  it floats
    PASS  reset
    2 checks: 1 passed, 1 failed
    """
    width = max((len(r.name) for r in results), default=0)
    lines = [title] if title else []
    for r in results:
        status = "PASS" if r.passed else "FAIL"
        line = f"{status}  {r.name:<{width}}"
        lines.append(f"{line}  {r.message}" if r.message else line.rstrip())
    failed = sum(not r.passed for r in results)
    lines.append(f"{len(results)} checks: {len(results) - failed} passed, {failed} failed")
    return "\n".join(lines)


def assert_conforms(
    backend: str | type | Callable[[], Any], checks: Iterable[Check | str] | None = None
) -> None:
    """Raise :class:`ConformanceError` unless the backend passes every check.

    Parameters
    ----------
    backend : str or type or callable
        See :func:`backend_factory`.
    checks : iterable of Check or str, optional
        Which checks to run (default: all).

    Raises
    ------
    ConformanceError
        (a BackendError and an AssertionError) whose message lists each failed check and
        why.

    Examples
    --------
    >>> assert_conforms("kinematic", ["protocol", "valid_pose"])
    """
    results = run_checks(backend, checks)
    failed = [r for r in results if not r.passed]
    if failed:
        name = getattr(backend, "__name__", None) or str(backend)
        raise ConformanceError(
            f"backend {name} failed {len(failed)} of {len(results)} conformance checks:\n"
            + "\n".join(f"  {r.name}: {r.message}" for r in failed)
        )
