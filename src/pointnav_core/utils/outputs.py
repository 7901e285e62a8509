"""Output files written whole or not at all, and output paths checked before any work.

Every file the library or the command line writes (results, plots, datasets, pictures) goes
through :func:`atomic_writer`: the bytes go to a temporary file in the same folder, are
flushed to disk, and the temporary file is then renamed over the target. A reader, or a
crash, a kill or a full disk in the middle, sees the old file or the new one, never a
mixture or a truncated file.

:func:`check_output` is called on every output path before the first episode is played, so
that a bad path costs nothing; it also refuses an output that is one of the inputs.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from typing import IO, Any

from pointnav_core.errors import ArgumentError

__all__ = ["atomic_writer", "check_output", "same_file"]

PathArg = str | os.PathLike[str]


@contextmanager
def atomic_writer(path: PathArg, mode: str = "wb", **kwargs: Any) -> Iterator[IO[Any]]:
    """Open a temporary file next to ``path``; on a clean exit it replaces ``path``.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write.
    mode : str
        ``"wb"`` or ``"w"`` (then ``kwargs`` such as ``encoding`` and ``newline`` apply).

    Notes
    -----
    On an exception (including a full disk while writing or flushing) the temporary file is
    removed and ``path`` is left as it was. The new file gets the permissions a plain
    ``open`` would give it (0o666 less the umask), not ``mkstemp``'s 0o600.
    """
    if mode not in ("w", "wb"):
        raise ArgumentError(f"mode must be 'w' or 'wb', got {mode!r}")
    target = os.fspath(path)
    folder, name = os.path.split(os.path.abspath(target))
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, mode, **kwargs) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, target)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def same_file(a: PathArg, b: PathArg) -> bool:
    """Whether two paths name the same file (after links; an absent file compares by path)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)


def check_output(name: str, path: PathArg, inputs: Sequence[PathArg] = ()) -> str:
    """Refuse an output path that cannot be written, before any work is done.

    Parameters
    ----------
    name : str
        The argument's name, for the message (``--results``).
    path : str or os.PathLike
        The output file.
    inputs : sequence of paths
        Files the same run reads: the output may not be one of them.

    Returns
    -------
    str
        ``path`` as a string.

    Raises
    ------
    ValueError
        When the path is a folder, its folder does not exist or cannot be written, or it is
        one of ``inputs``; the message names ``name`` and the path.
    """
    target = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(target))
    if not target or os.path.isdir(target):
        raise ArgumentError(f"{name} {target!r} is a folder; give a file path")
    if not os.path.isdir(folder):
        raise ArgumentError(f"{name} {target!r}: folder {folder!r} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise ArgumentError(f"{name} {target!r}: folder {folder!r} is not writable")
    if os.path.exists(target) and not os.access(target, os.W_OK):
        raise ArgumentError(f"{name} {target!r} exists and is not writable")
    for source in inputs:
        if same_file(target, source):
            raise ArgumentError(f"{name} {target!r} is an input of this run; give another path")
    return target
