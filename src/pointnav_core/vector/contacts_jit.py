"""The compiled path of the batched contacts: every world's slow robots in one numba loop.

The array path (:func:`~pointnav_core.vector.contacts.advance` for one robot per world,
:func:`~pointnav_core.vector.robots.advance_robots` for several) runs every contact round
for every robot of the batch as whole arrays: about a hundred array calls a step, each on
``robots x walls`` or ``robots x walls x tangents`` elements, most of them for robots that
resolve nothing. On the CPU this module does the same arithmetic one world, robot and wall
at a time in a numba kernel (:mod:`~pointnav_core.vector._contact_kernel`), stopping where
each world stops, with the same expressions in the same order, so both paths give the same
positions and contact flags; ``property_tests/test_compiled_paths.py`` checks that they
are equal (``tests/pairs_vector.py``).

numba is optional (the ``fast`` extra): without it (or inside
:func:`~pointnav_core.utils.compiled.numpy_paths`), or for arrays on a GPU, the engines
take the array path. torch tensors on the CPU are read and written through numpy views of
their memory.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pointnav_core.utils.compiled import kernel
from pointnav_core.vector.floors import FloorTables

__all__ = ["KERNEL", "advance_compiled", "advance_one", "available", "prepare"]

#: The kernel module and function, as :func:`pointnav_core.utils.compiled.kernel` takes them.
KERNEL = ("pointnav_core.vector._contact_kernel", "advance_worlds")

# The walls a robot may meet are within this (m) of its chord, beyond its radius
# (4 x the backend's _ACTIVE, as vector.contacts.window is called).
_WALL_MARGIN = 4.0 * 2.0e-9


def available(floors: FloorTables) -> bool:
    """Whether the compiled path can run for these floors' arrays (CPU, numba importable)."""
    a = floors.arrays
    return (not a.is_torch or a.device == "cpu") and kernel(*KERNEL) is not None


def prepare(floors: FloorTables) -> None:
    """Load the kernel now (numba compiles it on a machine's first use, then reads its
    cache): called when an engine is built, so that the first step with a contact costs
    what any other does. Nothing happens where the compiled path cannot run."""
    if available(floors):
        a = floors.arrays
        empty = a.zeros((0, 1))
        advance_compiled(floors, a.zeros((0, 1), a.i64), empty, empty, empty, empty, a.zeros((0, 1), a.boolean), 0.0, 0.0)


def advance_compiled(
    floors: FloorTables, scene: Any, x: Any, y: Any, mx: Any, my: Any, slow: Any, radius: Any, max_travel: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Move the ``slow`` robots by their chords with contacts; the others stay.

    Parameters
    ----------
    floors : FloorTables
    scene : int array (W, R)
        Each robot's scene index.
    x, y, mx, my : float arrays (W, R)
        Start positions and chords over the step (m).
    slow : bool array (W, R)
        The robots to resolve: within a world they move together and block each other;
        the others neither move nor block (the caller moves them: they are out of reach).
    radius : float or float array broadcasting to (W, R)
        Every robot's radius (m), one for all or each robot's own (two robots touch at the
        sum of their radii).
    max_travel : float
        The longest chord any step may have (m): the walls are gathered within it.

    Returns
    -------
    x, y : float64 numpy arrays (W, R)
        End positions (m): the start for robots not ``slow``.
    contact : bool numpy array (W, R)
        Whether each slow robot was blocked by a wall or another robot, or blocked one.
    """
    advance_worlds = kernel(*KERNEL)
    a = floors.arrays
    view = (lambda v: v.numpy()) if a.is_torch else (lambda v: v)
    x, y = np.ascontiguousarray(view(x), np.float64), np.ascontiguousarray(view(y), np.float64)
    radius = view(radius) if a.is_torch and not isinstance(radius, (int, float)) else radius
    # A writable copy always: numba compiles a read-only argument (a broadcast that is
    # already contiguous, as an empty one is) as another specialisation.
    rad = np.array(np.broadcast_to(np.asarray(radius, np.float64), x.shape), order="C")
    # One stencil for the largest robot: each robot keeps the walls within its own reach.
    reach = (float(rad.max()) if rad.size else 0.0) + max_travel + _WALL_MARGIN
    dr, dc, ok = (np.ascontiguousarray(floors.arrays.numpy(v)) for v in floors.stencil(reach))
    x_out, y_out = x.copy(), y.copy()
    contact = np.zeros(x.shape, np.bool_)
    advance_worlds(
        x, y, np.ascontiguousarray(view(mx), np.float64), np.ascontiguousarray(view(my), np.float64),
        np.ascontiguousarray(view(slow), np.bool_), np.ascontiguousarray(view(scene), np.int64), rad,
        floors.host_meta, floors.host_edge, dr, dc, ok, floors.host_segments, floors.segment_offsets,
        x_out, y_out, contact,
    )
    return x_out, y_out, contact


def advance_one(
    floors: FloorTables, scene: Any, x: Any, y: Any, mx: Any, my: Any, radius: Any, max_travel: float
) -> tuple[Any, Any, Any]:
    """:func:`advance_compiled` for one robot per world, with the arguments and results of
    :func:`~pointnav_core.vector.contacts.advance`: ``(M,)`` arrays in the floors' namespace."""
    a = floors.arrays
    rad = radius if isinstance(radius, (int, float)) else radius[:, None]
    out = advance_compiled(floors, scene[:, None], x[:, None], y[:, None], mx[:, None], my[:, None],
                           a.xp.ones_like(x[:, None]) > 0.0, rad, max_travel)
    return tuple(a.asarray(v[:, 0], a.boolean if v.dtype == np.bool_ else None) for v in out)  # type: ignore[return-value]
