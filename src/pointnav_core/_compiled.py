"""Optional compiled kernels: numba is the ``fast`` extra, and without it the numpy paths run.

A module with a compiled path asks :func:`kernel` for its numba function; the kernel
modules (``_collision_kernel``, ``_sight_kernel``, ``vector._contact_kernel``) import
numba at their top, so they are
imported only here, on first use. Inside :func:`numpy_paths` every such module takes its
numpy path, which is how the property tests compare the two.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

__all__ = ["kernel", "numpy_paths"]

_LOADED: dict[tuple[str, str], Any] = {}
_OFF: list[bool] = []


def kernel(module: str, name: str) -> Any:
    """The function ``name`` of the kernel module ``module``, or None without numba."""
    if _OFF:
        return None
    key = (module, name)
    if key not in _LOADED:
        try:
            _LOADED[key] = getattr(importlib.import_module(module), name)
        except ModuleNotFoundError as error:
            if error.name not in ("numba", "llvmlite"):
                raise
            _LOADED[key] = None
    return _LOADED[key]


@contextmanager
def numpy_paths() -> Iterator[None]:
    """Within the block, :func:`kernel` returns None: every caller takes its numpy path."""
    _OFF.append(True)
    try:
        yield
    finally:
        _OFF.pop()
