"""The sensors' argument checks: :mod:`pointnav_core.utils.validation` under the names and
keywords the sensor modules use. Each error names the parameter."""

from __future__ import annotations

from typing import Any

from pointnav_core.utils import validation

__all__ = ["check_int", "check_number"]


def check_number(
    name: str,
    value: Any,
    *,
    low: float | None = None,
    high: float | None = None,
    strict_low: bool = False,
    unit: str = "",
) -> float:
    """``value`` as a finite float in range (a bool or a string is not a number).

    >>> check_number("max_range", 5, low=0.0, strict_low=True, unit="m")
    5.0
    >>> check_number("max_range", True, low=0.0)
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: max_range must be a finite number >= 0, got True
    """
    return validation.real(name, value, minimum=low, strict=strict_low, maximum=high, unit=unit)


def check_int(name: str, value: Any, minimum: int) -> int:
    """``value`` as an int >= ``minimum`` (a bool or 2.0 is not an integer)."""
    return validation.integer(name, value, minimum=minimum)
