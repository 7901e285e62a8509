"""Argument checks: one rule for what counts as a number, everywhere.

Every public constructor and function checks its arguments with these helpers, so that
the same value is accepted or refused the same way wherever it is passed. The rules:

- a number is an ``int`` or ``float`` (or a numpy integer or floating scalar); a ``bool``
  is not a number (``True`` is not a radius of 1 m), a string is not a number (``"0.2"``
  is not 0.2 m), and a complex number is not a real one;
- a sequence of numbers is a list, tuple or numeric array of such numbers; a string is
  not a sequence of numbers (``"12"`` is not ``(1, 2)``);
- a refusal is a ``ValueError`` whose message starts with the parameter's name and says
  what was expected, with the unit.

>>> real("radius", 0.2, minimum=0.0)
0.2
>>> real("radius", True, minimum=0.0)
Traceback (most recent call last):
...
pointnav_core.errors.ArgumentError: radius must be a finite number >= 0 (m), got True
>>> vector("goal_pos", "12", sizes=(2, 3))
Traceback (most recent call last):
...
pointnav_core.errors.ArgumentError: goal_pos must be 2 or 3 finite numbers, got '12'
"""

from __future__ import annotations

import math
import operator
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.errors import ArgumentError

__all__ = [
    "MAX_CELLS", "boolean", "cell_budget", "goal_tolerance", "integer", "is_real", "is_real_array",
    "known_keys", "real", "vector",
]

_REAL_KINDS = "biuf"  # numpy dtype kinds that hold real numbers (b: refused below)

#: The cell budget of every grid and image a loader accepts: a floor grid, an image's pixels,
#: a MovingAI map's characters. A floor's derived tables take tens of bytes per cell, so
#: 1e8 cells already need gigabytes. Read at each call: a program may raise it.
MAX_CELLS = 100_000_000


def is_real(value: Any) -> bool:
    """Whether ``value`` is a real number: int, float or a numpy real scalar, not a bool."""
    if isinstance(value, (bool, np.bool_)):
        return False
    return isinstance(value, (int, float, np.integer, np.floating))


def is_real_array(value: Any) -> bool:
    """Whether ``value`` holds real numbers only, whatever its shape: a numpy array of an
    integer or floating dtype, a torch tensor of one (checked without importing torch), or
    a list or tuple (nested or not) of real numbers (:func:`is_real`) and such arrays.
    Booleans, complex numbers, strings and objects are not real numbers.

    >>> is_real_array([[0.5, 1], [np.float32(0.2), -1]]), is_real_array(np.array([1.0, 0.0]))
    (True, True)
    >>> is_real_array([0.5, True]), is_real_array(np.array([1 + 1j, 0])), is_real_array("12")
    (False, False, False)
    """
    if isinstance(value, (list, tuple)):
        return all(is_real(v) or is_real_array(v) for v in value)
    if isinstance(value, np.ndarray):
        return value.dtype.kind in "iuf"
    dtype = getattr(value, "dtype", None)
    if type(value).__module__.split(".")[0] == "torch" and dtype is not None:
        return not dtype.is_complex and str(dtype) != "torch.bool"
    return False


def _bound(minimum: float | None, strict: bool, maximum: float | None) -> str:
    parts = []
    if minimum is not None:
        parts.append(f"{'>' if strict else '>='} {minimum:g}")
    if maximum is not None:
        parts.append(f"<= {maximum:g}")
    return " " + " and ".join(parts) if parts else ""


def real(
    name: str,
    value: Any,
    *,
    minimum: float | None = None,
    strict: bool = False,
    maximum: float | None = None,
    finite: bool = True,
    unit: str = "m",
) -> float:
    """``value`` as a float, or a ValueError naming ``name``.

    Parameters
    ----------
    name : str
        The parameter's name, for the message.
    value : Any
        A real number (see the module notes).
    minimum, maximum : float, optional
        Bounds; ``strict`` makes the minimum exclusive.
    finite : bool
        Refuse infinities (NaN is always refused).
    unit : str
        Unit named in the message.
    """
    number = float(value) if is_real(value) else math.nan
    ok = not math.isnan(number) and (math.isfinite(number) or not finite)
    if ok and minimum is not None:
        ok = number > minimum if strict else number >= minimum
    if ok and maximum is not None:
        ok = number <= maximum
    if not ok:
        kind = "a finite number" if finite else "a number"
        suffix = f" ({unit})" if unit else ""
        raise ArgumentError(f"{name} must be {kind}{_bound(minimum, strict, maximum)}{suffix}, got {value!r}")
    return number


