"""A training run's learning curve: a CSV of one row per held-out evaluation, and a PNG.

Columns (:data:`COLUMNS`): ``step`` (env steps trained), ``wall_s`` (seconds since the run
started, the resumed parts added up), ``train_episodes``, ``train_return``,
``train_success`` and ``train_spl`` (the training episodes that ended since the previous
row: their count, mean undiscounted return and means), and ``heldout_episodes``,
``heldout_success``, ``heldout_spl`` and ``heldout_soft_spl`` (the held-out evaluation of
the checkpoint at ``step``). The PNG (Pillow) draws held-out success and SPL and the
training success against the steps.
"""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Sequence
from typing import Any

from pointnav_core.errors import ArgumentError
from pointnav_core.utils.outputs import atomic_writer

__all__ = ["COLUMNS", "plot_curve", "read_curve", "write_curve"]

COLUMNS = ("step", "wall_s", "train_episodes", "train_return", "train_success", "train_spl",
           "heldout_episodes", "heldout_success", "heldout_spl", "heldout_soft_spl")
_INTEGERS = ("step", "train_episodes", "heldout_episodes")


def write_curve(rows: Sequence[dict[str, Any]], path: str | os.PathLike[str]) -> None:
    """Write ``rows`` (dicts of :data:`COLUMNS`) as CSV, whole or not at all."""
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=COLUMNS, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: (int(row[k]) if k in _INTEGERS else f"{float(row[k]):.6g}") for k in COLUMNS})
    with atomic_writer(path, "w", encoding="utf-8", newline="") as fh:
        fh.write(text.getvalue())


def read_curve(path: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """The rows of a CSV of :func:`write_curve` (ValueError naming the file for another)."""
    with open(path, encoding="utf-8", newline="") as fh:
        reader = csv.DictReader(fh)
        if tuple(reader.fieldnames or ()) != COLUMNS:
            raise ArgumentError(f"curve {os.fspath(path)!r} must have the columns {list(COLUMNS)}")
        return [{k: (int(r[k]) if k in _INTEGERS else float(r[k])) for k in COLUMNS} for r in reader]


def plot_curve(rows: Sequence[dict[str, Any]], path: str | os.PathLike[str]) -> None:
    """Held-out success (green) and SPL (blue), and training success (grey), against the
    env steps, as a PNG."""
    from PIL import Image, ImageDraw

    width, height, left, right, top, bottom = 720, 420, 60, 20, 40, 50
    image = Image.new("RGB", (width, height), "white")
    draw = ImageDraw.Draw(image)
    pw, ph = width - left - right, height - top - bottom
    x_max = max([1, *(r["step"] for r in rows)])

    def px(x: float, y: float) -> tuple[float, float]:
        return left + pw * x / x_max, top + ph * (1.0 - y)

    for k in range(11):
        draw.line([px(0, k / 10), px(x_max, k / 10)], fill=(230, 230, 230))
        draw.text((left - 30, px(0, k / 10)[1] - 6), f"{k / 10:.1f}", fill="black")
    for k in range(5):
        x = x_max * k / 4
        draw.text((px(x, 0)[0] - 16, px(x, 0)[1] + 8), f"{x / 1000:.0f}k", fill="black")
    draw.rectangle([px(0, 1), px(x_max, 0)], outline="black")
    for key, colour, line in (("train_success", (160, 160, 160), 1), ("heldout_success", (20, 150, 60), 3),
                              ("heldout_spl", (30, 70, 200), 2)):
        points = [px(r["step"], r[key]) for r in rows]
        if len(points) > 1:
            draw.line(points, fill=colour, width=line)
        for cx, cy in points:
            draw.ellipse([cx - 3, cy - 3, cx + 3, cy + 3], fill=colour)
    draw.text((left, 12), "held-out success (green) and SPL (blue), training success (grey)", fill="black")
    draw.text((left + pw / 2 - 40, height - 20), "env steps", fill="black")
    with atomic_writer(path) as fh:
        image.save(fh, format="PNG")
