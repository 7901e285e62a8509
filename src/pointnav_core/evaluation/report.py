"""Evaluation results: one record per episode, their summary, the results file and a plot.

The results file is JSON lines: optionally a first line ``{"pointnav_eval": RUN}`` (what
produced the results: library version, dataset hash, settings), one line per episode
(:func:`result_line`), and optionally a last line ``{"summary": SUMMARY}``
(:func:`summary_record`: the means and their 95 % bootstrap confidence intervals). A ``.csv``
path gets the per-episode table only, and the run and summary records go to a JSON file
beside it (:func:`summary_path`). Every file is written whole or not at all
(:mod:`pointnav_core.utils.outputs`).

Confidence intervals (:func:`bootstrap_interval`) are percentile bootstrap intervals of the
mean: ``resamples`` (10,000) resamples of the episodes with replacement, drawn from
``numpy.random.default_rng(seed)`` (seed 0), resample ``b`` being the ``b``-th draw of
``rng.integers(0, n, size=n)``; the bounds are the ``(1 - confidence) / 2`` and
``(1 + confidence) / 2`` quantiles of the resample means (numpy's default linear
interpolation). Success, SPL and SoftSPL share the same resamples. The same results give
the same intervals.
"""

from __future__ import annotations

import csv
import itertools
import json
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.utils.outputs import atomic_writer
from pointnav_core.utils.validation import integer, real

__all__ = [
    "BOOTSTRAP_RESAMPLES",
    "INTERVAL_METRICS",
    "EpisodeResult",
    "bootstrap_interval",
    "plot_results",
    "read_results",
    "read_run",
    "result_line",
    "run_line",
    "summarize",
    "summary_path",
    "summary_record",
    "write_results",
]

#: Resamples behind each bootstrap confidence interval.
BOOTSTRAP_RESAMPLES = 10_000
#: The per-episode metrics that get a confidence interval.
INTERVAL_METRICS = ("success", "spl", "soft_spl")
#: Resampled values held in memory at once (8 bytes each, per metric).
_CHUNK = 1 << 20


@dataclass(frozen=True)
class EpisodeResult:
    """What happened in one episode.

    Attributes
    ----------
    episode_id, scene_id : str
    floor : int
    geodesic_distance : float
        Recorded in the dataset (m).
    success : bool
    spl, soft_spl : float
    distance_to_goal : float
        Geodesic distance (m) from where the robot ended to the goal.
    path_length : float
        Distance driven (m).
    collisions : int
        Steps in which the robot touched something.
    steps : int
    ended_by : str
        The termination conditions that ended the episode, joined by ``+``.
    pedestrian_collisions : int or None
        Steps in which the robot touched a pedestrian; None in an env without pedestrians.
    social : dict or None
        The episode's social metrics (:func:`pointnav_core.task.social_metrics`, the env's
        ``info["social"]``), values None where undefined; None without pedestrians.
    """

    episode_id: str
    scene_id: str
    floor: int
    geodesic_distance: float
    success: bool
    spl: float
    soft_spl: float
    distance_to_goal: float
    path_length: float
    collisions: int
    steps: int
    ended_by: str
    pedestrian_collisions: int | None = None
    social: Mapping[str, float | None] | None = None


def summarize(results: Sequence[EpisodeResult]) -> dict[str, float]:
    """Means over episodes: ``success``, ``spl``, ``soft_spl``, ``distance_to_goal`` (m),
    ``path_length`` (m), ``collisions`` (per episode), ``steps``; and ``episodes``. With
    pedestrians also ``pedestrian_collisions`` (per episode) and ``social_<metric>`` for
    each social metric, the mean over the episodes where it is defined (not None)."""
    if not results:
        raise ArgumentError("no results to summarize")
    keys = ("success", "spl", "soft_spl", "distance_to_goal", "path_length", "collisions", "steps")
    summary = {k: float(np.mean([float(getattr(r, k)) for r in results])) for k in keys}
    counts = [r.pedestrian_collisions for r in results if r.pedestrian_collisions is not None]
    if counts:
        summary["pedestrian_collisions"] = float(np.mean(counts))
    socials = [r.social for r in results if r.social]
    for key in dict.fromkeys(k for social in socials for k in social):
        defined = [float(v) for social in socials if (v := social.get(key)) is not None]
        if defined:
            summary[f"social_{key}"] = float(np.mean(defined))
    summary["episodes"] = float(len(results))
    return summary


