"""Evaluation results: one record per episode, their summary, the results file and a plot.

The results file has one JSON line per episode (:func:`result_line`), or CSV for a ``.csv``
path; both are written whole or not at all (:mod:`pointnav_core.outputs`).
"""

from __future__ import annotations

import csv
import json
import math
import os
from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass, fields

import numpy as np

from pointnav_core.outputs import atomic_writer

__all__ = [
    "EpisodeResult",
    "plot_results",
    "read_results",
    "result_line",
    "summarize",
    "write_results",
]


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


def summarize(results: Sequence[EpisodeResult]) -> dict[str, float]:
    """Means over episodes: ``success``, ``spl``, ``soft_spl``, ``distance_to_goal`` (m),
    ``path_length`` (m), ``collisions`` (per episode), ``steps``; and ``episodes``."""
    if not results:
        raise ValueError("no results to summarize")
    keys = ("success", "spl", "soft_spl", "distance_to_goal", "path_length", "collisions", "steps")
    summary = {k: float(np.mean([float(getattr(r, k)) for r in results])) for k in keys}
    summary["episodes"] = float(len(results))
    return summary


def result_line(result: EpisodeResult) -> str:
    """One episode as the results file's JSON line (with its newline)."""
    return json.dumps(asdict(result), sort_keys=False, allow_nan=True) + "\n"


def write_results(results: Iterable[EpisodeResult], path: str | os.PathLike[str]) -> None:
    """Write one row per episode: CSV for a ``.csv`` path, else JSON lines.

    The file is written whole or not at all (:func:`pointnav_core.outputs.atomic_writer`).
    """
    results = list(results)
    names = [f.name for f in fields(EpisodeResult)]
    with atomic_writer(path, "w", newline="", encoding="utf-8") as fh:
        if os.fspath(path).endswith(".csv"):
            writer = csv.DictWriter(fh, fieldnames=names, lineterminator="\n")
            writer.writeheader()
            for r in results:
                writer.writerow(
                    {k: repr(v) if isinstance(v, float) else v for k, v in asdict(r).items()}
                )
        else:
            fh.writelines(result_line(r) for r in results)


def read_results(path: str | os.PathLike[str]) -> list[EpisodeResult]:
    """Read results written by :func:`write_results` as JSON lines."""
    with open(path, encoding="utf-8") as fh:
        return [EpisodeResult(**json.loads(line)) for line in fh if line.strip()]


def plot_results(
    results: Sequence[EpisodeResult], path: str | os.PathLike[str], bin_width: float = 2.0
) -> None:
    """Draw SPL and success rate against geodesic distance as a PNG (Pillow).

    Each episode is a faint dot at its SPL; the lines join the means over bins of
    ``bin_width`` metres of geodesic distance (success green, SPL blue, SoftSPL orange).
    """
    from PIL import Image, ImageDraw

    if not results:
        raise ValueError("no results to plot")
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
        for lo, hi in zip(edges[:-1], edges[1:]):
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
