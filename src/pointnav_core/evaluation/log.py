"""The log a run of ``pointnav eval`` appends each finished episode to, and resumes from.

Next to the results file ``R`` a run keeps ``R.partial``: a first line naming the run's
settings (``{"pointnav_eval": {...}}``), then one line per finished episode, exactly the
line it will have in ``R`` (:func:`~pointnav_core.evaluation.report.result_line`); ``R``
starts with the same first line and ends with the summary. Each
line goes to disk in one ``write`` as its episode ends, and is taken back if the write
fails (a full disk), so the log is valid JSON lines whatever stops the run. ``R`` itself is
written once, at the end, in the dataset's order, whole or not at all; the log is then
removed. A resumed run reads the log back and plays only the episodes missing from it, so
its ``R`` is byte for byte the one an uninterrupted run writes.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from typing import Any

from pointnav_core.datasets.format import PointNavEpisode
from pointnav_core.errors import ArgumentError, PointNavError
from pointnav_core.evaluation.report import (
    EpisodeResult,
    result_line,
    run_line,
    summary_record,
    write_results,
)

__all__ = ["ResultsLog", "ResultsWriteError"]


class ResultsWriteError(PointNavError, OSError):
    """The log or the results file could not be written (a full disk, a file-size limit)."""


class ResultsLog:
    """``results + ".partial"``: see the module notes.

    Parameters
    ----------
    results : str
        The results file the run ends with.
    settings : mapping
        What decides the results (library version, dataset and its hash, policy, backend,
        episode selection, ...): a resumed run must have the same. The results file
        records them.
    """

    def __init__(self, results: str, settings: Mapping[str, Any]) -> None:
        self.results = results
        self.path = results + ".partial"
        self.settings = dict(settings)
        self.header = run_line(self.settings)
        self.done: dict[str, EpisodeResult] = {}
        self._fd: int | None = None
        self._size = 0

    def start(self, resume: bool, episodes: Sequence[PointNavEpisode]) -> dict[str, EpisodeResult]:
        """Open the log: read it back with ``resume``, else create it. Returns the finished
        results it holds, by episode id.

        A log that holds no finished episode is started again.

        Raises
        ------
        ValueError
            For a log left by another run while ``resume`` is False, a log written with
            other settings, or one naming an episode the dataset does not have.
        """
        if os.path.exists(self.path) and os.path.getsize(self.path) > len(self.header.encode()):
            if not resume:
                raise ArgumentError(
                    f"{self.path} holds the finished episodes of an earlier run: add --resume "
                    "to finish that run, or delete the file to start again"
                )
            self._read(episodes)
        else:
            self._fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_APPEND, 0o666)
            try:
                self._write(self.header.encode())
            except ResultsWriteError:
                self.close()
                os.unlink(self.path)
                raise
        return dict(self.done)

    def _read(self, episodes: Sequence[PointNavEpisode]) -> None:
        scenes = {ep.episode_id: ep.scene_id for ep in episodes}
        with open(self.path, "rb") as fh:
            lines = fh.read().split(b"\n")
        if not lines[0] or lines[0] + b"\n" != self.header.encode():
            raise ArgumentError(
                f"{self.path} was written by a run with other arguments or inputs (dataset or "
                "its contents, policy, backend, drive, max steps, scenes folder, --limit, "
                "--stride or library version): rerun with those, or delete it"
            )
        size = len(lines[0]) + 1
        for number, line in enumerate(lines[1:], start=2):
            try:
                result = EpisodeResult(**json.loads(line))
            except (ValueError, TypeError):
                break  # a torn last line (the disk filled as it was written): dropped
            if scenes.get(result.episode_id) != result.scene_id:
                raise ArgumentError(
                    f"{self.path}, line {number}: episode {result.episode_id!r} of scene "
                    f"{result.scene_id!r} is not in the dataset"
                )
            self.done.setdefault(result.episode_id, result)
            size += len(line) + 1
        self._fd = os.open(self.path, os.O_WRONLY | os.O_APPEND)
        os.ftruncate(self._fd, size)
        self._size = size

    def _write(self, data: bytes) -> None:
        assert self._fd is not None
        start = self._size
        try:
            written = 0
            while written < len(data):
                written += os.write(self._fd, data[written:])
            os.fsync(self._fd)
        except OSError as err:
            try:  # take the torn line back, so the log stays whole lines
                os.ftruncate(self._fd, start)
            except OSError:
                pass
            raise ResultsWriteError(f"cannot write {self.path}: {err.strerror or err}") from None
        self._size = start + len(data)

    def append(self, result: EpisodeResult) -> None:
        """Add a finished episode to the log, on disk before this returns."""
        self._write(result_line(result).encode())
        self.done.setdefault(result.episode_id, result)

    def finish(
        self, episodes: Sequence[PointNavEpisode]
    ) -> tuple[list[EpisodeResult], dict[str, Any] | None]:
        """Write the results file (the settings, the finished episodes in the dataset's
        order, their summary), then remove the log. Returns those results and the summary
        (:func:`~pointnav_core.evaluation.report.summary_record`; None without results)."""
        ordered = [self.done[ep.episode_id] for ep in episodes if ep.episode_id in self.done]
        summary = summary_record(ordered) if ordered else None
        try:
            write_results(ordered, self.results, run=self.settings, summary=summary)
        except OSError as err:
            raise ResultsWriteError(f"cannot write {self.results}: {err.strerror or err}") from None
        self.close()
        os.unlink(self.path)
        return ordered, summary

    def close(self) -> None:
        """Close the log, keeping it on disk."""
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None
