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

The worker (:mod:`~pointnav_core.vector.refresh_worker`) may fail: its build raises, or it
is killed while building or idle. The env then warns once (:class:`PoolRefreshWarning`,
with the cause), keeps its pool, and starts a new worker at the next refresh if the old one
died. Copies and pickles of the env leave the worker, and a pending refresh, behind.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import warnings
from collections.abc import Sequence
from typing import Any

from pointnav_core.errors import ArgumentError, TaskStateError
from pointnav_core.vector.fields import FieldTables
from pointnav_core.vector.refresh_worker import RefreshWorker
from pointnav_core.vector.xp import Arrays, make_arrays

__all__ = ["PoolRefresh", "PoolRefreshWarning", "PoolRefreshing", "build_pool", "join_pools", "pool_to"]

# The per-episode arrays of both pool kinds (FleetPool's have a robot axis).
_EPISODE_ARRAYS = ("sx", "sy", "syaw", "gx", "gy", "d0", "scene")


class PoolRefreshWarning(RuntimeWarning):
    """A background pool refresh failed (its build raised, or its worker died): the worlds
    go on with the episodes they have, and the next ``refresh_pool`` tries again."""


class RefreshFailed(Exception):
    """Why a background build gave no pool (internal: the env turns it into a warning)."""


def build_pool(kind: type, samplers: Sequence[Any], pool_size: int, seeds: Sequence[int]) -> Any:
    """A pool of ``kind`` on numpy (in the worker: numpy arrays pickle back cheaply)."""
    return kind(samplers, pool_size, seeds, make_arrays("numpy"))


class PoolRefresh:
    """A pool of ``kind`` being built by ``worker`` from ``samplers`` and ``seeds``.

    Parameters
    ----------
    worker : RefreshWorker
        Runs :func:`build_pool`.
    kind : type
        The pool class, called as ``kind(samplers, pool_size, seeds, arrays)``.
    samplers, pool_size, seeds
        Its arguments (the samplers are pickled into the worker).
    arrays : Arrays
        The env's device, where :meth:`result` puts the pool.
    """

    def __init__(self, worker: RefreshWorker, kind: type, samplers: Sequence[Any], pool_size: int,
                 seeds: Sequence[int], arrays: Arrays) -> None:
        worker.submit(build_pool, kind, list(samplers), pool_size, list(map(int, seeds)))
        self.worker = worker
        self._arrays = arrays
        self._outcome: tuple[str, Any] | None = None

    def done(self) -> bool:
        """Whether the build has finished (successfully or not), or its worker died."""
        if self._outcome is None:
            self._outcome = self.worker.answer(0.0)
        return self._outcome is not None

    def wait(self, timeout: float | None = None) -> bool:
        """Wait until :meth:`done`, at most ``timeout`` s (None: no limit); whether it is."""
        if self._outcome is None:
            self._outcome = self.worker.answer(timeout)
        return self._outcome is not None

    def result(self) -> Any:
        """The new pool on the env's device, waiting for the build if needed.

        Raises
        ------
        RefreshFailed
            With the cause, if the build raised or the worker died.
        """
        self.wait()
        kind, value = self._outcome
        if kind == "done":
            return pool_to(value, self._arrays)
        if kind == "failed":
            raise RefreshFailed(f"the pool refresh's build failed in its worker process: {value}")
        raise RefreshFailed(value)


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
    _worker: RefreshWorker | None = None
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

        A background refresh that fails (its build raises, or its worker process dies,
        while building or idle) is reported once, by a :class:`PoolRefreshWarning` naming
        the cause, at the step, reset or refresh that finds it; the worlds go on with the
        episodes they have, and the next refresh starts a new worker if the old one died.

        Raises
        ------
        RuntimeError
            Before the first ``reset()``.
        ValueError
            While the worlds run fixed episodes (``reset(options={"episodes": ...})``).
        """
        if self.pool is None:
            raise TaskStateError("call reset() before refresh_pool()")
        if self._fixed is not None:
            raise ArgumentError("refresh_pool: the worlds run fixed episodes (reset(options={'episodes': ...})); reset without them first")
        self._finish_refresh()
        seeds = self._rng.integers(2**31, size=self.pool_size * len(self.scenes))
        if wait:
            self._swap_pool(self._pool_kind()(self._samplers, self.pool_size, seeds, self.arrays))
            return
        if self._worker is not None and not self._worker.alive():  # died while idle
            self._report(self._worker.death("while idle") + "; a new one is started")
        if self._worker is None:
            self._worker = RefreshWorker()
        self._refresh = PoolRefresh(self._worker, self._pool_kind(), self._samplers, self.pool_size, seeds, self.arrays)

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
            self._take_refresh()

    def _take_refresh(self) -> None:
        """Swap in the pending refresh's pool, or report why there is none and go on."""
        refresh, self._refresh = self._refresh, None
        try:
            new = refresh.result()
        except RefreshFailed as failure:
            if not refresh.worker.alive():
                self._report(f"{failure}; the next refresh_pool() starts a new worker")
            else:
                warnings.warn(f"{failure}; the worlds go on with their current episodes", PoolRefreshWarning, stacklevel=4)
            return
        self._swap_pool(new)

    def _report(self, cause: str) -> None:
        """Warn of a dead worker, once, and let it go (the next refresh starts another)."""
        self._stop_worker()
        warnings.warn(f"{cause}; the worlds go on with their current episodes", PoolRefreshWarning, stacklevel=4)

    def _swap_pool(self, new: Any) -> None:
        self._refresh = None
        # After the current pool (which may still hold an older one's episodes, too).
        self._old_from = len(new.fields)
        self.pool = join_pools(new, self.pool)
        self._fresh = new
        self.state = dataclasses.replace(self.state, goal_field=self.state.goal_field + self._old_from)

    def _poll_pool(self) -> None:
        """At a step's start: swap in a finished refresh; drop old episodes no world is in."""
        if self._refresh is not None and self._refresh.done():
            self._take_refresh()
        if self._old_from is not None and not bool((self.state.goal_field >= self._old_from).any()):
            self.pool, self._fresh, self._old_from = self._fresh, None, None

    def _stop_worker(self) -> None:
        worker, self._worker, self._refresh = self._worker, None, None
        if worker is not None:
            worker.close()

    def close_extras(self, **kwargs: Any) -> None:
        """Stop the refresh worker process, if one was started (a pending build is dropped)."""
        self._stop_worker()

    def __getstate__(self) -> dict[str, Any]:
        """The env's state for a copy or a pickle, without the refresh worker: the copy
        starts its own at its first refresh, and a refresh pending here is the original's
        alone (the copy goes on with the episodes it has)."""
        state = self.__dict__.copy()
        state.pop("_worker", None)
        state.pop("_refresh", None)
        return state

    @property
    def refresh_active(self) -> bool:
        """Whether a refresh is pending or older episodes are still run (steps poll then)."""
        return self._refresh is not None or self._old_from is not None
