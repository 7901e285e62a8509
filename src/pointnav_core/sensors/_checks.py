"""Argument checks shared by the sensors: each error names the parameter."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["check_int", "check_number"]


def check_number(
    name: str, value: Any, *, low: float | None = None, high: float | None = None,
    strict_low: bool = False, unit: str = "",
) -> float:
    """Return ``value`` as a finite float in range, or raise ValueError naming ``name``.

    A bool is not a number, nor is a string.

    Examples
    --------
    >>> check_number("max_range", 5, low=0.0, strict_low=True, unit="m")
    5.0
    >>> check_number("max_range", True, low=0.0)
    Traceback (most recent call last):
    ...
    ValueError: max_range must be a finite number >= 0.0, got True
    """
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
        value, (bool, np.bool_)
    )
    number = float(value) if ok else math.nan
    bound = ""
    if low is not None:
        bound = f" {'>' if strict_low else '>='} {low}"
        ok = ok and (number > low if strict_low else number >= low)
    if high is not None:
        bound += f"{' and' if bound else ''} <= {high:.6g}"
        ok = ok and number <= high
    if not (ok and math.isfinite(number)):
        suffix = f" ({unit})" if unit else ""
        raise ValueError(f"{name} must be a finite number{bound}{suffix}, got {value!r}")
    return number


def check_int(name: str, value: Any, minimum: int) -> int:
    """Return ``value`` as an int >= ``minimum``, or raise ValueError naming ``name``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)
