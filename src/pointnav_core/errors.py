"""The library's exceptions: one base class and a few precise subclasses.

Every error pointnav-core raises on purpose derives from :class:`PointNavError`, so
``except PointNavError`` catches them all, and nothing else. Each subclass also derives
from the builtin exception that Python, Gymnasium and PettingZoo code would raise for the
same fault, so ``except ValueError`` (or ``RuntimeError``, ``TypeError``) keeps working.
The same misuse raises the same class in every engine: the single env
(``PointNav-v0``), the PettingZoo ``parallel_env`` and the batched ``VectorPointNavEnv``.

===========================  ===========================  ===============================================
class                        also a                       raised when
===========================  ===========================  ===============================================
:class:`PointNavError`       ``Exception``                (base class; never raised itself)
:class:`ArgumentError`       ``ValueError``               an argument (or a file it names) is refused:
                                                          the message starts with the parameter's name
                                                          and says what was expected, with the unit
:class:`ArgumentTypeError`   ``ArgumentError``,           an argument is an object of the wrong type
                             ``TypeError``                (a Polygon, a RobotSpec, ... was expected)
:class:`TaskStateError`      ``RuntimeError``             a call is not legal in the current state:
                                                          ``step`` before ``reset``, after the end
:class:`SamplingError`       ``RuntimeError``             a start, goal or free point meeting the
                                                          constraints was not found
:class:`BackendError`        ``TypeError``                a backend does not implement the protocol
``UnknownBackendError``      ``BackendError``,            a backend name is not registered
                             ``ValueError``               (``pointnav_core.backends.protocol``)
``ConformanceError``         ``BackendError``,            a backend fails the conformance kit
                             ``AssertionError``           (``pointnav_core.testing.conformance``)
:class:`EpisodeError`        ``RuntimeError``             playing an evaluation episode failed
``WorkerError``              ``RuntimeError``             a worker process died or raised
                                                          (``pointnav_core.utils.workers``)
``ResultsWriteError``        ``OSError``                  a results file could not be written
                                                          (``pointnav_core.evaluation.log``)
===========================  ===========================  ===============================================

The names follow Python's own ``argparse.ArgumentError`` and ``ArgumentTypeError``: an
argument error is a ``ValueError``, as Gymnasium's and PettingZoo's argument checks raise.

>>> from pointnav_core.utils.validation import real
>>> try:
...     real("radius", True, minimum=0.0)
... except ValueError as err:
...     print(type(err).__name__, isinstance(err, PointNavError), "|", err)
ArgumentError True | radius must be a finite number >= 0 (m), got True
"""

from __future__ import annotations

__all__ = [
    "PointNavError", "ArgumentError", "ArgumentTypeError", "TaskStateError", "SamplingError",
    "BackendError", "EpisodeError",
]


class PointNavError(Exception):
    """Base class of every error raised on purpose by pointnav-core."""


class ArgumentError(PointNavError, ValueError):
    """An argument is refused: the message names the parameter and what was expected.

    Also raised for the contents of a file an argument names (a map image, a dataset, a
    config file): the message then names the file and the field.
    """


class ArgumentTypeError(ArgumentError, TypeError):
    """An argument is an object of the wrong type (e.g. a Polygon was expected).

    Both a ``TypeError``, as Python raises for the wrong type, and an :class:`ArgumentError`,
    so that ``except ArgumentError`` catches every refused argument.
    """


class TaskStateError(PointNavError, RuntimeError):
    """A method was called in a state that does not allow it (e.g. step before reset).

    Raised the same way by the single task and env, the PettingZoo env and the batched
    engine. The state is unchanged when this is raised.
    """


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
