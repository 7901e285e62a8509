"""Real maps committed as test data, read with their format's rules written out here."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image

from pointnav_core.floor.maps import FREE, OBSTACLE, VOID
from pointnav_core.scenes import Scene

DATA = Path(__file__).parent / "data"

#: A MovingAI map of 6 x 4 m at 0.5 m per character: one room with a pillar (the
#: evaluation and training tests' small scene).
PILLAR_ROOM = """type octile
height 8
width 12
map
@@@@@@@@@@@@
@..........@
@..........@
@....@@....@
@....@@....@
@..........@
@..........@
@@@@@@@@@@@@
"""


def bookstore_codes() -> np.ndarray:
    """The bookstore map's cell codes (``tests/data/bookstore``), row 0 at the bottom:
    map_server's trinary rule (occupancy ``(255 - p) / 255``; free below 0.196, occupied
    above 0.65, unknown as VOID)."""
    img = np.asarray(Image.open(DATA / "bookstore" / "map.pgm")).astype(np.float64)
    occ = (255.0 - img) / 255.0
    codes = np.full(img.shape, VOID, np.uint8)
    codes[occ > 0.65] = OBSTACLE
    codes[occ < 0.196] = FREE
    return np.ascontiguousarray(codes[::-1])  # image row 0 is the top


def bookstore(rows: slice = slice(None), cols: slice = slice(None)) -> Scene:
    """The bookstore map at 0.05 m, origin (-10, -10), or the crop ``[rows, cols]`` of it
    (cells, row 0 at the bottom) with the origin of its first cell."""
    codes = bookstore_codes()
    r0, c0 = rows.start or 0, cols.start or 0
    return Scene.from_array(codes[rows, cols], 0.05, origin=(-10.0 + 0.05 * c0, -10.0 + 0.05 * r0))


def pillar_room_dataset(folder: Any, episodes: int) -> Any:
    """Write ``PILLAR_ROOM`` as ``folder/room.map`` and an ``episodes``-episode dataset on it
    as ``folder/val.json.gz`` (``pointnav dataset generate``, geodesics up to 4 m); its path.

    It runs from inside the folder, so that the scene ids (``movingai:./room.map``), and with
    them the episodes drawn, do not depend on where the folder is."""
    import os

    from pointnav_core.cli import main

    folder = Path(folder)
    (folder / "room.map").write_text(PILLAR_ROOM)
    out = folder / "val.json.gz"
    args = ["dataset", "generate", "--scenes", ".", "--split", "train", "--episodes", str(episodes),
            "--max-geodesic", "4", "--out", str(out), "--quiet"]
    here = os.getcwd()
    os.chdir(folder)
    try:
        assert main(args) == 0
    finally:
        os.chdir(here)
    return out
