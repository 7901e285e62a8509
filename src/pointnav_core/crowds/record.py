"""What a crowd was at an episode's start, so that a dataset episode replays it exactly.

A :class:`PedestrianRecord` is one pedestrian as :meth:`Crowd.spawn
<pointnav_core.crowds.Crowd.spawn>` placed it: its start, the goals it walks first, whether
it walks them round and round, its own seed, radius and speed. A crowd's record is a tuple
of them (:meth:`Crowd.record <pointnav_core.crowds.Crowd.record>`); spawning from it places
exactly that crowd (:mod:`pointnav_core.datasets.format` stores it in an episode).

Each pedestrian's draws come from its own generator, ``numpy.random.default_rng(seed)``:
first three uniform numbers in [0, 1) (its radius and speed within the config's ranges,
then its heading in [-pi, pi)), then the goals it draws once its goal list is used up (or
all its goals, when the list is empty). One pedestrian's replans never shift another's
draws, and a recorded radius and speed replace the first two numbers without moving the
stream.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

from pointnav_core.errors import ArgumentError
from pointnav_core.utils import validation

__all__ = ["SEED_LIMIT", "PedestrianRecord", "make_record"]

#: Pedestrian seeds are integers in ``[0, SEED_LIMIT)`` (exact in any JSON reader's double).
SEED_LIMIT = 2**53


@dataclasses.dataclass(frozen=True)
class PedestrianRecord:
    """One pedestrian of a recorded crowd (metres, m/s, world frame z up).

    Attributes
    ----------
    start : (float, float)
        Where it stands at the episode's start (m).
    goals : tuple of (float, float)
        The goals it walks to in turn (m); may be empty (all drawn).
    loop : bool
        True: ``goals`` round and round (the presets'); False: once, then drawn goals.
    seed : int
        Seed of its own generator, ``0 <= seed <`` :data:`SEED_LIMIT`.
    radius : float
        Disc radius (m), > 0.
    speed : float
        Preferred walking speed (m/s), >= 0.
    """

    start: tuple[float, float]
    goals: tuple[tuple[float, float], ...]
    loop: bool
    seed: int
    radius: float
    speed: float


#: ``error(field, must, got)``: the exception for a bad field.
Error = Callable[[str, str, Any], Exception]


def _argument_error(field: str, must: str, got: Any) -> Exception:
    return ArgumentError(f"{field} must be {must}, got {got!r}")


def _number(error: Error, name: str, value: Any, strict: bool = False, minimum: float = -math.inf) -> float:
    ok = validation.is_real(value) and math.isfinite(value)  # not a bool, not a string
    if not ok or value < minimum or (strict and value == minimum):
        raise error(name, "a finite number" + (f" {'>' if strict else '>='} {minimum}" if minimum > -math.inf else ""), value)
    return float(value)


def _point(error: Error, name: str, value: Any) -> tuple[float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise error(name, "[x, y] (m)", value)
    return _number(error, f"{name}[0]", value[0]), _number(error, f"{name}[1]", value[1])


def make_record(
    name: str, start: Any, goals: Any, loop: Any, seed: Any, radius: Any, speed: Any, error: Error | None = None
) -> PedestrianRecord:
    """A :class:`PedestrianRecord` of checked fields (plain JSON values: a tuple or list
    for a point); errors name ``name`` and the field (``{name}.seed``, ...).

    Parameters
    ----------
    name : str
        How the pedestrian is named in errors, e.g. ``"info.pedestrians[3]"``.
    start, goals, loop, seed, radius, speed
        The fields (m, m/s; see :class:`PedestrianRecord`).
    error : callable, optional
        ``error(field, must, got)`` builds the exception raised (default: an
        :class:`~pointnav_core.errors.ArgumentError` ``"{field} must be {must}, got {got!r}"``).

    Raises
    ------
    ValueError
        What ``error`` builds, for the first bad field.
    """
    error = error or _argument_error
    if not isinstance(goals, (list, tuple)):
        raise error(f"{name}.goals", "a list of [x, y] points (m)", goals)
    if not isinstance(loop, bool):
        raise error(f"{name}.loop", "true or false", loop)
    if loop and not goals:
        raise error(f"{name}.goals", f"a non-empty list when {name}.loop is true", goals)
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < SEED_LIMIT:
        raise error(f"{name}.seed", "an integer in [0, 2**53)", seed)
    return PedestrianRecord(
        start=_point(error, f"{name}.start", start),
        goals=tuple(_point(error, f"{name}.goals[{k}]", g) for k, g in enumerate(goals)),
        loop=loop,
        seed=seed,
        radius=_number(error, f"{name}.radius", radius, strict=True, minimum=0.0),
        speed=_number(error, f"{name}.speed", speed, minimum=0.0),
    )
