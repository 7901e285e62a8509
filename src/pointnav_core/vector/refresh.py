"""Fresh episodes while the worlds run: a pool built in a worker process and swapped in.

An env's episode pool (:class:`~pointnav_core.vector.episodes.EpisodePool` or
:class:`~pointnav_core.vector.fleet_pool.FleetPool`) is prepared ahead, so that no reset
samples or plans during a step. :class:`PoolRefresh` builds the next pool (the same number
of episodes per scene, from new seeds) in a worker process, so that the build (sampling and
settling goal fields, Python-bound) does not hold the stepping process back; the env swaps
it in at the start of a step once it is ready, with :func:`join_pools`: the new episodes
come first, so autoresets draw from them only, and the old ones after, so that the worlds
still in an old episode keep its goal field (their field index shifted by the new pool's
length). When no world is left in an old episode, the env keeps the new pool alone.
"""

from __future__ import annotations

import copy
import functools
import multiprocessing
from collections.abc import Sequence
from concurrent.futures import Executor, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from pointnav_core.vector.fields import FieldTables
from pointnav_core.vector.xp import Arrays, make_arrays

__all__ = ["PoolRefresh", "PoolRefreshing", "build_pool", "join_pools", "pool_to", "refresh_executor"]

# The per-episode arrays of both pool kinds (FleetPool's have a robot axis).
_EPISODE_ARRAYS = ("sx", "sy", "syaw", "gx", "gy", "d0", "scene")


def refresh_executor() -> Executor:
    """One worker process, started fresh (``spawn``: safe beside torch and CUDA)."""
    return ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("spawn"))


def build_pool(kind: type, samplers: Sequence[Any], pool_size: int, seeds: Sequence[int]) -> Any:
    """A pool of ``kind`` on numpy (in the worker: numpy arrays pickle back cheaply)."""
    return kind(samplers, pool_size, seeds, make_arrays("numpy"))


class PoolRefresh:
    """A pool of ``kind`` being built by ``executor`` from ``samplers`` and ``seeds``.

    Parameters
    ----------
    executor : Executor
        Runs :func:`build_pool` (a process pool from :func:`refresh_executor`).
    kind : type
        The pool class, called as ``kind(samplers, pool_size, seeds, arrays)``.
    samplers, pool_size, seeds
        Its arguments (the samplers are pickled into the worker).
    arrays : Arrays
        The env's device, where :meth:`result` puts the pool.
    """

    def __init__(self, executor: Executor, kind: type, samplers: Sequence[Any], pool_size: int,
                 seeds: Sequence[int], arrays: Arrays) -> None:
        self._future = executor.submit(build_pool, kind, list(samplers), pool_size, list(map(int, seeds)))
        self._arrays = arrays

    def done(self) -> bool:
        """Whether the build has finished (successfully or not)."""
        return self._future.done()

    def result(self) -> Any:
        """The new pool on the env's device, waiting for the build if needed; re-raises
        the build's error."""
        try:
            pool = self._future.result()
        except BrokenProcessPool as error:
            raise RuntimeError(
                "the pool refresh's worker process died; a script that starts one must guard its "
                "entry point with `if __name__ == '__main__':` (the worker is spawned and imports "
                "it), as for any spawned process, or call refresh_pool(wait=True)"
            ) from error
        return pool_to(pool, self._arrays)


def pool_to(pool: Any, arrays: Arrays) -> Any:
    """``pool`` with its arrays on ``arrays``' device (``pool`` itself if already there)."""
    if pool.fields.arrays.device == arrays.device:
        return pool
    moved = copy.copy(pool)
    for name in _EPISODE_ARRAYS:
        if hasattr(pool, name):
            setattr(moved, name, _to(getattr(pool, name), arrays))
    if hasattr(pool, "field"):  # each episode's goal field (an index, not an episode array to join)
        moved.field = _to(pool.field, arrays)
    moved.fields = pool.fields.to(arrays)
    return moved


def _to(values: Any, arrays: Arrays) -> Any:
    return arrays.asarray(values, arrays.i64 if values.dtype.kind in "iu" else arrays.f64)


