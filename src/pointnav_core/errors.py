"""The library's exceptions: one base class and a few precise subclasses."""

from __future__ import annotations

__all__ = ["PointNavError", "SamplingError", "BackendError", "EpisodeError"]


class PointNavError(Exception):
    """Base class of every error raised on purpose by pointnav-core."""


class SamplingError(PointNavError, RuntimeError):
    """Sampling a start, a goal or a free point could not meet its constraints.

    The message names the constraint that failed and how many trials were made.
    """


class BackendError(PointNavError, TypeError):
    """A backend is unknown, or does not implement the Backend protocol."""


class EpisodeError(PointNavError, RuntimeError):
    """Playing an episode failed: its policy raised, or the process playing it died.

    The message names the episode (its id and scene) and the cause.
    """
