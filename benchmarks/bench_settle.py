"""Settling a goal field's left-over cells: one cell at a time beside the batched path.

A square map of ``--side`` cells (0.1 m) holds ``--boxes`` random boxes of 2-9 cells a
side; a 0.18 m robot's goal field for a random goal is built and every block of its root
table is checked (``settle``'s first part, timed as ``setup``). The cells left without a
root (kind 3) are then settled on copies of the same table by ``GoalField._settle_cells``
(``batched``) and, unless ``--no-loop``, by ``GoalField._settle_cell`` one cell at a time
(``loop``, what ``settle`` did before; with ``--loop-every N`` only every N-th cell, its
time scaled to all of them), and the two tables are compared on the cells both settled.

Run: ``python benchmarks/bench_settle.py [--side 500] [--boxes 190] [--no-loop | --loop-every N]``
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from bench_build import grid  # the same random-box map (this folder is on the path when run)

from pointnav_core import scenes
from pointnav_core.tangent_field import _BLOCK


def build(side: int, boxes: int) -> tuple[object, float]:
    """The goal field with every block checked, and the seconds that took."""
    scene = scenes.Scene.from_array(grid(side, boxes), 0.1)  # bench_build's map
    start = time.perf_counter()
    planner = scene.planner(0, 0.18)
    goal = scene.get_random_point(0, robot=0.18, rng=np.random.default_rng(1))[1][:2]
    field = planner.goal_field(goal)
    t = field._build_table()
    h, w = planner.geo.shape
    for r0 in range(0, h, _BLOCK):
        for c0 in range(0, w, _BLOCK):
            field._check_block(r0 * w + c0)
    return field, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=500, help="cells per side")
    parser.add_argument("--boxes", type=int, default=190, help="random boxes")
    parser.add_argument("--no-loop", action="store_true", help="skip the one-cell-at-a-time settle")
    parser.add_argument("--loop-every", type=int, default=1, help="settle every N-th cell one at a time")
    args = parser.parse_args()
    field, setup = build(args.side, args.boxes)
    t = field._table
    cells = np.flatnonzero(t["kind"] == 3)
    print(f"{args.side} x {args.side} cells, {args.boxes} boxes: setup {setup:.1f} s, {len(cells)} cells of kind 3")
    before = {k: v.copy() for k, v in t.items() if isinstance(v, np.ndarray)}
    start = time.perf_counter()
    field._settle_cells(cells)
    batched = time.perf_counter() - start
    print(f"batched {batched:.2f} s ({batched / max(len(cells), 1) * 1e3:.3f} ms per cell)")
    if args.no_loop:
        return
    kind, label = t["kind"].copy(), t["label"].copy()
    t.update({k: v.copy() for k, v in before.items()})
    sample = cells[:: args.loop_every]
    start = time.perf_counter()
    for i in sample.tolist():
        field._settle_cell(i)
    per = (time.perf_counter() - start) / max(len(sample), 1) * 1e3
    loop = per * len(cells) / 1e3
    same = np.array_equal(kind[sample], t["kind"][sample]) and np.array_equal(label[sample], t["label"][sample])
    timed = "all" if len(sample) == len(cells) else f"{len(sample)} timed, scaled"
    print(f"loop {loop:.2f} s ({per:.3f} ms per cell, {timed}), {loop / batched:.1f}x; tables equal: {same}")


if __name__ == "__main__":
    main()