def bootstrap_interval(
    values: ArrayLike,
    *,
    confidence: float = 0.95,
    resamples: int = BOOTSTRAP_RESAMPLES,
    seed: int = 0,
) -> NDArray[np.float64]:
    """Percentile bootstrap confidence interval of the mean (see the module notes).

    Parameters
    ----------
    values : array_like, shape (n,) or (n, k)
        One value per episode (a column per metric: the columns share the resamples).
    confidence : float
        In (0, 1] (1: the range of the resample means).
    resamples : int
        Number of bootstrap resamples (>= 1).
    seed : int
        Seed of ``numpy.random.default_rng`` (>= 0).

    Returns
    -------
    ndarray, shape (2,) or (2, k)
        The lower and upper bounds (of each column).
    """
    data = np.asarray(values, dtype=float)
    if data.ndim not in (1, 2) or data.shape[0] < 1 or not np.isfinite(data).all():
        raise ArgumentError(
            f"values must be a non-empty (n,) or (n, k) array of finite numbers, got shape {data.shape}"
        )
    real("confidence", confidence, minimum=0.0, strict=True, maximum=1.0, unit="")
    integer("resamples", resamples, minimum=1)
    integer("seed", seed, minimum=0)
    n = data.shape[0]
    columns = data.reshape(n, -1)
    rng = np.random.default_rng(seed)
    means = np.empty((resamples, columns.shape[1]))
    rows = max(1, _CHUNK // n)  # a chunk of rows draws the same numbers as row by row
    for start in range(0, resamples, rows):
        stop = min(resamples, start + rows)
        means[start:stop] = columns[rng.integers(0, n, size=(stop - start, n))].mean(axis=1)
    tail = (1.0 - confidence) / 2.0
    bounds = np.quantile(means, [tail, 1.0 - tail], axis=0)
    return bounds.reshape((2, *data.shape[1:]))


def summary_record(
    results: Sequence[EpisodeResult],
    *,
    confidence: float = 0.95,
    resamples: int = BOOTSTRAP_RESAMPLES,
    seed: int = 0,
) -> dict[str, Any]:
    """The results file's summary: :func:`summarize`'s means (``episodes`` as an int) and
    ``intervals``: ``{"success": [lo, hi], "spl": ..., "soft_spl": ..., "confidence",
    "method", "resamples", "seed"}`` (:func:`bootstrap_interval`)."""
    record: dict[str, Any] = dict(summarize(results))
    record["episodes"] = len(results)
    table = [[float(getattr(r, k)) for k in INTERVAL_METRICS] for r in results]
    bounds = bootstrap_interval(table, confidence=confidence, resamples=resamples, seed=seed)
    intervals: dict[str, Any] = {
        "confidence": float(confidence),
        "method": "percentile bootstrap",
        "resamples": resamples,
        "seed": seed,
    }
    for j, key in enumerate(INTERVAL_METRICS):
        intervals[key] = [float(bounds[0, j]), float(bounds[1, j])]
    record["intervals"] = intervals
    return record


def result_line(result: EpisodeResult) -> str:
    """One episode as the results file's JSON line (with its newline)."""
    return json.dumps(asdict(result), sort_keys=False, allow_nan=True) + "\n"


def run_line(run: Mapping[str, Any]) -> str:
    """The first line of a results file (and of its log): ``{"pointnav_eval": run}``."""
    return json.dumps({"pointnav_eval": dict(run)}, sort_keys=True) + "\n"


def summary_path(path: str | os.PathLike[str]) -> str:
    """Where the run and summary records of a ``.csv`` results file go: ``R.csv`` ->
    ``R.summary.json``."""
    return os.fspath(path).removesuffix(".csv") + ".summary.json"


def write_results(
    results: Iterable[EpisodeResult],
    path: str | os.PathLike[str],
    *,
    run: Mapping[str, Any] | None = None,
    summary: Mapping[str, Any] | None = None,
) -> None:
    """Write one row per episode: CSV for a ``.csv`` path, else JSON lines.

    With ``run`` (what produced the results) and ``summary`` (:func:`summary_record`), a
    JSON lines file starts with ``{"pointnav_eval": run}`` and ends with
    ``{"summary": summary}``; for a ``.csv`` path they are written to :func:`summary_path`
    as one JSON object. Each file is written whole or not at all
    (:func:`pointnav_core.utils.outputs.atomic_writer`).
    """
    results = list(results)
    names = [f.name for f in fields(EpisodeResult)]
    is_csv = os.fspath(path).endswith(".csv")
    with atomic_writer(path, "w", newline="", encoding="utf-8") as fh:
        if is_csv:
            writer = csv.DictWriter(fh, fieldnames=names, lineterminator="\n")
            writer.writeheader()
            for r in results:
                writer.writerow({k: _csv_cell(v) for k, v in asdict(r).items()})
        else:
            if run is not None:
                fh.write(run_line(run))
            fh.writelines(result_line(r) for r in results)
            if summary is not None:
                fh.write(json.dumps({"summary": dict(summary)}) + "\n")
    if is_csv and (run is not None or summary is not None):
        records = {"pointnav_eval": dict(run or {}), "summary": dict(summary or {})}
        with atomic_writer(summary_path(path), "w", encoding="utf-8") as fh:
            fh.write(json.dumps(records, indent=1) + "\n")


def _csv_cell(value: Any) -> Any:
    """A CSV cell: floats exactly (``repr``), a dict (the social metrics) as JSON, and
    None as an empty cell."""
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, Mapping):
        return json.dumps(dict(value))
    return "" if value is None else value


