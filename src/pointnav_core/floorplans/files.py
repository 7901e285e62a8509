"""Floor plans from files: ProcTHOR houses and HouseExpo plans, as exact polygons.

Both readers return a :class:`~pointnav_core.floorplans.FloorPlan` (an outline and obstacle
polygons in metres), which :meth:`Scene.from_polygons` rasterises while keeping the polygons
as the floor's exact collision geometry.

* **ProcTHOR** (``house.json`` of ai2thor / procthor, schema 1.0): the floor is the union of
  the rooms' ``floorPolygon`` (their ``x`` and ``z``; THOR's y is up, so THOR ``(x, z)`` is
  world ``(x, y)``, the same picture seen from above). Each wall (its two base points,
  ``y = 0``) becomes a ``wall_thickness`` slab centred on it, except ``empty`` walls (the
  open side between two rooms of one space), and each door's ``holePolygon`` (``x`` from
  wall0's first base point along the wall) is cut out of the walls, unless ``doors`` closes
  it (ProcTHOR's ``openness``: 1 open, 0 closed); windows are above the
  floor and cut nothing. Objects carry no size in the house file, so they become obstacles only when
  ``object_sizes`` gives their footprint: ``assetId -> (size_x, size_z)`` metres, turned by
  their y rotation (degrees, clockwise seen from above, as Unity turns).
* **HouseExpo** (``<id>.json``): ``verts`` is the outline of the free space in metres (the
  walls are its boundary); ``bbox`` and ``room_category`` (room boxes) are not geometry the
  robot collides with and are only checked for shape.

A file that is not what the reader expects raises ``ValueError`` naming the file and the field.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from typing import Any

import shapely
from shapely import affinity
from shapely.geometry import LineString, Polygon, box

from pointnav_core.errors import ArgumentError
from pointnav_core.floorplans import FloorPlan
from pointnav_core.utils import validation

__all__ = ["DOOR_MODES", "read_houseexpo", "read_procthor", "sniff_plan_format"]

#: ``doors=`` of :func:`read_procthor`: every door open (a hole in its wall), each as the
#: file stores it (closed where its ``openness`` is 0), or every door closed (no holes).
DOOR_MODES = ("open", "as_stored", "closed")


def _load(path: str | os.PathLike[str]) -> tuple[dict[str, Any], str]:
    where = repr(os.fspath(path))
    with open(path, encoding="utf-8") as file:
        try:
            doc = json.load(file)
        except json.JSONDecodeError as exc:
            raise ArgumentError(f"{where} is not valid JSON: {exc}") from None
    if not isinstance(doc, dict):
        raise ArgumentError(f"{where} must hold a JSON object, got {type(doc).__name__}")
    return doc, where


def sniff_plan_format(path: str | os.PathLike[str]) -> str:
    """``"procthor"`` or ``"houseexpo"`` for a JSON file, by its top-level keys (a house's
    ``rooms``, ``walls`` or ``doors``; a plan's ``verts``); ``ValueError`` naming the file
    otherwise."""
    doc, where = _load(path)
    if "verts" in doc:
        return "houseexpo"
    if {"rooms", "walls", "doors"} & doc.keys():
        return "procthor"
    raise ArgumentError(
        f"{where} is neither a ProcTHOR house (rooms, walls, doors) nor a HouseExpo plan (verts)"
    )


def _xz(points: Any, where: str) -> list[tuple[float, float]]:
    """THOR points ``[{x, y, z}, ...]`` as world ``(x, z)`` pairs."""
    if not isinstance(points, list) or not all(isinstance(p, dict) for p in points):
        raise ArgumentError(f"{where} must be a list of {{x, y, z}} points, got {points!r:.80}")
    out = []
    for p in points:
        x, z = p.get("x"), p.get("z")
        if not (validation.is_real(x) and validation.is_real(z) and math.isfinite(x) and math.isfinite(z)):
            raise ArgumentError(f"{where} has a point without finite x and z: {p!r}")
        out.append((float(x), float(z)))
    return out


def _polygon(points: list[tuple[float, float]], where: str) -> Polygon:
    if len(points) < 3:
        raise ArgumentError(f"{where} must have at least 3 points, got {len(points)}")
    poly = Polygon(points)
    if poly.is_empty or poly.area <= 0 or not poly.is_valid:
        reason = shapely.is_valid_reason(poly) if not poly.is_valid else "zero area"
        raise ArgumentError(f"{where} is not a valid polygon: {reason}")
    return poly


def _outline(parts: Sequence[Polygon], where: str) -> Polygon:
    union = shapely.unary_union(list(parts))
    if not isinstance(union, Polygon):
        raise ArgumentError(f"{where}: the floor is {len(shapely.get_parts(union))} separate pieces; one is expected")
    return union


def _walls(doc: dict[str, Any], where: str, thickness: float) -> tuple[dict[str, LineString], Any]:
    walls = doc.get("walls")
    if not isinstance(walls, list):
        raise ArgumentError(f"{where}: walls must be a list, got {walls!r:.80}")
    bases: dict[str, LineString] = {}
    empty: set[str] = set()
    for i, wall in enumerate(walls):
        field = f"{where}: walls[{i}].polygon"
        if not isinstance(wall, dict) or not isinstance(wall.get("id"), str):
            raise ArgumentError(f"{where}: walls[{i}] must be an object with an id, got {wall!r:.80}")
        points = _xz(wall.get("polygon"), field)
        heights = [p.get("y", 0) for p in wall["polygon"]]
        base = [pt for pt, h in zip(points, heights) if h == min(heights)]
        if len(base) < 2 or base[0] == base[1]:
            raise ArgumentError(f"{field} must have two distinct points at its lowest y")
        bases[wall["id"]] = LineString(base[:2])
        if wall.get("empty") is True:  # an open side between two rooms: no wall is built
            empty.add(wall["id"])
    slabs = [line.buffer(thickness / 2, cap_style="square") for k, line in bases.items() if k not in empty]
    return bases, shapely.unary_union(slabs)


def _is_closed(door: dict[str, Any], field: str, mode: str) -> bool:
    """Whether ``door`` fills its wall's hole under ``mode`` (one of :data:`DOOR_MODES`).

    ProcTHOR writes ``openness`` 1 (open) or 0 (closed: its doors to the outside) on doors
    with a leaf, and nothing on door frames (always open); THOR's openness is in [0, 1],
    and only 0 closes the doorway (a leaf ajar leaves a gap).
    """
    if mode != "as_stored":
        return mode == "closed"
    openness = door.get("openness", 1)
    if not (validation.is_real(openness) and 0.0 <= openness <= 1.0):
        raise ArgumentError(f"{field}.openness must be a number in [0, 1], got {openness!r}")
    return openness == 0


def _door_holes(doc: dict[str, Any], where: str, bases: Mapping[str, LineString], thickness: float,
                mode: str) -> list[Polygon]:
    doors = doc.get("doors", [])
    if not isinstance(doors, list):
        raise ArgumentError(f"{where}: doors must be a list, got {doors!r:.80}")
    holes = []
    for i, door in enumerate(doors):
        field = f"{where}: doors[{i}]"
        wall = door.get("wall0") if isinstance(door, dict) else None
        if wall not in bases:
            raise ArgumentError(f"{field}.wall0 must name a wall of walls, got {wall!r}")
        if _is_closed(door, field, mode):  # its hole stays filled (the door's file is still checked)
            continue
        span = [x for x, _ in _xz(door.get("holePolygon"), f"{field}.holePolygon")]
        if len(span) < 2:
            raise ArgumentError(f"{field}.holePolygon must have two corners")
        line = bases[wall]
        (x0, y0), (x1, y1) = line.coords[0], line.coords[-1]
        ux, uy = (x1 - x0) / line.length, (y1 - y0) / line.length
        lo, hi = min(span), max(span)
        ends = [(x0 + ux * s, y0 + uy * s) for s in (lo, hi)]
        # Wider than the wall across it, so the cut goes through the whole slab.
        holes.append(LineString(ends).buffer(thickness, cap_style="flat"))
    return holes


def _objects(doc: dict[str, Any], where: str, sizes: Mapping[str, Sequence[float]]) -> list[Polygon]:
    out = []
    for i, obj in enumerate(doc.get("objects", [])):
        field = f"{where}: objects[{i}]"
        asset = obj.get("assetId") if isinstance(obj, dict) else None
        if asset not in sizes:
            raise ArgumentError(f"{field}: object_sizes has no footprint for assetId {asset!r}")
        (cx, cz), = _xz([obj.get("position")], f"{field}.position")
        sx, sz = validation.vector(f"object_sizes[{asset!r}]", sizes[asset], sizes=(2,))
        yaw = (obj.get("rotation") or {}).get("y", 0.0)
        if not validation.is_real(yaw):
            raise ArgumentError(f"{field}.rotation.y must be a number (degrees), got {yaw!r}")
        rect = box(cx - sx / 2, cz - sz / 2, cx + sx / 2, cz + sz / 2)
        out.append(affinity.rotate(rect, -float(yaw), origin=(cx, cz)))
    return out


def read_procthor(
    path: str | os.PathLike[str],
    wall_thickness: float = 0.1,
    object_sizes: Mapping[str, Sequence[float]] | None = None,
    doors: str = "open",
) -> FloorPlan:
    """The floor plan of a ProcTHOR ``house.json`` (see the module notes).

    Parameters
    ----------
    path : str or os.PathLike
    wall_thickness : float
        Thickness (m) of the slab each wall becomes, > 0; THOR's walls are planes.
    object_sizes : mapping, optional
        ``assetId -> (size_x, size_z)`` in metres; with it every top-level object is an
        obstacle (an object without an entry is an error). Without it objects are ignored.
    doors : {"open", "as_stored", "closed"}
        ``"open"`` (default): every door is a hole in its wall. ``"as_stored"``: a door
        whose ``openness`` is 0 (ProcTHOR's doors to the outside) leaves its wall whole; a
        door without ``openness`` (a door frame) is open. ``"closed"``: every wall is
        whole, frames included.

    Raises
    ------
    ValueError
        Naming ``doors`` for another value, and the file and field for a door whose
        ``openness`` is not a number in [0, 1] (with ``"as_stored"``).
    """
    if not isinstance(doors, str) or doors not in DOOR_MODES:
        raise ArgumentError(f"doors must be one of {', '.join(map(repr, DOOR_MODES))}, got {doors!r}")
    thickness = validation.real("wall_thickness", wall_thickness, minimum=0.0, strict=True)
    doc, where = _load(path)
    rooms = doc.get("rooms")
    if not isinstance(rooms, list) or not rooms:
        raise ArgumentError(f"{where}: rooms must be a non-empty list of rooms with a floorPolygon, got {rooms!r:.80}")
    floors = []
    for i, room in enumerate(rooms):
        field = f"{where}: rooms[{i}].floorPolygon"
        floors.append(_polygon(_xz(room.get("floorPolygon") if isinstance(room, dict) else None, field), field))
    outline = _outline(floors, f"{where}: rooms")
    bases, walls = _walls(doc, where, thickness)
    holes = _door_holes(doc, where, bases, thickness, doors)
    if holes:
        walls = walls.difference(shapely.unary_union(holes))
    obstacles = [p for p in shapely.get_parts(walls) if p.area > 0]
    if object_sizes is not None:
        obstacles += _objects(doc, where, object_sizes)
    return FloorPlan(outline=outline, obstacles=obstacles)


def read_houseexpo(path: str | os.PathLike[str]) -> FloorPlan:
    """The floor plan of a HouseExpo ``<id>.json``: ``verts`` (m) as the outline, no obstacles."""
    doc, where = _load(path)
    verts = doc.get("verts")
    if not isinstance(verts, list) or not all(isinstance(v, list) and len(v) == 2 for v in verts):
        raise ArgumentError(f"{where}: verts must be a list of [x, y] points in metres, got {verts!r:.80}")
    points = []
    for v in verts:
        if not all(validation.is_real(c) and math.isfinite(c) for c in v):
            raise ArgumentError(f"{where}: verts has a point that is not two finite numbers: {v!r}")
        points.append((float(v[0]), float(v[1])))
    rooms = doc.get("room_category", {})
    if not isinstance(rooms, dict) or not all(
        isinstance(b, list) and all(isinstance(r, list) and len(r) == 4 for r in b) for b in rooms.values()
    ):
        raise ArgumentError(f"{where}: room_category must map a category to [xmin, ymin, xmax, ymax] boxes")
    return FloorPlan(outline=_polygon(points, f"{where}: verts"))
