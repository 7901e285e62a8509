"""The ``pointnav scene build`` command: a scene's geometry built ahead, into the disk cache.

``pointnav scene build SCENE [SCENE ...] [--robot-radius R ...]`` builds, for every floor
of every scene and every robot radius, the per-floor geometry that a geodesic query needs
(the tangent graph's nodes, sight bounds and edges: :mod:`pointnav_core.geodesic.cache`)
and keeps it in the geometry cache, as Habitat keeps a scene's navmesh in a file. Every
later process (an eval worker, a pool worker, an SB3 subprocess, a Ray worker) then loads
it instead of building it. ``SCENE`` is anything a dataset's ``scene_id`` can be
(``rooms:3``, ``movingai:PATH``, a ``.map`` or ``.png`` path, ...); ``--scenes SET --split
S`` adds every scene of a split of a scene set. The oracle also plans for a robot 2 cm
wider, so ``--oracle`` builds that radius too.

Floors whose build is quicker than reading it back (:data:`~pointnav_core.geodesic.cache.MIN_SECONDS`)
are not kept; the summary says how many were.
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Sequence
from typing import Any

from pointnav_core.errors import ArgumentError
from pointnav_core.utils.workers import WorkerError, WorkerPool, usable_cores

__all__ = ["add_commands", "build_scenes"]

#: Extra width (m) the oracle (``ShortestPathFollower``'s default ``margin``) plans with.
_ORACLE_MARGIN = 0.02


def _no_state() -> None:
    return None


def _build_job(_state: None, job: tuple[str, str | None, float]) -> tuple[str, float, int, int, float]:
    return _build_one(*job)


def _build_one(scene_id: str, root: str | None, radius: float) -> tuple[str, float, int, int, float]:
    """Build every floor of ``scene_id`` for ``radius`` (m): ``(scene_id, radius, floors,
    kept, seconds)``, where ``kept`` counts the floors whose build is in the cache now."""
    from pointnav_core.datasets.scene_sets import load_scene
    from pointnav_core.geodesic import planner_for

    started = time.perf_counter()
    scene = load_scene(scene_id, root)
    kept = 0
    for tmap in scene.floors:
        planner = planner_for(tmap, radius)
        planner.build_all_edges()
        planner.cell_links()  # every cell's clear links, where the floor is small enough
        kept += planner.cached
    return scene_id, radius, scene.n_floors, kept, time.perf_counter() - started


def build_scenes(
    scene_ids: Sequence[str],
    radii: Sequence[float],
    *,
    root: str | None = None,
    workers: int = 1,
    progress: bool = True,
) -> list[tuple[str, float, int, int, float]]:
    """Build every floor of every scene for every radius, in ``workers`` processes.

    Returns one ``(scene_id, radius, floors, kept, seconds)`` per scene and radius, in the
    order given; ``kept`` is the number of floors whose build is in the disk cache.
    """
    from tqdm import tqdm

    jobs = [(scene_id, root, float(r)) for scene_id in scene_ids for r in radii]
    done: dict[int, tuple[str, float, int, int, float]] = {}
    with tqdm(total=len(jobs), desc="scenes", unit="scene", disable=not progress or None) as bar:
        if workers == 1:
            for i, job in enumerate(jobs):
                done[i] = _build_one(*job)
                bar.update(1)
        else:
            # Workers that end with this process, even when it is killed (pointnav_core.utils.workers).
            with WorkerPool(min(workers, len(jobs), usable_cores()), _no_state, (), _build_job) as pool:
                try:
                    for i, row in pool.imap_unordered(enumerate(jobs)):
                        done[i] = row  # type: ignore[index]
                        bar.update(1)
                except WorkerError as err:
                    where = "" if err.key is None else f"scene {jobs[err.key][0]!r}: "  # type: ignore[index]
                    raise ArgumentError(f"{where}{err.cause}") from None
    return [done[i] for i in range(len(jobs))]


def _scene_build(args: argparse.Namespace) -> int:
    from pointnav_core.datasets import scene_set
    from pointnav_core.geodesic import cache

    folder = cache.cache_dir()
    if folder is None:
        raise ArgumentError(f"the geometry cache is off ({cache.ENV_VAR}={os.environ.get(cache.ENV_VAR)!r}): nothing to keep")
    ids = list(args.scene)
    if args.scenes is not None:
        ids += scene_set(args.scenes).scene_ids(args.split)
    if not ids:
        raise ArgumentError("give at least one SCENE, or --scenes SET")
    radii = sorted({*args.robot_radius, *(r + _ORACLE_MARGIN for r in args.robot_radius if args.oracle)})
    for r in radii:
        if not r > 0:
            raise ArgumentError(f"--robot-radius must be > 0 (m), got {r}")
    started = time.perf_counter()
    rows = build_scenes(ids, radii, root=args.scenes_dir, workers=args.workers, progress=not args.quiet)
    floors, kept = sum(row[2] for row in rows), sum(row[3] for row in rows)
    print(
        f"built {floors} floor(s) of {len(set(ids))} scene(s) for radius {', '.join(f'{r:g}' for r in radii)} m "
        f"in {time.perf_counter() - started:.1f} s; {kept} kept in {folder} "
        f"(the rest build in under {cache.MIN_SECONDS} s)"
    )
    return 0


def add_commands(sub: Any, positive_int: Any, reporting: Any) -> None:
    """Add ``scene build`` to the ``pointnav`` sub-command parser."""
    scene = sub.add_parser("scene", help="scenes' geometry, built ahead into the disk cache")
    ssub = scene.add_subparsers(dest="scene_command", required=True)
    build = ssub.add_parser("build", help="build scenes' per-floor geometry into the cache")
    build.add_argument("scene", nargs="*", metavar="SCENE", help="scene ids or files (rooms:3, movingai:PATH, a .map, ...)")
    build.add_argument("--scenes", metavar="SET", help="also every scene of SET's --split")
    build.add_argument("--split", default="val", help="the split of --scenes (default val)")
    build.add_argument("--scenes-dir", metavar="DIR", help="folder relative scene paths are read from")
    build.add_argument(
        "--robot-radius", type=float, nargs="+", default=[0.18], metavar="M", help="robot radii (default 0.18 m)"
    )
    build.add_argument("--oracle", action="store_true", help="also the radius the oracle plans with (+2 cm)")
    build.add_argument("--workers", type=positive_int, default=1, metavar="N")
    build.add_argument("--quiet", action="store_true", help="no progress bar")
    build.set_defaults(func=reporting("scene build", _scene_build))
