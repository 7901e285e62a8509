"""The compiled path of :func:`pointnav_core.sensors.noise.scan_noise` (imports numba).

Imported only when the compiled path runs, so the package imports without numba. The same
64-bit integer arithmetic as :mod:`~pointnav_core.sensors.noise`'s numpy path (uint64
throughout, so every product wraps modulo 2**64), one loop over the keys and rays instead
of a dozen whole-array passes: the uniforms are the same bits.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["ray_uniforms"]

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_S30, _S27, _S31, _S11 = np.uint64(30), np.uint64(27), np.uint64(31), np.uint64(11)
_UNIT = 1.0 / 9007199254740992.0  # 2**-53


@numba.njit(cache=True, nogil=True, inline="always")
def _finalise(z):  # pragma: no cover
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


@numba.njit(cache=True, nogil=True)
def ray_uniforms(h, n_rays, channels, out):  # pragma: no cover
    # h: (K,) uint64, each key's mix(mix(episode, robot), step); out: (len(channels), K, n_rays).
    # u = (top 53 bits of f(f(h + G) ^ ray) + G -> f -> ^ channel -> f) + 0.5) * 2**-53.
    for k in range(h.shape[0]):
        base = _finalise(h[k] + _GOLDEN)
        for r in range(n_rays):
            inner = _finalise(_finalise(base ^ np.uint64(r)) + _GOLDEN)
            for c in range(channels.shape[0]):
                word = _finalise(inner ^ channels[c]) >> _S11
                out[c, k, r] = (float(word) + 0.5) * _UNIT
