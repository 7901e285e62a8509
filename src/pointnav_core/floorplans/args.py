"""Argument checks shared by the floor-plan generators (see :mod:`pointnav_core.utils.validation`)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import shapely
from shapely.geometry import MultiPolygon, Polygon

from pointnav_core.errors import ArgumentError, ArgumentTypeError
from pointnav_core.utils import validation

__all__ = [
    "Seed",
    "check_pair",
    "check_polygon",
    "check_positive",
    "check_probability",
    "check_range",
    "rng_from",
]

Seed = int | np.random.SeedSequence | np.random.Generator | None


def check_polygon(geom: object, name: str) -> None:
    if not isinstance(geom, Polygon):
        hint = " (split it with shapely.get_parts)" if isinstance(geom, MultiPolygon) else ""
        raise ArgumentTypeError(f"{name} must be a shapely Polygon, got {type(geom).__name__}{hint}")
    if geom.is_empty:
        raise ArgumentError(f"{name} must be a non-empty Polygon")
    if not geom.is_valid:
        raise ArgumentError(f"{name} must be a valid Polygon: {shapely.is_valid_reason(geom)}")


def check_positive(value: float, name: str, unit: str = "m") -> float:
    return validation.real(name, value, minimum=0.0, strict=True, unit=unit)


def check_pair(value: Sequence[float], name: str, meaning: str) -> tuple[float, float]:
    try:
        a, b = validation.vector(name, value, sizes=(2,))
    except ValueError:
        raise ArgumentError(f"{name} must be two numbers {meaning}, got {value!r}") from None
    if not (a > 0.0 and b > 0.0):
        raise ArgumentError(f"{name} must be two finite numbers > 0 {meaning}, got {value!r}")
    return float(a), float(b)


def check_range(value: Sequence[float], name: str) -> tuple[float, float]:
    lo, hi = check_pair(value, name, "(min, max) in metres")
    if lo > hi:
        raise ArgumentError(f"{name} must be (min, max) with min <= max, got {value!r}")
    return lo, hi


def rng_from(seed: object) -> np.random.Generator:
    """A Generator from ``seed``: None, an int >= 0, a SeedSequence or a Generator."""
    if seed is None or isinstance(seed, (np.random.SeedSequence, np.random.Generator)):
        return np.random.default_rng(seed)
    return np.random.default_rng(validation.integer("seed", seed, minimum=0))


def check_probability(value: float, name: str) -> float:
    if not (validation.is_real(value) and 0.0 <= value <= 1.0):
        raise ArgumentError(f"{name} must be a probability in [0, 1], got {value!r}")
    return float(value)
