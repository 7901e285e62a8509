"""Optional compiled kernels: numba is the ``fast`` extra, and without it the array paths run.

Every compiled function is obtained here, by :func:`kernel` (module and name), and by no
other import: the kernel modules (the ``_*kernel`` modules of ``floor``, ``geodesic``,
``sensors`` and ``vector``) import numba at their top, so they are imported only here, on
first use. Inside :func:`numpy_paths` :func:`kernel` returns None, so every caller takes
its plain path, which is how the property tests compare the two
(``property_tests/test_compiled_paths.py``, one check per kernel).

A public ``method=`` parameter picks a path by one of :data:`METHODS`: ``"array"`` the
plain path (whole-array numpy, or torch in the batched engine), ``"numba"`` the compiled
one, ``"auto"`` the compiled one where it can run. :func:`check_method` refuses any other
word and :func:`choose` gives the function to run.

Kernels are compiled with ``cache=True``. numba keeps its cache next to the module or in
the user's cache folder; on a read-only install with no writable home (a container run as
another user) it finds neither and refuses to compile at all. :func:`kernel_module` then
points numba at a private folder in the system's temporary folder, and if there is none
either, runs the plain paths (with a ``RuntimeWarning``): slower, never a crash.
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

from pointnav_core.errors import ArgumentError

__all__ = ["METHODS", "check_method", "choose", "kernel", "kernel_module", "numpy_paths"]

#: The values of every public ``method=`` parameter: the compiled path where it can run,
#: the plain (array) path, the compiled path or an error.
METHODS = ("auto", "array", "numba")

_LOADED: dict[tuple[str, str], Any] = {}
_OFF: list[bool] = []
_UNSEEN = object()  # not looked up yet (None: looked up, no numba)


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
    """The function ``name`` of the kernel module ``module``, or None without numba (and
    inside :func:`numpy_paths`). Looked up once: later calls read a dict (hot paths call it)."""
    if _OFF:
        return None
    fn = _LOADED.get((module, name), _UNSEEN)
    if fn is _UNSEEN:
        loaded = kernel_module(module)
        fn = _LOADED[module, name] = None if loaded is None else getattr(loaded, name)
    return fn


def check_method(method: str) -> None:
    """Refuse a ``method`` not in :data:`METHODS` (an ArgumentError naming the three).

    >>> check_method("numpy")
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: method must be one of 'auto', 'array', 'numba', got 'numpy' (the plain path is 'array')
    """
    if method not in METHODS:
        # The sensors' plain path was once called "numpy": say what it is called now.
        hint = " (the plain path is 'array')" if method == "numpy" else ""
        raise ArgumentError(f"method must be one of {', '.join(map(repr, METHODS))}, got {method!r}{hint}")


def choose(method: str, module: str, name: str, usable: bool = True, needs: str = "numba") -> Any:
    """The compiled function to run for ``method`` (checked by :func:`check_method`), or None
    for the plain path.

    Parameters
    ----------
    method : {"auto", "array", "numba"}
    module, name : str
        The kernel, as for :func:`kernel` (not loaded for ``"array"``).
    usable : bool
        Whether the caller's data can go to compiled code at all (arrays on the CPU).
    needs : str
        What ``"numba"`` needs, for its error when the kernel cannot run.
    """
    fn = kernel(module, name) if usable and method != "array" else None
    if fn is None and method == "numba":
        raise ArgumentError(f'method="numba" needs {needs}: pip install "pointnav-core[fast]"')
    return fn


@contextmanager
def numpy_paths() -> Iterator[None]:
    """Within the block, :func:`kernel` returns None: every caller takes its plain path
    (``method="numba"`` raises)."""
    _OFF.append(True)
    try:
        yield
    finally:
        _OFF.pop()
