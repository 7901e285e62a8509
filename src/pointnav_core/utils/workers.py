"""Worker processes that die with their parent, fed one task at a time.

:class:`WorkerPool` starts ``spawn`` processes, each of which builds its state once
(``init(*initargs)``) and then runs ``task(state, item)`` for every item it is sent, one at
a time, so the parent always knows which item a worker holds. Unlike a
``ProcessPoolExecutor``:

- a worker watches its parent and exits within half a second once the parent is gone,
  even after a SIGKILL that gave the parent no chance to clean up;
- workers ignore SIGINT (a Ctrl-C reaches the whole process group): the parent decides, and
  :meth:`WorkerPool.close` ends them (SIGTERM, then SIGKILL), so an interrupted run stops
  at once instead of playing every queued item;
- a worker that dies or raises is reported as :class:`WorkerError` naming its item.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections import deque
from collections.abc import Callable, Hashable, Iterable, Iterator
from contextlib import contextmanager
from multiprocessing import connection, get_context
from typing import Any

from pointnav_core.errors import PointNavError

__all__ = ["WorkerError", "WorkerPool", "in_worker", "mark_worker", "usable_cores"]

#: How often (s) a worker checks that its parent is alive.
_WATCH_PERIOD = 0.2


class WorkerError(PointNavError, RuntimeError):
    """A worker died, or raised, while it held an item (``key``; None: while starting)."""

    def __init__(self, key: Hashable | None, cause: str) -> None:
        self.key, self.cause = key, cause
        what = "while starting" if key is None else f"on {key!r}"
        super().__init__(f"a worker process failed {what}: {cause}")


def usable_cores() -> int:
    """The CPU cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


_IN_WORKER = False


def in_worker() -> bool:
    """Whether this process is a worker of :class:`WorkerPool` (or another of the library's
    worker processes): it then keeps to one core, its siblings having the others."""
    return _IN_WORKER


def mark_worker() -> None:
    """Record that this process is one of the library's workers (see :func:`in_worker`)."""
    global _IN_WORKER
    _IN_WORKER = True


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(_WATCH_PERIOD)
    os._exit(1)  # the parent is gone: nobody reads what this worker would produce


def _describe(error: BaseException) -> str:
    return f"{type(error).__name__}: {error}"


def _worker_main(conn: Any, parent: int, init: Callable[..., Any], initargs: tuple, task: Callable[[Any, Any], Any]) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):  # blocked since birth (see WorkerPool): now ignored
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True).start()
    mark_worker()
    try:
        state = init(*initargs)
    except Exception as error:
        conn.send(("raised", None, _describe(error)))
        return
    conn.send(("ready", None, None))
    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            return
        if message is None:
            return
        key, item = message
        try:
            conn.send(("done", key, task(state, item)))
        except Exception as error:
            conn.send(("raised", key, _describe(error)))


@contextmanager
def _signals_held() -> Iterator[None]:
    """Hold SIGINT and SIGTERM back from this process's Python handlers for the block, then
    deliver the first that came.

    A handler that raises (Ctrl-C's KeyboardInterrupt) between the spawn of a worker and
    the write of its start-up data would leave the worker reading a closed pipe, and
    printing that traceback on the shared stderr. Only the main thread can set handlers:
    elsewhere the block runs as it is.
    """
    held: list[int] = []
    wanted = [signal.SIGINT, signal.SIGTERM]
    previous = {s: signal.getsignal(s) for s in wanted}
    if threading.current_thread() is not threading.main_thread() or None in previous.values():
        yield
        return
    for signum in wanted:
        signal.signal(signum, lambda signum, _frame: held.append(signum))
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        if held:
            signal.raise_signal(held[0])


