"""Pools over many scenes: each scene's part built in a worker process, with a progress bar.

A pool's scenes are independent: scene ``s``'s part (its episodes, sampled by its own
sampler from its own seeds, and their goal fields settled) depends on nothing else, and
the seeds of every scene are drawn up front. So the parts are built by
:class:`~pointnav_core.utils.workers.WorkerPool` (spawned workers that die with this process,
ignore Ctrl-C and report the item they held) on every usable core, and assembled here in
scene order: the same episodes as a build in this process, and the same distance at every
point. With the geometry disk cache on, a worker only samples its scene's episodes and
runs their goals' searches: its fields' cells are left to settle in the stepping process as
robots arrive (``FieldTables``), which makes each field again from its scene's sampler,
reloading the floor's geometry from the cache (or building it again, where that took under
``cache.MIN_SECONDS``); with the cache off, a worker settles them.

Each worker reloads a floor's geometry from the disk cache (:mod:`pointnav_core.geodesic.cache`)
when another process built it before, rather than building it again.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np

from pointnav_core.errors import ArgumentError
from pointnav_core.geodesic.cache import cache_dir
from pointnav_core.utils import validation
from pointnav_core.utils.workers import WorkerError, WorkerPool, usable_cores
from pointnav_core.vector.episodes import ScenePart, build_in_process
from pointnav_core.vector.fields import check_budget

__all__ = ["PARALLEL_SCENES", "PROGRESS_SCENES", "build_parts", "pool_options", "pool_workers"]

#: With ``workers=None``, a pool of fewer scenes is built in this process: a worker's start
#: (a second or two of imports) would cost more than it saves.
PARALLEL_SCENES = 4
#: With ``progress=None``, the bar is shown from this many scenes on (a generated house's
#: part takes about a second: a build of a few seconds or more).
PROGRESS_SCENES = 4


def pool_workers(workers: int | None, n_scenes: int) -> int:
    """The processes that build a pool of ``n_scenes`` scenes: ``workers`` (an int >= 1, or
    None: the usable cores, at most one per scene, and 1 under :data:`PARALLEL_SCENES`
    scenes), never more than the scenes; 1 means in this process."""
    if workers is None:
        return 1 if n_scenes < PARALLEL_SCENES else max(1, min(usable_cores(), n_scenes))
    return max(1, min(validation.integer("workers", workers, minimum=1), n_scenes))


def pool_options(workers: Any, progress: Any, n_scenes: int) -> tuple[int, bool | None]:
    """The envs' ``workers`` (:func:`pool_workers`) and ``progress`` (None or a bool),
    checked; ValueError naming the argument."""
    if progress is not None and not isinstance(progress, (bool, np.bool_)):
        raise ArgumentError(f"progress must be None, True or False, got {progress!r}")
    return pool_workers(workers, n_scenes), None if progress is None else bool(progress)


def _init(kind: Any, pool_size: int, starts: int, reach: float, lazy: bool) -> tuple[Any, int, int, float, bool]:
    return kind, pool_size, starts, reach, lazy


def _scene_task(state: tuple[Any, int, int, float, bool], item: tuple[int, Any, list[int]]) -> tuple[int, str, Any]:
    """Scene ``s``'s part in a worker; an error comes back as a value, to be raised with its type."""
    kind, pool_size, starts, reach, lazy = state
    s, env, seeds = item
    try:
        return s, "done", kind.scene_part(env, s, pool_size, seeds, starts, reach, lazy=lazy, portable=True)
    except Exception as error:  # noqa: BLE001 (raised again in the parent, naming the scene)
        return s, "raised", error


def build_parts(kind: Any, samplers: Sequence[Any], pool_size: int, seeds: Sequence[int], starts: int = 1,
                reach: float = math.inf, workers: int = 1, progress: bool | None = None) -> list[ScenePart]:
    """Every scene's part of a pool of ``kind`` (``EpisodePool`` or ``FleetPool``), in order.

    Parameters
    ----------
    kind : type
        The pool class (its ``scene_part`` builds one scene's part).
    samplers, pool_size, seeds, starts, reach
        As for the pool class: ``seeds`` holds ``pool_size`` seeds per scene, scene by scene.
    workers : int
        Processes (1: here, scene after scene).
    progress : bool, optional
        A tqdm bar over the scenes (on stderr); None: from :data:`PROGRESS_SCENES` scenes
        on, on a terminal.

    Raises
    ------
    Exception
        A scene's error, of its own type, naming the scene (``scene 3: ...``); a worker
        that dies raises :class:`~pointnav_core.utils.workers.WorkerError` naming its scene.
        The byte budget (:data:`~pointnav_core.vector.fields.FIELD_TABLE_BYTES`) is
        checked as the parts come in, before any further one is kept. Workers that cannot
        start (a script without the ``__main__`` guard) give a ``RuntimeWarning``, and the
        pool is built here.
    """
    from tqdm.auto import tqdm

    n = len(samplers)
    # None: tqdm's own choice (a terminal only) from PROGRESS_SCENES scenes on; True: shown.
    disable = (None if n >= PROGRESS_SCENES else True) if progress is None else not progress
    with tqdm(total=n, desc="pool scenes", unit="scene", disable=disable) as bar:
        if workers > 1 and n > 1:
            try:
                return _in_workers(kind, samplers, pool_size, seeds, starts, reach, workers, bar)
            except WorkerError as error:
                if error.key is not None:
                    raise
                # No worker started: most often a script without the __main__ guard.
                warnings.warn(
                    f"the pool's worker processes could not start ({error.cause}): a script that starts "
                    "them must guard its entry point with `if __name__ == '__main__':`; building the pool "
                    "in this process (workers=1 does so without trying)", RuntimeWarning, stacklevel=4,
                )
        # Here, in the stepping process: the fields settle lazily, as robots arrive.
        return build_in_process(kind, samplers, pool_size, seeds, starts, reach, bar.update, lazy=True)


def _in_workers(kind: Any, samplers: Sequence[Any], pool_size: int, seeds: Sequence[int], starts: int, reach: float,
                workers: int, bar: Any) -> list[ScenePart]:
    """:func:`build_parts` with ``workers`` processes; the budget is checked as parts come in."""
    n = len(samplers)
    parts: list[ScenePart | None] = [None] * n
    cells = goals = 0
    items = ((f"scene {s}", (s, env, [int(v) for v in seeds[s * pool_size:(s + 1) * pool_size]]))
             for s, env in enumerate(samplers))
    # With the geometry disk cache on, the parent reloads each floor's geometry cheaply, so
    # the workers only sample and the fields settle in the parent as robots arrive.
    lazy = cache_dir() is not None
    with WorkerPool(min(workers, n), _init, (kind, pool_size, starts, reach, lazy), _scene_task) as pool:
        for _, (s, status, value) in pool.imap_unordered(items):
            if status == "raised":
                raise _scene_error(s, value)
            check_budget([], cells + value.cells, goals + len(value.fields))
            cells, goals = cells + value.cells, goals + len(value.fields)
            parts[s] = value
            bar.update(1)
    return parts  # type: ignore[return-value]


def _scene_error(s: int, error: BaseException) -> BaseException:
    """``error`` of a worker's scene ``s``, again of its type when it takes a message."""
    message = f"scene {s}: {error}"
    try:
        again = type(error)(message)
    except Exception:  # noqa: BLE001 (an exception class with other arguments)
        return WorkerError(f"scene {s}", f"{type(error).__name__}: {error}")
    return again
