"""ProcTHOR houses and HouseExpo plans: exact polygon floors, door holes, objects, bad files.

Reference lengths are worked out by hand for a point robot (shortest paths bend at obstacle
corners), so they do not depend on the library's planner beyond what it must compute.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from shapely.geometry import Polygon

from pointnav_core.datasets import load_scene, scene_set
from pointnav_core.scenes import Scene

DATA = Path(__file__).parent / "data"


def thor(x: float, z: float, y: float = 0.0) -> dict:
    return {"x": x, "y": y, "z": z}


def wall(room: int, a: tuple[float, float], b: tuple[float, float]) -> dict:
    """A THOR wall from base point a to b, 2.5 m high (its id lists the ends as THOR does)."""
    return {
        "id": f"wall|{room}|{a[0]:.2f}|{a[1]:.2f}|{b[0]:.2f}|{b[1]:.2f}",
        "roomId": f"room|{room}",
        "polygon": [thor(*a), thor(*b), thor(*a, y=2.5), thor(*b, y=2.5)],
    }


def two_room_house() -> dict:
    """Rooms [0, 4] x [0, 3] and [4, 8] x [0, 3] (THOR x, z), a 1 m door in the shared wall
    at z in [1, 2], measured from wall0's first base point (4, 0)."""
    corners = {1: [(0, 0), (4, 0), (4, 3), (0, 3)], 2: [(4, 0), (8, 0), (8, 3), (4, 3)]}
    rooms = [{"id": f"room|{r}", "floorPolygon": [thor(x, z) for x, z in c]} for r, c in corners.items()]
    walls = []
    for r, c in corners.items():
        walls += [wall(r, c[i], c[(i + 1) % 4]) for i in range(4)]
    shared = wall(1, (4, 0), (4, 3))
    door = {"id": "door|1|2", "wall0": shared["id"], "wall1": "wall|2|4.00|3.00|4.00|0.00",
            "holePolygon": [thor(1.0, 0.0), thor(2.0, 2.0)], "openable": True, "openness": 1}
    walls = [w for w in walls if w["id"] != shared["id"]] + [shared]
    objects = [
        {"id": "Table|1", "assetId": "Table_1", "position": thor(2.0, 1.5, 0.4), "rotation": thor(0, 0)},
        {"id": "Sofa|2", "assetId": "Sofa_1", "position": thor(6.0, 1.5, 0.4), "rotation": {"x": 0, "y": 90, "z": 0}},
    ]
    return {"rooms": rooms, "walls": walls, "doors": [door], "objects": objects, "metadata": {"schema": "1.0.0"}}


@pytest.fixture
def house(tmp_path) -> Path:
    path = tmp_path / "house.json"
    path.write_text(json.dumps(two_room_house()))
    return path


def test_procthor_rooms_are_the_floor_walls_block_and_the_door_is_open(house):
    scene = Scene.from_procthor(house)
    tmap = scene.floors[0]
    outline = tmap.geometry.outline
    assert outline.area == pytest.approx(24.0) and outline.bounds == (0.0, 0.0, 8.0, 3.0)
    assert scene.is_usable(0, (4.0, 1.5))  # in the door
    assert not scene.is_usable(0, (4.0, 0.5)) and not scene.is_usable(0, (4.0, 2.5))  # the wall
    assert not scene.is_usable(0, (9.0, 1.5))  # off the floor
    # Straight through the door, and around the door's lower jamb (slab x in [3.95, 4.05],
    # z up to 1.0) for a point robot: two legs to the jamb's corners and the slab's width.
    assert scene.geodesic_distance(0, (2, 1.5), (6, 1.5)) == pytest.approx(4.0, abs=1e-9)
    # (The planner keeps about 1e-6 m off corners, hence the tolerance.)
    around = 2 * math.hypot(1.95, 0.7) + 0.1
    assert scene.geodesic_distance(0, (2, 0.3), (6, 0.3)) == pytest.approx(around, abs=1e-5)


def test_procthor_objects_block_only_with_their_footprints(house):
    assert Scene.from_procthor(house).is_usable(0, (2.0, 1.5))
    sizes = {"Table_1": (1.0, 1.0), "Sofa_1": (2.0, 0.5)}
    scene = Scene.from_procthor(house, object_sizes=sizes)
    assert not scene.is_usable(0, (2.0, 1.5)) and scene.is_usable(0, (2.6, 1.5))
    # The sofa (2 m along its x) turned 90 degrees: now 2 m along world y, 0.5 m along x.
    assert not scene.is_usable(0, (6.0, 2.3)) and scene.is_usable(0, (6.5, 1.5))
    with pytest.raises(ValueError, match=r"house\.json.*objects\[1\].*'Sofa_1'"):
        Scene.from_procthor(house, object_sizes={"Table_1": (1.0, 1.0)})


