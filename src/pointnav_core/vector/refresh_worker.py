"""One spawned worker process that runs ``refresh_pool``'s builds, one at a time.

A plain process and a pipe rather than a ``ProcessPoolExecutor``: the env must tell a
build that raised (the worker lives on) from a worker that died (killed mid-build or while
idle, or never started because the script has no ``__main__`` guard), say which, and start
a new worker after a death; an executor only reports ``BrokenProcessPool`` and stays broken.
The worker stops when its pipe closes (at :meth:`RefreshWorker.close`), at once when the
env's process ends, however it ends (even mid-build), and ignores Ctrl-C (the env's
process decides); it is also a daemon, ended at the interpreter's exit.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import threading
import traceback
from collections.abc import Callable
from multiprocessing.connection import Connection, wait
from multiprocessing.reduction import ForkingPickler
from typing import Any

from pointnav_core.errors import TaskStateError
from pointnav_core.utils import workers

__all__ = ["RefreshWorker"]

# Seconds a closing worker gets to leave on its own before it is terminated.
_CLOSE_GRACE = 5.0


def _describe(error: BaseException) -> str:
    """``Type: message (file:line, in function)`` of ``error``'s innermost frame."""
    summary = "".join(traceback.format_exception_only(type(error), error)).strip()
    frames = traceback.extract_tb(error.__traceback__)
    if frames:
        last = frames[-1]
        summary += f" (at {last.filename}:{last.lineno}, in {last.name})"
    return summary


def _leave_with_parent() -> None:
    """Exit as soon as the env's process ends, even in the middle of a build (a thread)."""
    parent = multiprocessing.parent_process()
    if parent is not None:
        wait([parent.sentinel])
        os._exit(0)


def _serve(conn: Connection) -> None:
    """The worker's loop: say it started, then answer each job until the pipe closes.

    A job is ``(function, args)``; the answer ``("done", result)``, or ``("failed", cause)``
    when the job could not be read, raised, or its result could not be sent.
    """
    # Ctrl-C reaches the whole process group: the env's process decides, and the worker
    # leaves when the env closes its pipe or exits (a traceback from here would only confuse).
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_leave_with_parent, name="pointnav-pool-refresh-parent", daemon=True).start()
    workers.mark_worker()  # one core: the env's process steps on the others
    try:
        conn.send(("ready", None))
        while True:
            try:
                func, args = conn.recv()
                reply: tuple[str, Any] = ("done", func(*args))
            except EOFError:  # the env closed the pipe, or its process died
                return
            except Exception as error:  # noqa: BLE001 (any build error is reported to the env, which keeps its pool)
                reply = ("failed", _describe(error))
            try:
                conn.send(reply)
            except (TypeError, ValueError, AttributeError) as error:  # the result does not pickle
                conn.send(("failed", _describe(error)))
    except OSError:  # the env's end is gone: nobody is left to answer
        return


class RefreshWorker:
    """A spawned process (``spawn``: safe beside torch and CUDA) that runs one job at a time.

    Attributes
    ----------
    pid : int
        The worker's process id.
    """

    def __init__(self) -> None:
        ctx = multiprocessing.get_context("spawn")
        self._conn, child = ctx.Pipe()
        self._process = ctx.Process(target=_serve, args=(child,), name="pointnav-pool-refresh", daemon=True)
        self._process.start()
        child.close()  # only the worker holds its end: its death closes the pipe
        self.pid = self._process.pid
        self._started = False  # its first message came
        self._busy = False
        self._eof = False  # its end of the pipe closed: it died
        self._sender: threading.Thread | None = None

    def submit(self, func: Callable[..., Any], *args: Any) -> None:
        """Start ``func(*args)`` in the worker (one job at a time), without waiting for it.

        The job is pickled here (an error in doing so is raised here) and sent by a thread:
        a worker still starting reads nothing for a second or two, and the samplers are a
        few MB, more than the pipe holds.
        """
        if self._busy:
            raise TaskStateError("the refresh worker is still busy with a job")
        payload = bytes(ForkingPickler.dumps((func, args)))
        self._sender = threading.Thread(target=self._send, args=(payload,), name="pointnav-pool-refresh-send", daemon=True)
        self._busy = True
        self._sender.start()

    def _send(self, payload: bytes) -> None:
        try:
            self._conn.send_bytes(payload)
        except OSError:  # the worker died (or was closed): answer() reports it
            pass

    def alive(self) -> bool:
        """Whether the worker process is running."""
        return self._process.is_alive()

    def answer(self, timeout: float | None = 0.0) -> tuple[str, Any] | None:
        """The pending job's outcome, waiting up to ``timeout`` s (None: until there is one).

        Returns ``("done", result)``, ``("failed", cause)`` (the job raised), ``("died",
        cause)`` (the worker process ended; it runs no more jobs), or None while it runs.
        """
        while True:
            if not self._eof and self._conn.poll():
                try:
                    kind, value = self._conn.recv()
                except (EOFError, OSError):  # its end closed: the worker died
                    self._eof = True
                    continue
                except Exception as error:  # noqa: BLE001 (the result does not unpickle here: reported as a failed build)
                    kind, value = "failed", _describe(error)
                if kind == "ready":
                    self._started = True
                    continue
                self._busy = False
                return kind, value
            if self._eof or not self._process.is_alive():
                self._process.join()
                if not self._eof and self._conn.poll():  # answered just before it ended
                    continue
                self._busy = False
                return "died", self.death("while building a pool")
            if not wait([self._conn, self._process.sentinel], timeout):
                return None

    def death(self, doing: str) -> str:
        """Why the (ended) worker process ended, for a message; ``doing``: what it was doing
        ("while building a pool", "while idle")."""
        code = self._process.exitcode
        name = f"the pool refresh's worker process (pid {self.pid})"
        if not self._started and code is not None and code > 0:
            # The spawned worker imports the main script; without the guard it runs the
            # script again, whose own refresh fails while the worker is still starting.
            return (
                f"{name} exited with code {code} before it could start: a script that starts one must "
                "guard its entry point with `if __name__ == '__main__':` (the worker is spawned and "
                "imports it), as for any spawned process, or call refresh_pool(wait=True)"
            )
        if code is not None and code < 0:
            try:
                how = f"was killed by signal {signal.Signals(-code).name}"
            except ValueError:
                how = f"was killed by signal {-code}"
        else:
            how = f"exited with code {code}"
        return f"{name} {how} {doing}"

    def close(self) -> None:
        """Stop the worker: a busy one at once (its job is dropped), an idle one when it sees
        its pipe close (terminated after a few seconds if it does not)."""
        if self._busy:
            self._process.terminate()
        else:
            self._conn.close()
        self._process.join(_CLOSE_GRACE)
        if self._process.is_alive():
            self._process.terminate()
            self._process.join()
        if self._sender is not None:  # its send fails once the worker is gone
            self._sender.join()
        self._conn.close()
        self._process.close()