class WorkerPool:
    """``workers`` processes running ``task(init(*initargs), item)`` (see the module notes).

    ``init`` and ``task`` must be importable module-level functions, and ``initargs`` and
    the items picklable. Use as a context manager: leaving the block ends every worker.
    """

    def __init__(self, workers: int, init: Callable[..., Any], initargs: tuple, task: Callable[[Any, Any], Any]) -> None:
        self._procs, self._conns = [], []
        try:
            with _signals_held():
                self._start(workers, init, initargs, task)
        except BaseException:  # a signal held while starting is raised here: end what started
            self.close()
            raise

    def _start(self, workers: int, init: Callable[..., Any], initargs: tuple, task: Callable[[Any, Any], Any]) -> None:
        context = get_context("spawn")
        # A worker is born with SIGINT blocked (the mask survives fork and exec), so that a
        # Ctrl-C to the process group while it is still starting does not kill it with a
        # traceback. (In this process the mask does not hold SIGINT back: another thread,
        # e.g. a BLAS one, takes it; _signals_held does.)
        blocking = hasattr(signal, "pthread_sigmask")
        if blocking:  # it would unblock SIGINT if it started in the middle (it blocks its own)
            from multiprocessing import resource_tracker

            resource_tracker.ensure_running()
        mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT}) if blocking else None
        try:
            for _ in range(workers):
                ours, theirs = context.Pipe()
                proc = context.Process(
                    target=_worker_main, args=(theirs, os.getpid(), init, initargs, task), daemon=True
                )
                proc.start()
                theirs.close()
                self._procs.append(proc)
                self._conns.append(ours)
        finally:
            if blocking:
                signal.pthread_sigmask(signal.SIG_SETMASK, mask)

    def __enter__(self) -> WorkerPool:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def imap_unordered(
        self, items: Iterable[tuple[Hashable, Any]], group: Callable[[Any], Hashable] | None = None
    ) -> Iterator[tuple[Hashable, Any]]:
        """Run every ``(key, item)``; yield ``(key, task's return)`` as each finishes.

        Parameters
        ----------
        items : iterable of (key, item)
            Sent in this order, one to each worker as it becomes free (without ``group``).
        group : callable, optional
            ``group(item)`` names the state an item needs (an evaluation's scene): a free
            worker takes the next item of the group it last ran, else the first group no
            other worker is on, else the largest group left (see :class:`_GroupedQueue`),
            so that each worker builds a group's state once rather than every worker
            building every group's.

        Raises
        ------
        WorkerError
            When a worker raises or ends before returning, naming the item it held.
        """
        todo: Any = iter(items) if group is None else _GroupedQueue(items, group)
        held: dict[int, Hashable | None] = dict.fromkeys(range(len(self._procs)))  # None: starting
        while held:
            connection.wait([self._conns[k] for k in held] + [self._procs[k].sentinel for k in held])
            for k in list(held):
                conn, proc = self._conns[k], self._procs[k]
                try:
                    if not conn.poll():
                        if not proc.is_alive():
                            raise WorkerError(held[k], f"the process ended (exit code {proc.exitcode})")
                        continue
                    kind, key, out = conn.recv()
                    if kind == "raised":
                        raise WorkerError(key, out)
                    if kind == "done":
                        yield key, out
                    nxt = next(todo, None) if group is None else todo.take(k)
                    if nxt is None:
                        del held[k]
                        continue
                    held[k] = nxt[0]
                    conn.send(nxt)
                except (EOFError, OSError):
                    proc.join(1.0)
                    raise WorkerError(held[k], f"the process ended (exit code {proc.exitcode})") from None

    def close(self) -> None:
        """End every worker: a polite stop, SIGTERM, then SIGKILL for one that lingers."""
        for conn in self._conns:
            try:
                conn.send(None)
            except (OSError, ValueError):
                pass
        deadline = time.monotonic() + 0.5
        for proc in self._procs:
            proc.join(max(0.0, deadline - time.monotonic()))
            if proc.is_alive():
                proc.terminate()
        for proc in self._procs:
            proc.join(2.0)
            if proc.is_alive():
                proc.kill()
                proc.join()
        for conn in self._conns:
            conn.close()
        self._procs, self._conns = [], []


class _GroupedQueue:
    """Items waiting for workers, kept by group (see :meth:`WorkerPool.imap_unordered`)."""

    def __init__(self, items: Iterable[tuple[Hashable, Any]], group: Callable[[Any], Hashable]) -> None:
        self._groups: dict[Hashable, deque[tuple[Hashable, Any]]] = {}  # first-seen order
        for entry in items:
            self._groups.setdefault(group(entry[1]), deque()).append(entry)
        self._on: dict[int, Hashable] = {}  # worker -> the group it last took from

    def take(self, worker: int) -> tuple[Hashable, Any] | None:
        """The next ``(key, item)`` for ``worker``; None when none are left."""
        if not self._groups:
            return None
        mine = self._on.get(worker)
        if mine not in self._groups:
            others = {g for w, g in self._on.items() if w != worker}
            free = [g for g in self._groups if g not in others]
            # Every group left has a worker on it: help with the largest, so that the last
            # items are shared rather than queued behind one worker.
            mine = free[0] if free else max(self._groups, key=lambda g: len(self._groups[g]))
            self._on[worker] = mine
        queue = self._groups[mine]
        entry = queue.popleft()
        if not queue:
            del self._groups[mine]
        return entry
