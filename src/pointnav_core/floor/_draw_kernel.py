"""Compiled row spans of :func:`pointnav_core.floor.draw.draw_cell` (numba, the ``fast`` extra).

Imported only through :func:`pointnav_core.utils.compiled.kernel`. The same expressions, in
the same order, as the array path ``draw._row_spans``, one row at a time: ``math.hypot`` is the
C library's ``hypot``, as ``np.hypot`` is, so both settle every row's ends alike (a property
test).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _reaches(col, dy, ox, res, rx, reach):  # pragma: no cover
    return math.hypot((ox + (col + 0.5) * res) - rx, dy) <= reach


@njit(cache=True, nogil=True)
def row_spans(flat, w, oy, ox, res, rx, ry, reach, rows, start, count):  # pragma: no cover
    """For each of ``rows``: where its cells within ``reach`` (m) of ``(rx, ry)`` start in the
    sorted flat indices ``flat``, and how many there are (written to ``start`` and ``count``)."""
    for i in range(rows.shape[0]):
        row = rows[i]
        dy = (oy + (row + 0.5) * res) - ry
        half = math.sqrt(max(reach * reach - dy * dy, 0.0))
        lo = float(math.ceil((rx - half - ox) / res - 0.5))
        hi = float(math.floor((rx + half - ox) / res - 0.5))
        before = _reaches(lo - 1, dy, ox, res, rx, reach)
        first_in = _reaches(lo, dy, ox, res, rx, reach)
        last_in = _reaches(hi, dy, ox, res, rx, reach)
        after = _reaches(hi + 1, dy, ox, res, rx, reach)
        lo = lo - 1 if before else (lo if first_in else lo + 1)
        hi = hi + 1 if after else (hi if last_in else hi - 1)
        a = np.int64(max(lo, 0.0))
        b = np.int64(min(hi, w - 1.0))
        start[i] = np.searchsorted(flat, row * w + a)
        count[i] = np.searchsorted(flat, row * w + b, side="right") - start[i] if a <= b else 0
