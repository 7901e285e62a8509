"""Counter-based noise draws: a pure function of integer keys, the same in every engine.

The range scan's noise and dropout (:class:`~pointnav_core.sensors.RangeScan`,
:class:`~pointnav_core.vector.scan.VectorScan`) do not draw from a generator's stream: each
value is a hash of where it is used,

``u = uniform(mix(mix(mix(mix(episode, robot), step), ray), channel))``

with ``episode = episode_key(base, n)``: ``base`` the entropy of the env's seed sequence
(the seed given to ``reset``, modulo 2**64) and ``n`` the number of episodes begun since
that seeding (0 for the seeded reset); ``robot`` the robot's index in the env; ``step`` the
step within the episode (0 for the reset observation); ``ray`` the ray's index; ``channel``
:data:`NOISE` or :data:`DROPOUT`. So a single env reset with seed ``s + w`` and world ``w``
of a batched engine seeded with ``s`` read the same numbers, in any order and on any
batch shape, and no generator is drawn from (turning noise on changes no episode).

``mix(h, v) = f(f(h + G) ^ v)``, all modulo 2**64, with ``f`` the splitmix64 finaliser
(Steele, Lea and Flood 2014; ``z ^= z >> 30; z *= 0xBF58476D1CE4E5B9; z ^= z >> 27;
z *= 0x94D049BB133111EB; z ^= z >> 31``) and ``G = 0x9E3779B97F4A7C15``. The top 53 bits
``k`` of the last hash give ``u = (k + 0.5) / 2**53``, strictly inside ``(0, 1)``;
normals are ``ndtri(u)`` (the inverse of the normal CDF, :func:`scipy.special.ndtri`).

Examples
--------
>>> u = uniforms(episode_key(7, 0), np.arange(2)[:, None, None], 0, np.arange(3), NOISE)
>>> u.shape, bool(((u > 0.0) & (u < 1.0)).all())
((2, 1, 3), True)
>>> bool((uniforms(episode_key(7, 0), 1, 0, np.arange(3), NOISE) == u[1, 0]).all())
True
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.special import ndtri

from pointnav_core.utils.compiled import check_method, choose

__all__ = ["DROPOUT", "NOISE", "episode_key", "mix", "normals", "scan_noise", "seed_entropy", "uniforms"]

#: The channel of the Gaussian noise.
NOISE = 0
#: The channel of the dropout.
DROPOUT = 1

_MASK = (1 << 64) - 1
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_S30, _S27, _S31, _S11 = np.uint64(30), np.uint64(27), np.uint64(31), np.uint64(11)


def _u64(v: Any) -> NDArray[np.uint64]:
    """``v`` as a uint64 array (Python ints taken modulo 2**64; negative ints wrap)."""
    if isinstance(v, int):
        return np.asarray(v & _MASK, dtype=np.uint64)
    arr = np.asarray(v)
    if arr.dtype == np.uint64:
        return arr
    return arr.astype(np.int64).astype(np.uint64)


def _finalise(z: NDArray[np.uint64]) -> NDArray[np.uint64]:
    """The splitmix64 finaliser (a bijection of 64-bit words), elementwise."""
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


def mix(h: Any, v: Any) -> NDArray[np.uint64]:
    """``f(f(h + G) ^ v)`` modulo 2**64, elementwise and broadcast: the key ``h`` extended by ``v``.

    Parameters
    ----------
    h, v : int or integer array
        Keys; Python ints are taken modulo 2**64, signed arrays as their two's complement.

    Returns
    -------
    uint64 array
        The broadcast shape of ``h`` and ``v``.
    """
    with np.errstate(over="ignore"):
        return _finalise(_finalise(_u64(h) + _GOLDEN) ^ _u64(v))


def seed_entropy(rng: np.random.Generator) -> tuple[Any, int]:
    """The seed sequence of ``rng`` and its entropy modulo 2**64, the base of the episode keys.

    ``reset(seed=s)`` of a gymnasium env gives entropy ``s``; an unseeded sequence has a
    random 128-bit entropy; an entropy given as a sequence of ints is folded with
    :func:`mix`. A generator without a seed sequence is keyed by itself and draws one
    base from its own stream (once per generator).

    Returns
    -------
    (object, int)
        The object whose identity marks one seeding, and the base.
    """
    seq = getattr(rng.bit_generator, "seed_seq", None)
    if isinstance(seq, np.random.SeedSequence):
        entropy = seq.entropy
        if isinstance(entropy, (int, np.integer)):
            return seq, int(entropy) & _MASK
        h = 0
        for value in np.atleast_1d(np.asarray(entropy, dtype=object)).tolist():
            h = int(mix(h, int(value) & _MASK))
        return seq, h
    return rng, int(rng.integers(2**63))


def episode_key(base: Any, n: Any) -> NDArray[np.uint64]:
    """The key of the ``n``-th episode (0: the seeded reset's) since seeding with entropy ``base``."""
    return mix(base, n)


def _words(episode: Any, robot: Any, step: Any, ray: Any, channel: int) -> NDArray[np.uint64]:
    return mix(mix(mix(mix(episode, robot), step), ray), channel)


def uniforms(episode: Any, robot: Any, step: Any, ray: Any, channel: int) -> NDArray[np.float64]:
    """Uniform floats in ``(0, 1)`` (53 bits), one per broadcast element of the keys.

    Parameters
    ----------
    episode : uint64 array or int
        :func:`episode_key` of each element's episode.
    robot, step, ray : int or integer array
        The robot's index in its env, the step within the episode (0 at reset), the ray's index.
    channel : int
        :data:`NOISE` or :data:`DROPOUT`.

    Returns
    -------
    float64 array
        ``(k + 0.5) / 2**53`` with ``k`` the top 53 bits of the hash.
    """
    k = _words(episode, robot, step, ray, channel) >> _S11
    return (k.astype(np.float64) + 0.5) * (1.0 / 9007199254740992.0)


def normals(episode: Any, robot: Any, step: Any, ray: Any, channel: int = NOISE) -> NDArray[np.float64]:
    """Standard normal draws ``ndtri(u)`` of :func:`uniforms` (same keys, same shape)."""
    return np.asarray(ndtri(uniforms(episode, robot, step, ray, channel)), dtype=np.float64)


def scan_noise(
    episode: Any, robot: Any, step: Any, n_rays: int, noise_std: float, dropout: float, method: str = "auto"
) -> tuple[NDArray[np.float64] | None, NDArray[np.bool_] | None]:
    """The noise (m) and the lost readings of ``n_rays`` rays (keys broadcast over a last ray axis).

    Parameters
    ----------
    episode, robot, step : int or integer array
        Keys as for :func:`uniforms`, with a trailing axis of length 1 for the rays.
    n_rays : int
        Rays of the scan.
    noise_std : float
        Standard deviation (m); 0 gives None.
    dropout : float
        Probability of a lost reading; 0 gives None.
    method : {"auto", "array", "numba"}
        The hashing of the rays' words: numpy's whole-array passes, or one compiled loop
        (the ``fast`` extra; ``"auto"`` takes it when numba is installed). The same bits.

    Returns
    -------
    (float64 array or None, bool array or None)
        ``noise_std * ndtri(u)`` on channel :data:`NOISE`, and ``u < dropout`` on
        channel :data:`DROPOUT`, each of the keys' shape with ``n_rays`` last.
    """
    check_method(method)
    channels = [c for c, on in ((NOISE, noise_std > 0.0), (DROPOUT, dropout > 0.0)) if on]
    if not channels:
        return None, None
    with np.errstate(over="ignore"):
        h = mix(mix(episode, robot), step)  # the keys' part common to the rays
    u = _ray_uniforms(h, n_rays, channels, method)
    noise = noise_std * ndtri(u[0]) if noise_std > 0.0 else None
    lost = u[-1] < dropout if dropout > 0.0 else None
    return noise, lost


def _ray_uniforms(h: NDArray[np.uint64], n_rays: int, channels: list[int], method: str) -> NDArray[np.float64]:
    """:func:`uniforms` of keys ``mix(h, ray)`` for every ray and channel: shape
    ``(len(channels),) + h.shape[:-1] + (n_rays,)`` (``h`` has a trailing axis of 1)."""
    kernel = choose(method, "pointnav_core.sensors._noise_kernel", "ray_uniforms")
    if kernel is not None:
        flat = np.ascontiguousarray(h, dtype=np.uint64).reshape(-1)
        out = np.empty((len(channels), flat.shape[0], n_rays))
        kernel(flat, n_rays, np.asarray(channels, dtype=np.uint64), out)
        return out.reshape((len(channels),) + h.shape[:-1] + (n_rays,))
    ray = np.arange(n_rays, dtype=np.uint64)
    with np.errstate(over="ignore"):
        # mix(key, channel) = f(f(key + G) ^ channel): the inner word is the channels' common part.
        inner = _finalise(mix(h, ray) + _GOLDEN)
        words = [_finalise(inner ^ np.uint64(c)) >> _S11 for c in channels]
    return (np.stack(words).astype(np.float64) + 0.5) * (1.0 / 9007199254740992.0)