def goal_tolerance(name: str, value: Any) -> float:
    """A success radius (m) as a float: finite and > 0, or a ValueError naming ``name``.

    Zero is refused: success is a distance *below* the radius, so at 0 m no episode could
    ever succeed, and every one would silently run to its step limit.

    >>> goal_tolerance("goal_tolerance", 0)
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: goal_tolerance must be a finite number > 0 (m), got 0
    """
    return real(name, value, minimum=0.0, strict=True, unit="m")


def integer(name: str, value: Any, *, minimum: int | None = None) -> int:
    """``value`` as an int, or a ValueError naming ``name`` (no bools, no 2.0)."""
    number = None
    if not isinstance(value, (bool, np.bool_)):
        try:
            number = operator.index(value)
        except TypeError:
            number = None
    if number is None or (minimum is not None and number < minimum):
        bound = "" if minimum is None else f" >= {minimum}"
        raise ArgumentError(f"{name} must be an integer{bound}, got {value!r}")
    return int(number)


def known_keys(name: str, keys: Any, valid: Any) -> None:
    """Raise ValueError naming ``name`` and its first key not in ``valid`` (listed), if any.

    >>> known_keys("robot", {"size": 1}, ("radius", "drive"))
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: robot has an unknown key 'size'; valid keys are ['radius', 'drive']
    """
    for key in keys:
        if key not in valid:
            raise ArgumentError(f"{name} has an unknown key {key!r}; valid keys are {list(valid)}")


def cell_budget(name: str, rows: int, cols: int) -> None:
    """Refuse a grid of ``rows x cols`` cells beyond :data:`MAX_CELLS`, before it is built.

    Every grid and image loader calls this with the size it is about to read or build, so
    the same budget holds everywhere and a huge file is refused before it is decoded.

    >>> cell_budget("grid", 20000, 20000)
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: grid is 20000 x 20000 = 400000000 cells, over the cell budget of 100000000 (pointnav_core.utils.validation.MAX_CELLS)
    """
    if rows * cols > MAX_CELLS:
        raise ArgumentError(
            f"{name} is {rows} x {cols} = {rows * cols} cells, over the cell budget of "
            f"{MAX_CELLS} (pointnav_core.utils.validation.MAX_CELLS)"
        )


def boolean(name: str, value: Any) -> bool:
    """``value`` as a bool: only ``True``/``False`` (and numpy's) are accepted."""
    if not isinstance(value, (bool, np.bool_)):
        raise ArgumentError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def vector(
    name: str, value: Any, *, sizes: tuple[int, ...], finite: bool = True
) -> NDArray[np.float64]:
    """``value`` as a 1-D float64 array of one of ``sizes`` numbers, or a ValueError.

    A list or tuple must hold real numbers (see :func:`is_real`); an array must have a
    real, non-boolean dtype. Strings, bools and complex numbers are refused.
    """
    arr = None
    if isinstance(value, np.ndarray):
        if value.dtype.kind in _REAL_KINDS and value.dtype.kind != "b":
            arr = value.astype(np.float64).reshape(-1) if value.ndim <= 1 else None
    elif isinstance(value, (list, tuple)) and all(is_real(v) for v in value):
        arr = np.array(value, dtype=np.float64)
    ok = arr is not None and arr.shape[0] in sizes and not np.isnan(arr).any()
    if ok and finite:
        ok = bool(np.isfinite(arr).all())
    if not ok:
        count = " or ".join(str(s) for s in sizes)
        kind = "finite numbers" if finite else "numbers"
        raise ArgumentError(f"{name} must be {count} {kind}, got {value!r}")
    return arr  # type: ignore[return-value]
