"""The compiled fast path of :func:`~pointnav_core.sensors.raycast.cast_rays` (numba).

The numpy path of :mod:`~pointnav_core.sensors.raycast` tests every grid crossing up to
``max_range`` of every ray, and every candidate polygon edge against every ray, as whole
arrays: about forty numpy calls a scan whatever the scene. This module does the same
arithmetic one ray at a time in a numba kernel, stopping where the ray stops:

- the two crossing families are walked in order of ``t`` and the walk ends at the first
  blocked crossing (the y-family's walk also ends past the x-family's hit);
- polygon edges are culled once per origin (bounding box within ``max_range``, back
  faces, nearest point beyond every ray's range so far), then tested against the rays
  within their angular span only (directions compared by a monotone stand-in for
  ``atan2``, with a margin far above rounding);
- other robots' discs are tested per ray.

Every quantity is the same expression as in the numpy path, evaluated in the same order on
the same cosines and sines (computed by numpy in :func:`~pointnav_core.sensors.raycast.cast_rays`,
and turned into ray directions by the same products), so both paths give the same ranges;
``property_tests/test_compiled_paths.py`` checks that they are equal (``tests/pairs_scan.py``).

numba is optional (the ``fast`` extra). The kernel
(:mod:`~pointnav_core.sensors._raycast_kernel`) is loaded by
:func:`pointnav_core.utils.compiled.kernel` on the first scan; without numba (or inside
``numpy_paths()``) :func:`available` is false and ``cast_rays`` takes the array path. The
kernel is compiled once and cached on disk (``cache=True``), so later processes load it.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.utils.compiled import kernel

__all__ = ["KERNEL", "available", "cast_rays_compiled"]

#: The kernel module and function, as :func:`pointnav_core.utils.compiled.kernel` takes them.
KERNEL = ("pointnav_core.sensors._raycast_kernel", "cast")


def available() -> bool:
    """Whether the compiled path can run (numba importable, outside ``numpy_paths()``)."""
    return kernel(*KERNEL) is not None


def cast_rays_compiled(
    geometry: Any,
    p: NDArray[np.float64],
    cy: NDArray[np.float64],
    sy: NDArray[np.float64],
    ca: NDArray[np.float64],
    sa: NDArray[np.float64],
    max_range: float,
    discs: NDArray[np.float64],
    own: NDArray[np.int64],
) -> tuple[NDArray[np.float64], int]:
    """Ranges (m), ``(N, R)``, from origins ``p`` with headings of cosine ``cy`` and sine
    ``sy`` ``(N,)``, along rays at bearings of cosine ``ca`` and sine ``sa`` ``(R,)``.

    The arguments are :func:`~pointnav_core.sensors.raycast.cast_rays`'s, already converted:
    ``discs`` ``(M, 3)`` (possibly empty) and ``own`` ``(N,)`` (-1: no own disc). Origins
    inside an obstacle polygon are not zeroed here: the second value counts the origins in
    a cell a polygon touches, and the caller asks shapely about those.
    """
    out = np.empty((len(cy), len(ca)), dtype=np.float64)
    near = kernel(*KERNEL)(
        p, cy, sy, ca, sa, geometry.jit_params(max_range), geometry.lookup, geometry.clearance,
        geometry.near_polygon, geometry.edge_table, discs, own, out,
    )
    return out, near
