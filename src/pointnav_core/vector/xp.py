"""The array namespace and device of a batched engine: numpy on the CPU, or torch.

The step is written once against the handful of functions numpy and torch share
(``where``, ``minimum``, ``sqrt``, fancy indexing ...). What they spell differently lives
here, in :class:`Arrays`: casts, constructors on the right device and the way back to
numpy. torch is imported only when a torch device is asked for.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pointnav_core.errors import ArgumentError

__all__ = ["Arrays", "make_arrays"]


class Arrays:
    """numpy or torch on one device, with the few calls they spell differently.

    Attributes
    ----------
    xp : module
        ``numpy`` or ``torch``.
    device : str
        ``"numpy"``, ``"cpu"`` (torch on the CPU) or a CUDA device such as ``"cuda:0"``.
    """

    def __init__(self, xp: Any, device: str) -> None:
        self.xp = xp
        self.device = device
        self.is_torch = xp is not np
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
