"""Optional compiled kernels: numba is the ``fast`` extra, and without it the numpy paths run.

A module with a compiled path asks :func:`kernel` for its numba function; the kernel
modules (``_collision_kernel``, ``_sight_kernel``, ``vector._contact_kernel``) import
numba at their top, so they are
imported only here, on first use. Inside :func:`numpy_paths` every such module takes its
numpy path, which is how the property tests compare the two.

Kernels are compiled with ``cache=True``. numba keeps its cache next to the module or in
the user's cache folder; on a read-only install with no writable home (a container run as
another user) it finds neither and refuses to compile at all. :func:`kernel_module` then
points numba at a private folder in the system's temporary folder, and if there is none
either, runs the numpy paths (with a ``RuntimeWarning``): slower, never a crash.
"""

from __future__ import annotations

import importlib
import os
import tempfile
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from types import ModuleType
from typing import Any

__all__ = ["kernel", "kernel_module", "numpy_paths"]

_LOADED: dict[tuple[str, str], Any] = {}
_OFF: list[bool] = []


def _cannot_cache(error: RuntimeError) -> bool:
    return "cannot cache function" in str(error)


def _private_cache() -> str | None:
    """A folder for numba's cache owned by this user only, or None where none can be made."""
    try:
        folder = os.path.join(tempfile.gettempdir(), f"pointnav_core-numba-{os.getuid()}")
        os.makedirs(folder, mode=0o700, exist_ok=True)
        # A folder someone else made in a shared /tmp could feed us their compiled code.
        if os.stat(folder).st_uid != os.getuid() or not os.access(folder, os.W_OK):
            return None
        return folder
    except (OSError, AttributeError):  # AttributeError: no getuid (Windows)
        return None


def kernel_module(module: str) -> ModuleType | None:
    """Import the kernel module ``module``, or None without numba (or without any cache).

    Raises whatever else the import raises.
    """
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as error:
        if error.name not in ("numba", "llvmlite"):
            raise
        return None
    except RuntimeError as error:
        if not _cannot_cache(error):
            raise
    folder = _private_cache()
    if folder is not None:
        import numba

        numba.config.CACHE_DIR = folder  # read by numba each time a kernel is decorated
        try:
            return importlib.import_module(module)
        except RuntimeError as error:
            if not _cannot_cache(error):
                raise
    warnings.warn(
        "numba finds no writable folder for its cache (set NUMBA_CACHE_DIR); "
        "pointnav_core runs its numpy paths instead of the compiled kernels",
        RuntimeWarning,
        stacklevel=2,
    )
    return None


def kernel(module: str, name: str) -> Any:
    """The function ``name`` of the kernel module ``module``, or None without numba."""
    if _OFF:
        return None
    key = (module, name)
    if key not in _LOADED:
        loaded = kernel_module(module)
        _LOADED[key] = None if loaded is None else getattr(loaded, name)
    return _LOADED[key]


@contextmanager
def numpy_paths() -> Iterator[None]:
    """Within the block, :func:`kernel` returns None: every caller takes its numpy path."""
    _OFF.append(True)
    try:
        yield
    finally:
        _OFF.pop()
