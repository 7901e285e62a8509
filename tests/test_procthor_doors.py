"""ProcTHOR doors open, as stored (``openness`` 0 closed) or closed: ``doors=``.

The doorways' midpoints are worked out in the test from the house file's own numbers (the
wall's base points and the door's ``holePolygon`` span), and the expected state of each
door from its ``openness`` as ProcTHOR writes it (1 open, 0 closed; door frames carry none).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
import shapely
from shapely.geometry import Point

from pointnav_core.floorplans.files import read_procthor
from pointnav_core.scenes import Scene

HOUSE = Path(__file__).parent / "data" / "procthor" / "procthor_train_1.json"


def thor(x: float, z: float, y: float = 0.0) -> dict:
    return {"x": x, "y": y, "z": z}


def three_rooms() -> dict:
    """Rooms [0, 4], [4, 8] and [8, 12] (THOR x) by [0, 3] (z); a closed door (openness 0)
    at z in [1, 2] of the wall x = 4, a door frame (no openness) at z in [1, 2] of x = 8."""
    rooms = [{"id": f"room|{k}", "floorPolygon": [thor(x, z) for x, z in
                                                  [(4 * k, 0), (4 * k + 4, 0), (4 * k + 4, 3), (4 * k, 3)]]}
             for k in range(3)]
    walls = [{"id": f"wall|{x}", "polygon": [thor(x, 0), thor(x, 3), thor(x, 0, 2.5), thor(x, 3, 2.5)]}
             for x in (0, 4, 8, 12)]
    walls += [{"id": f"wall|z{z}", "polygon": [thor(0, z), thor(12, z), thor(0, z, 2.5), thor(12, z, 2.5)]}
              for z in (0, 3)]
    hole = [thor(1.0, 0.0), thor(2.0, 2.1)]
    doors = [{"id": "door|0|1", "wall0": "wall|4", "holePolygon": hole, "openable": True, "openness": 0},
             {"id": "door|1|2", "wall0": "wall|8", "holePolygon": hole, "assetId": "Doorframe_1"}]
    return {"rooms": rooms, "walls": walls, "doors": doors}


@pytest.fixture
def house(tmp_path) -> Path:
    path = tmp_path / "house.json"
    path.write_text(json.dumps(three_rooms()))
    return path


@pytest.mark.parametrize(("doors", "first", "second"), [
    ("open", True, True), ("as_stored", False, True), ("closed", False, False),
])
def test_doors_open_or_fill_their_walls_holes(house, doors, first, second):
    scene = Scene.from_procthor(house, resolution=0.1, doors=doors)
    # The doorways' middles (4, 1.5) and (8, 1.5), on the wall lines.
    assert scene.is_usable(0, (4.0, 1.5)) is first and scene.is_usable(0, (8.0, 1.5)) is second
    # Room 0 to room 1 straight through the first door (4 m), or not at all.
    d = scene.geodesic_distance(0, (2.0, 1.5), (6.0, 1.5))
    assert d == pytest.approx(4.0, abs=1e-9) if first else d == math.inf
    # A closed door leaves the wall whole: 0.1 m thick over z in [0.1, 2.9], less the
    # 1 m hole of an open door.
    wall = shapely.union_all(read_procthor(house, doors=doors).obstacles).intersection(shapely.box(3.9, 0.1, 4.1, 2.9))
    assert wall.area == pytest.approx(0.1 * (1.8 if first else 2.8), abs=1e-9)


def doorway_middles(doc: dict) -> dict[str, tuple[float, float]]:
    """Each door's middle (world x, y = THOR x, z): its hole's span along wall0 from the
    wall's first base point."""
    bases = {w["id"]: [(p["x"], p["z"]) for p in w["polygon"] if p["y"] == 0][:2] for w in doc["walls"]}
    out = {}
    for door in doc["doors"]:
        (x0, z0), (x1, z1) = bases[door["wall0"]]
        length = math.hypot(x1 - x0, z1 - z0)
        s = (door["holePolygon"][0]["x"] + door["holePolygon"][1]["x"]) / 2
        out[door["id"]] = (x0 + (x1 - x0) * s / length, z0 + (z1 - z0) * s / length)
    return out


@pytest.mark.parametrize("doors", ["open", "as_stored", "closed"])
def test_the_shipped_house_closes_its_outside_door_as_stored(doors):
    doc = json.loads(HOUSE.read_text())
    middles = doorway_middles(doc)
    stored_closed = {d["id"] for d in doc["doors"] if d.get("openness", 1) == 0}
    assert stored_closed == {"door|1|3"}  # ProcTHOR's door to the outside
    walls = shapely.union_all(read_procthor(HOUSE, doors=doors).obstacles)
    blocked = {k for k, xy in middles.items() if walls.intersects(Point(xy))}
    want = {"open": set(), "as_stored": stored_closed, "closed": set(middles)}[doors]
    assert blocked == want


@pytest.mark.parametrize("doors", ["ajar", "", None, True, 1])
def test_bad_doors_are_refused(house, doors):
    with pytest.raises(ValueError, match=r"doors must be one of 'open', 'as_stored', 'closed'"):
        Scene.from_procthor(house, doors=doors)


@pytest.mark.parametrize("openness", [2, -0.5, "0", True, None])
def test_a_bad_openness_is_named(tmp_path, openness):
    doc = three_rooms()
    doc["doors"][0]["openness"] = openness
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(ValueError, match=r"bad\.json.*doors\[0\]\.openness must be a number in \[0, 1\]"):
        read_procthor(path, doors="as_stored")
    read_procthor(path)  # "open" does not read it