def _records(path: str | os.PathLike[str]) -> Iterable[dict[str, Any]]:
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            if line.strip():
                yield json.loads(line)


def read_results(path: str | os.PathLike[str]) -> list[EpisodeResult]:
    """The episodes of a JSON lines results file written by :func:`write_results` (its run
    and summary records are skipped: :func:`read_run`)."""
    return [EpisodeResult(**r) for r in _records(path) if "episode_id" in r]


def read_run(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The run and summary records of a results file: ``{"pointnav_eval": {...},
    "summary": {...}}`` (either absent when the file has none). A ``.csv`` path reads its
    :func:`summary_path`."""
    if os.fspath(path).endswith(".csv"):
        with open(summary_path(path), encoding="utf-8") as fh:
            return {k: v for k, v in json.load(fh).items() if v}
    return {k: v for r in _records(path) if "episode_id" not in r for k, v in r.items()}


def plot_results(
    results: Sequence[EpisodeResult], path: str | os.PathLike[str], bin_width: float = 2.0
) -> None:
    """Draw SPL and success rate against geodesic distance as a PNG (Pillow).

    Each episode is a faint dot at its SPL; the lines join the means over bins of
    ``bin_width`` metres of geodesic distance (success green, SPL blue, SoftSPL orange).
    """
    from PIL import Image, ImageDraw

    if not results:
        raise ArgumentError("no results to plot")
    width, height, left, right, top, bottom = 720, 420, 60, 20, 40, 50
    geo = np.array([r.geodesic_distance for r in results])
    spl = np.array([r.spl for r in results])
    success = np.array([float(r.success) for r in results])
    x_max = max(bin_width, math.ceil(geo.max() / bin_width) * bin_width)
    image = Image.new("RGB", (width, height), "white")
    draw = ImageDraw.Draw(image)
    pw, ph = width - left - right, height - top - bottom

    def px(x: float, y: float) -> tuple[float, float]:
        return left + pw * x / x_max, top + ph * (1.0 - y)

    for k in range(11):  # grid and y ticks
        y = k / 10
        draw.line([px(0, y), px(x_max, y)], fill=(230, 230, 230))
        draw.text((left - 30, px(0, y)[1] - 6), f"{y:.1f}", fill="black")
    step = bin_width * max(1, round(x_max / bin_width / 10))
    x = 0.0
    while x <= x_max + 1e-9:
        draw.line([px(x, 0), (px(x, 0)[0], px(x, 0)[1] + 4)], fill="black")
        draw.text((px(x, 0)[0] - 8, px(x, 0)[1] + 8), f"{x:g}", fill="black")
        x += step
    draw.rectangle([px(0, 1), px(x_max, 0)], outline="black")
    for g, s in zip(geo, spl):
        cx, cy = px(g, s)
        draw.ellipse([cx - 1.5, cy - 1.5, cx + 1.5, cy + 1.5], fill=(170, 190, 235))
    edges = np.arange(0.0, x_max + bin_width / 2, bin_width)
    soft = np.array([r.soft_spl for r in results])
    # Success under the others, wider, so that equal curves stay visible.
    for values, colour, line in (
        (success, (20, 150, 60), 5),
        (soft, (230, 140, 20), 2),
        (spl, (30, 70, 200), 2),
    ):
        points = []
        for lo, hi in itertools.pairwise(edges):
            sel = (geo >= lo) & (geo < hi)
            if sel.any():
                points.append(px((lo + hi) / 2, float(values[sel].mean())))
        if len(points) > 1:
            draw.line(points, fill=colour, width=line)
        for cx, cy in points:
            draw.ellipse([cx - 3, cy - 3, cx + 3, cy + 3], fill=colour)
    draw.text(
        (left, 12),
        f"success (green), SPL (blue) and SoftSPL (orange) vs geodesic distance, {len(results)} episodes",
        fill="black",
    )
    draw.text((left + pw / 2 - 60, height - 20), "geodesic distance (m)", fill="black")
    with atomic_writer(path) as fh:
        image.save(fh, format="PNG")