def test_houseexpo_verts_are_the_exact_outline(tmp_path):
    plan = {"id": "L", "room_num": 2, "bbox": {"min": [0, 0], "max": [4, 4]},
            "verts": [[0, 0], [4, 0], [4, 1], [1, 1], [1, 4], [0, 4]],
            "room_category": {"hallway": [[0, 0, 4, 1]], "bedroom": [[0, 1, 1, 4]]}}
    path = tmp_path / "L.json"
    path.write_text(json.dumps(plan))
    scene = Scene.from_houseexpo(path, resolution=0.1)
    assert scene.floors[0].geometry.outline.area == pytest.approx(7.0)
    assert not scene.is_usable(0, (2.0, 2.0))
    # Around the inner corner (1, 1), for a point robot.
    assert scene.geodesic_distance(0, (3.5, 0.5), (0.5, 3.5)) == pytest.approx(2 * math.hypot(2.5, 0.5), abs=1e-5)
    assert load_scene(f"houseexpo:{path}").floors[0].geometry.outline.area == pytest.approx(7.0)


def test_plain_json_paths_are_told_apart_by_their_keys(house, tmp_path):
    assert load_scene(str(house)).floors[0].geometry.outline.area == pytest.approx(24.0)
    other = tmp_path / "other.json"
    other.write_text('{"hello": 1}')
    with pytest.raises(ValueError, match=r"other\.json.*neither a ProcTHOR house .* nor a HouseExpo plan"):
        load_scene(str(other))
    # In a folder too: a .json that is no floor plan is named, not skipped.
    with pytest.raises(ValueError, match=r"other\.json.*neither a ProcTHOR house"):
        scene_set(str(tmp_path))


def broken(field: str) -> dict:
    doc = two_room_house()
    if field == "no rooms":
        del doc["rooms"]
    elif field == "empty rooms":
        doc["rooms"] = []
    elif field == "bad door wall":
        doc["doors"][0]["wall0"] = "wall|9|0|0|0|0"
    elif field == "room without floorPolygon":
        del doc["rooms"][1]["floorPolygon"]
    elif field == "separate rooms":
        for p in doc["rooms"][1]["floorPolygon"]:
            p["x"] += 10
    return doc


@pytest.mark.parametrize(
    "field, message",
    [
        ("no rooms", r"bad\.json'?: rooms must be a non-empty list"),
        ("empty rooms", r"bad\.json'?: rooms must be a non-empty list"),
        ("bad door wall", r"bad\.json'?: doors\[0\]\.wall0 must name a wall"),
        ("room without floorPolygon", r"bad\.json'?: rooms\[1\]\.floorPolygon"),
        ("separate rooms", r"bad\.json'?: rooms: the floor is 2 separate pieces"),
    ],
)
def test_bad_procthor_files_name_the_file_and_the_field(tmp_path, field, message):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(broken(field)))
    with pytest.raises(ValueError, match=message):
        Scene.from_procthor(path)
    with pytest.raises(ValueError, match=message):  # and nothing half built is cached
        load_scene(f"procthor:{path}")
    path.write_text(json.dumps(two_room_house()))
    assert load_scene(f"procthor:{path}").floors[0].geometry.outline.area == pytest.approx(24.0)


def test_bad_houseexpo_and_json_files_are_refused(tmp_path):
    path = tmp_path / "bad.json"
    path.write_text('{"verts": [[0, 0], [1, 0]]}')
    with pytest.raises(ValueError, match=r"bad\.json'?: verts must have at least 3 points"):
        Scene.from_houseexpo(path)
    path.write_text('{"verts": [[0, 0], [1, 1], [1, 0], [0, 1]]}')  # a bow tie
    with pytest.raises(ValueError, match=r"bad\.json'?: verts is not a valid polygon"):
        Scene.from_houseexpo(path)
    path.write_text('{"verts": [[0, 0], [1')
    with pytest.raises(ValueError, match=r"bad\.json'? is not valid JSON"):
        Scene.from_houseexpo(path)


def test_a_real_procthor_house_gives_its_rooms_doors_and_open_sides():
    path = DATA / "procthor" / "procthor_train_1.json"
    doc = json.loads(path.read_text())
    rooms = [Polygon([(p["x"], p["z"]) for p in r["floorPolygon"]]) for r in doc["rooms"]]
    walls = {w["id"]: [(p["x"], p["z"]) for p in w["polygon"] if p["y"] == 0] for w in doc["walls"]}
    scene = Scene.from_procthor(path, resolution=0.1)
    assert scene.floors[0].geometry.outline.area == pytest.approx(sum(r.area for r in rooms))
    for door in doc["doors"]:  # the middle of each hole, along wall0 from its first base point
        (x0, z0), (x1, z1) = walls[door["wall0"]]
        s = (door["holePolygon"][0]["x"] + door["holePolygon"][1]["x"]) / 2
        length = math.hypot(x1 - x0, z1 - z0)
        middle = (x0 + (x1 - x0) * s / length, z0 + (z1 - z0) * s / length)
        assert scene.is_usable(0, middle), door["id"]
    for wall_id, (a, b) in walls.items():
        middle = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)
        doored = any(d["wall0"] == wall_id or d["wall1"] == wall_id for d in doc["doors"])
        empty = any(w["id"] == wall_id and w.get("empty") for w in doc["walls"])
        if empty:  # an open side between two rooms of one space
            assert scene.is_usable(0, middle), wall_id
        elif not doored:
            assert not scene.is_usable(0, middle), wall_id
    # Every room reaches every other for the default robot, through doors and open sides.
    inside = [r.buffer(-0.3).representative_point() for r in rooms]
    for p in inside[1:]:
        assert math.isfinite(scene.geodesic_distance(0, (inside[0].x, inside[0].y), (p.x, p.y), robot=0.18))
