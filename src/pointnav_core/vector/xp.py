"""The array namespace and device of a batched engine: numpy on the CPU, or torch.

The step is written once against the handful of functions numpy and torch share
(``where``, ``minimum``, ``sqrt``, fancy indexing ...). What they spell differently lives
here and only here: constructors on the right device and the way back to numpy in
:class:`Arrays`; copies, joins, gathers, reductions, casts and sorts in the small functions
below, each given the array module ``xp`` (``numpy`` or ``torch``) and doing the same
arithmetic on both. torch is imported only when a torch device is asked for.

Examples
--------
>>> a = np.array([[3.0, 1.0, 2.0]])
>>> take_along(np, a, np.array([[2, 0]])).tolist(), amax(np, a, -1).tolist()
([[2.0, 3.0]], [3.0])
>>> cat(np, [a, a], -1).shape, stable_argsort(np, np.array([1.0, 0.0, 1.0])).tolist()
((1, 6), [1, 0, 2])
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pointnav_core.errors import ArgumentError

__all__ = ["Arrays", "amax", "as_dtype", "cat", "copy", "make_arrays", "sort", "stable_argsort", "swap_last_two",
           "take_along"]


class Arrays:
    """numpy or torch on one device, with the few calls they spell differently.

    Attributes
    ----------
    xp : module
        ``numpy`` or ``torch``.
    device : str
        ``"numpy"``, ``"cpu"`` (torch on the CPU) or a CUDA device such as ``"cuda:0"``.
    on_gpu : bool
        Whether the arrays live on a GPU (work is then batched whole, not in cache-sized blocks).
    """

    def __init__(self, xp: Any, device: str) -> None:
        self.xp = xp
        self.device = device
        self.is_torch = xp is not np
        self.on_gpu = self.is_torch and device != "cpu"
        if self.is_torch:
            self.f64, self.i64, self.boolean = xp.float64, xp.int64, xp.bool
        else:
            self.f64, self.i64, self.boolean = np.float64, np.int64, np.bool_

    def __reduce__(self) -> tuple[Any, tuple[str]]:
        # Pickled by device name (a module does not pickle), e.g. into a worker process.
        return make_arrays, (self.device,)

    def asarray(self, a: Any, dtype: Any = None) -> Any:
        """``a`` as an array of this namespace on this device (``dtype`` default: float64)."""
        dtype = self.f64 if dtype is None else dtype
        if self.is_torch:
            if isinstance(a, self.xp.Tensor):
                return a.to(device=self.device, dtype=dtype)
            return self.xp.as_tensor(np.asarray(a), dtype=dtype, device=self.device)
        return np.asarray(a, dtype=dtype)

    def discs(self, discs: tuple[Any, Any, Any, Any]) -> tuple[Any, Any, Any, Any]:
        """A world's discs ``(x, y, radius, count)`` (a crowd's, as the scan and the local map
        take them) on this device: float64 centres and radii, int64 counts."""
        return (*(self.asarray(v) for v in discs[:3]), self.asarray(discs[3], self.i64))

    def zeros(self, shape: Any, dtype: Any = None) -> Any:
        dtype = self.f64 if dtype is None else dtype
        if self.is_torch:
            return self.xp.zeros(shape, dtype=dtype, device=self.device)
        return np.zeros(shape, dtype=dtype)

    def full(self, shape: Any, value: Any, dtype: Any = None) -> Any:
        dtype = self.f64 if dtype is None else dtype
        if self.is_torch:
            shape = (shape,) if isinstance(shape, int) else tuple(shape)
            return self.xp.full(shape, value, dtype=dtype, device=self.device)
        return np.full(shape, value, dtype=dtype)

    def arange(self, n: int) -> Any:
        if self.is_torch:
            return self.xp.arange(n, device=self.device)
        return np.arange(n)

    def to_int(self, a: Any) -> Any:
        return a.to(self.i64) if self.is_torch else a.astype(np.int64)

    def nonzero(self, mask: Any) -> Any:
        """Indices of the True entries of a 1-D mask."""
        if self.is_torch:
            return self.xp.nonzero(mask).reshape(-1)
        return np.flatnonzero(mask)

    def any(self, mask: Any) -> bool:
        return bool(mask.any())

    def numpy(self, a: Any) -> np.ndarray:
        """A numpy copy of ``a`` (a fresh array)."""
        if self.is_torch:
            return a.detach().cpu().numpy()
        return np.array(a)


def copy(xp: Any, a: Any) -> Any:
    """A fresh copy of ``a`` (``clone`` in torch)."""
    return a.copy() if xp is np else a.clone()


def cat(xp: Any, parts: Any, axis: int = 0) -> Any:
    """``parts`` joined along ``axis`` (``concatenate``; ``cat`` in torch)."""
    return np.concatenate(parts, axis) if xp is np else xp.cat(parts, axis)


def take_along(xp: Any, a: Any, idx: Any) -> Any:
    """``a``'s entries at the integer indices ``idx`` along the last axis (``gather`` in torch)."""
    return np.take_along_axis(a, idx, -1) if xp is np else xp.gather(a, -1, idx)


def amax(xp: Any, a: Any, axis: int) -> Any:
    """The maximum of ``a`` along ``axis`` (values only; ``amax`` in torch)."""
    return a.max(axis) if xp is np else a.amax(axis)


def swap_last_two(xp: Any, a: Any) -> Any:
    """``a`` with its last two axes swapped (a view)."""
    return np.swapaxes(a, -1, -2) if xp is np else a.transpose(-1, -2)


def as_dtype(xp: Any, a: Any, dtype: Any) -> Any:
    """``a`` cast to ``dtype`` (``xp.float32`` ...; ``to`` in torch)."""
    return a.astype(dtype) if xp is np else a.to(dtype)


def stable_argsort(xp: Any, a: Any) -> Any:
    """Indices that sort ``a`` along its last axis, equal values in their original order
    (torch's default sort is not stable)."""
    return np.argsort(a, -1, kind="stable") if xp is np else xp.argsort(a, dim=-1, stable=True)


def sort(xp: Any, a: Any) -> Any:
    """``a`` sorted along its last axis (values only; torch also returns the indices)."""
    return np.sort(a, -1) if xp is np else xp.sort(a, -1)[0]


def make_arrays(device: Any) -> Arrays:
    """The namespace for ``device``: ``"numpy"`` (the default engine), ``"cpu"`` or ``"cuda[:n]"`` (torch).

    Raises
    ------
    ValueError
        Naming ``device``: not a string, not one of these, torch missing, or a CUDA device
        on a machine without CUDA.
    """
    if not isinstance(device, str):
        raise ArgumentError(f"device must be 'numpy', 'cpu' or 'cuda[:n]', got {device!r}")
    if device == "numpy":
        return Arrays(np, "numpy")
    if device != "cpu" and not (device == "cuda" or device.startswith("cuda:")):
        raise ArgumentError(f"device must be 'numpy', 'cpu' or 'cuda[:n]', got {device!r}")
    try:
        import torch
    except ImportError:
        raise ArgumentError(
            f"device {device!r} needs torch: install the 'vector' extra (pip install 'pointnav-core[vector]')"
        ) from None
    if device != "cpu":
        if not torch.cuda.is_available():
            raise ArgumentError(f"device {device!r} asks for CUDA, but torch finds no CUDA device here")
        index = device.partition(":")[2]
        if index and (not index.isdigit() or int(index) >= torch.cuda.device_count()):
            raise ArgumentError(f"device {device!r} names no CUDA device of {torch.cuda.device_count()}")
    return Arrays(torch, device)