def join_pools(new: Any, old: Any) -> Any:
    """``new``'s episodes followed by ``old``'s, as one pool of ``new``'s kind and size.

    Entry ``i`` of ``old`` (and its goal fields) becomes entry ``len(new) + i`` (field
    ``len(new.fields) + f``); ``new``'s draws (``pool_size``, scene order) are unchanged.
    """
    xp = new.fields.arrays.xp
    joined = copy.copy(new)
    for name in _EPISODE_ARRAYS:
        if hasattr(new, name):
            setattr(joined, name, xp.concatenate([getattr(new, name), getattr(old, name)]))
    joined.fields = FieldTables.concat(new.fields, old.fields)
    if hasattr(new, "field"):  # each episode's goal field, old ones after new's fields
        joined.field = xp.concatenate([new.field, old.field + len(new.fields)])
    return joined


class PoolRefreshing:
    """The batched envs' ``refresh_pool``: needs ``pool``, ``pool_size``, ``scenes``,
    ``_samplers``, ``_rng``, ``_fixed``, ``_field`` and ``arrays``; the env calls
    :meth:`_poll_pool` at a step's start (while :attr:`refresh_active`) and
    :meth:`_finish_refresh` at a reset."""

    # The pending build and its worker, the new pool while older episodes are still run,
    # and the field index from which they start.
    _refresh: PoolRefresh | None = None
    _executor: Executor | None = None
    _fresh: Any = None
    _old_from: int | None = None

    def refresh_pool(self, wait: bool = False) -> None:
        """Prepare fresh episodes (``pool_size`` per scene, new seeds) for the autoresets.

        The new pool is built in a worker process (started at the first refresh, kept
        until ``close()``) and swapped in at the start of the first step after it is ready;
        from then on autoresets draw from it alone, while the worlds still in an old episode
        finish it (their goal fields are kept until none is left). With ``wait=True`` it is
        built here and swapped in before returning: between batches, and reproducibly (the
        seeds come from the env's generator either way, and give the same pool, but in the
        background the step of the swap depends on the machine).

        Raises
        ------
        RuntimeError
            Before the first ``reset()``.
        ValueError
            While the worlds run fixed episodes (``reset(options={"episodes": ...})``).
        """
        if self.pool is None:
            raise RuntimeError("call reset() before refresh_pool()")
        if self._fixed is not None:
            raise ValueError("refresh_pool: the worlds run fixed episodes (reset(options={'episodes': ...})); reset without them first")
        self._finish_refresh()
        seeds = self._rng.integers(2**31, size=self.pool_size * len(self.scenes))
        if wait:
            self._swap_pool(self._pool_kind()(self._samplers, self.pool_size, seeds, self.arrays))
            return
        if self._executor is None:
            self._executor = refresh_executor()
        self._refresh = PoolRefresh(self._executor, self._pool_kind(), self._samplers, self.pool_size, seeds, self.arrays)

    def _pool_kind(self) -> Any:
        # The pool class with this env's starts per goal (a partial pickles for the worker);
        # the multi-robot engine, which inherits refresh_pool, has one start per goal.
        starts = getattr(self, "starts_per_goal", 1)
        return functools.partial(type(self.pool), starts=starts, reach=self._reach)

    @property
    def refresh_pending(self) -> bool:
        """Whether a background refresh has not been swapped in yet."""
        return self._refresh is not None

    def _finish_refresh(self) -> None:
        """Swap in a pending refresh, waiting for its build."""
        if self._refresh is not None:
            self._swap_pool(self._refresh.result())

    def _swap_pool(self, new: Any) -> None:
        self._refresh = None
        # After the current pool (which may still hold an older one's episodes, too).
        self._old_from = len(new.fields)
        self.pool = join_pools(new, self.pool)
        self._fresh = new
        self._field = self._field + self._old_from

    def _poll_pool(self) -> None:
        """At a step's start: swap in a finished refresh; drop old episodes no world is in."""
        if self._refresh is not None and self._refresh.done():
            self._swap_pool(self._refresh.result())
        if self._old_from is not None and not bool((self._field >= self._old_from).any()):
            self.pool, self._fresh, self._old_from = self._fresh, None, None

    def close_extras(self, **kwargs: Any) -> None:
        """Stop the refresh worker process, if one was started (a pending build is dropped)."""
        self._refresh = None
        if self._executor is not None:
            self._executor.shutdown(wait=True, cancel_futures=True)
            self._executor = None

    @property
    def refresh_active(self) -> bool:
        """Whether a refresh is pending or older episodes are still run (steps poll then)."""
        return self._refresh is not None or self._old_from is not None
