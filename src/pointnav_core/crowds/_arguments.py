"""Argument checks shared by the crowd steps (:mod:`~pointnav_core.crowds.orca`,
:mod:`~pointnav_core.crowds.social_force`): per-agent vectors and per-agent numbers, refused
with an :class:`~pointnav_core.errors.ArgumentError` naming the argument."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import DTypeLike, NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.utils.validation import is_real_array

__all__ = ["agents", "per_agent"]


def agents(name: str, value: Any, shape: tuple[int, ...] | None, dtype: DTypeLike = np.float64) -> NDArray[Any]:
    """``value`` as an array of ``dtype`` of ``(n, 2)`` or ``(w, n, 2)`` finite numbers (of
    ``shape`` when given), each within ``dtype``'s range (float32's when it is float32)."""
    arr = np.asarray(value) if is_real_array(value) else None
    ok = arr is not None and arr.ndim in (2, 3) and arr.shape[-1] == 2 and (shape is None or arr.shape == shape)
    if ok:
        arr = arr.astype(np.float64)
        ok = bool(np.isfinite(arr).all() and (np.abs(arr) <= np.finfo(dtype).max).all())
    if not ok:
        want = "an (n, 2) or (w, n, 2) array" if shape is None else f"an array of shape {shape}"
        raise ArgumentError(f"{name} must be {want} of finite numbers (m, m/s), got {value!r}")
    return np.ascontiguousarray(arr, dtype=dtype)


def per_agent(name: str, value: Any, shape: tuple[int, int], unit: str, dtype: DTypeLike = np.float64) -> NDArray[Any]:
    """``value`` (a number, one per agent ``(n,)`` or per world and agent ``(w, n)``) as a
    ``(w, n)`` array of ``dtype`` of finite numbers >= 0."""
    if not (is_real_array(value) or isinstance(value, (int, float, np.integer, np.floating))) or isinstance(value, bool):
        raise ArgumentError(f"{name} must be a number >= 0 ({unit}) or one per agent, got {value!r}")
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim > 2 or arr.shape not in ((), shape[1:], shape) or not (np.isfinite(arr).all() and (arr >= 0).all()):
        raise ArgumentError(
            f"{name} must be a finite number >= 0 ({unit}), or an array of shape {shape[1:]} or {shape} "
            f"of them, got {value!r}"
        )
    return np.ascontiguousarray(np.broadcast_to(arr.astype(dtype), shape))
