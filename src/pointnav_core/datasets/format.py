"""Episode datasets in Habitat's PointNav format: gzip JSON, one list of episodes per file.

A file holds ``{"episodes": [...], "pointnav_core": {...}}``. Each episode has Habitat's
keys, so ``habitat.datasets.pointnav.PointNavDatasetV1`` reads it (it ignores the extra
top-level key)::

    {"episode_id": "0", "scene_id": "rooms:200",
     "start_position": [x, y, z], "start_rotation": [qx, qy, qz, qw],
     "goals": [{"position": [x, y, z], "radius": 0.5}],
     "info": {"geodesic_distance": 7.31, "floor": 0, "robot_radius": 0.18}}

The floor index and the robot radius the episode was made for live in ``info``, a free-form
dict in Habitat (its episode class takes no other extra keys).

An episode may record its crowd (:attr:`PointNavEpisode.pedestrians`, issue 33): then
``info["pedestrians"]`` holds one object per pedestrian, its start, goal list, its own seed,
radius and speed (:mod:`pointnav_core.datasets.crowd_records`), and an env that plays the
episode places exactly that crowd. Without one the key is absent and the file is as before.

Frames
------
A dataset is stored in pointnav-core's frame (x, y on the floor, z up, a yaw about +z as
the quaternion ``(0, 0, sin(yaw/2), cos(yaw/2))``), so a file round-trips exactly; the
metadata says ``"frame": "z-up"``. :meth:`EpisodeDataset.save` with ``frame="habitat"``
writes Habitat's y-up frame instead (:func:`to_habitat_position`,
:func:`to_habitat_rotation`): ``(x, y, z) -> (x, z, -y)``, and a heading ``yaw`` (0 along
+x) becomes a rotation by ``yaw - pi/2`` about +y (Habitat's agent looks along -z).
:meth:`EpisodeDataset.load` reads either frame back into ours.

Files are written byte-for-byte reproducibly: keys sorted, no whitespace, floats as
Python's shortest round-trip repr, and a gzip header with no file name and mtime 0.
"""

from __future__ import annotations

import gzip
import io
import json
import math
import os
import zlib
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from pointnav_core.crowds.record import PedestrianRecord
from pointnav_core.datasets.crowd_records import records_from_json, records_to_json
from pointnav_core.errors import ArgumentError
from pointnav_core.utils import validation

__all__ = [
    "EpisodeDataset",
    "PointNavEpisode",
    "FORMAT_VERSION",
    "MAX_DATASET_BYTES",
    "from_habitat_position",
    "from_habitat_rotation",
    "to_habitat_position",
    "to_habitat_rotation",
]

#: Default budget (bytes) of a dataset's JSON text after decompression: about 700,000
#: episodes. :meth:`EpisodeDataset.load` takes another as ``max_bytes``.
MAX_DATASET_BYTES = 256 * 1024 * 1024
#: Version of the ``pointnav_core`` metadata block.
FORMAT_VERSION = 1
#: How far a stored quaternion's norm may be from 1, and its tilt from a pure yaw.
_QUAT_TOL = 1e-6


@dataclass(frozen=True)
class PointNavEpisode:
    """One point-goal episode, in pointnav-core's frame (metres, radians, z up).

    Attributes
    ----------
    episode_id : str
        Unique within its dataset.
    scene_id : str
        Which scene (see :mod:`pointnav_core.datasets.scene_sets`).
    floor : int
        Floor index; start and goal are on it.
    start_position : (float, float, float)
        Start ``(x, y, z)`` in metres; z is the floor's height.
    start_rotation : (float, float, float, float)
        Start orientation ``(x, y, z, w)``: a yaw about +z.
    goal_position : (float, float, float)
        Goal ``(x, y, z)`` in metres.
    goal_radius : float or None
        Success distance (m) recorded with the goal (Habitat's ``goals[0].radius``); None
        leaves it to the task's ``goal_tolerance``.
    geodesic_distance : float
        Shortest-path length (m) from start to goal for a disc of ``robot_radius``.
    robot_radius : float
        Radius (m) of the robot the episode was made for.
    pedestrians : tuple of PedestrianRecord or None
        The crowd at the episode's start, one record per pedestrian (start, goals, seed,
        radius, speed; :mod:`pointnav_core.crowds.record`), or None: no recorded crowd.
    """

    episode_id: str
    scene_id: str
    floor: int
    start_position: tuple[float, float, float]
    start_rotation: tuple[float, float, float, float]
    goal_position: tuple[float, float, float]
    goal_radius: float | None
    geodesic_distance: float
    robot_radius: float
    pedestrians: tuple[PedestrianRecord, ...] | None = None

    @property
    def start_xy(self) -> tuple[float, float]:
        """Start ``(x, y)`` in metres."""
        return self.start_position[0], self.start_position[1]

    @property
    def goal_xy(self) -> tuple[float, float]:
        """Goal ``(x, y)`` in metres."""
        return self.goal_position[0], self.goal_position[1]

    @property
    def start_yaw(self) -> float:
        """Start heading (rad) in (-pi, pi], 0 along +x."""
        _, _, qz, qw = self.start_rotation
        return math.atan2(2.0 * qz * qw, qw * qw - qz * qz)

    def to_json(self, frame: str = "z-up") -> dict[str, Any]:
        """The episode as Habitat's JSON dict, in ``frame`` (``"z-up"`` or ``"habitat"``)."""
        start, goal, rotation = self.start_position, self.goal_position, self.start_rotation
        if frame == "habitat":
            start, goal = to_habitat_position(start), to_habitat_position(goal)
            rotation = to_habitat_rotation(self.start_yaw)
        info: dict[str, Any] = {
            "geodesic_distance": self.geodesic_distance,
            "floor": self.floor,
            "robot_radius": self.robot_radius,
        }
        if self.pedestrians is not None:  # absent otherwise: older files stay byte for byte
            info["pedestrians"] = records_to_json(self.pedestrians, frame, self.start_position[2])
        return {
            "episode_id": self.episode_id,
            "scene_id": self.scene_id,
            "start_position": list(start),
            "start_rotation": list(rotation),
            "goals": [{"position": list(goal), "radius": self.goal_radius}],
            "info": info,
        }


def to_habitat_position(xyz: Sequence[float]) -> tuple[float, float, float]:
    """Our ``(x, y, z)`` (z up) as Habitat's ``(x, y, z)`` (y up): ``(x, z, -y)``, metres.

    Examples
    --------
    >>> to_habitat_position((1.0, 2.0, 3.0))
    (1.0, 3.0, -2.0)
    """
    x, y, z = (float(v) for v in xyz)
    return x, z, -y


def from_habitat_position(xyz: Sequence[float]) -> tuple[float, float, float]:
    """Habitat's ``(x, y, z)`` (y up) as ours (z up): the inverse of :func:`to_habitat_position`.

    Examples
    --------
    >>> from_habitat_position((1.0, 3.0, -2.0))
    (1.0, 2.0, 3.0)
    """
    x, y, z = (float(v) for v in xyz)
    return x, -z, y


def to_habitat_rotation(yaw: float) -> tuple[float, float, float, float]:
    """Habitat's start rotation ``(x, y, z, w)`` for our heading ``yaw`` (rad, 0 along +x).

    Habitat's agent looks along its -z, which is our +y: heading ``yaw`` is a rotation by
    ``yaw - pi/2`` about Habitat's +y axis.

    Examples
    --------
    >>> [round(v, 6) for v in to_habitat_rotation(math.pi / 2)]  # facing our +y: identity
    [0.0, 0.0, 0.0, 1.0]
    """
    half = 0.5 * (float(yaw) - 0.5 * math.pi)
    return 0.0, math.sin(half), 0.0, math.cos(half)


def from_habitat_rotation(quat: Sequence[float]) -> float:
    """Our heading (rad, in (-pi, pi]) from Habitat's rotation about +y ``(x, y, z, w)``.

    Examples
    --------
    >>> round(from_habitat_rotation(to_habitat_rotation(0.3)), 12)
    0.3
    """
    _, qy, _, qw = (float(v) for v in quat)
    angle = math.atan2(2.0 * qy * qw, qw * qw - qy * qy) + 0.5 * math.pi
    return math.pi - (math.pi - angle) % (2.0 * math.pi)


# ---------------------------------------------------------------------- validation
class _Where:
    """Names an episode in error messages: ``episode '7' (index 7 of file.json.gz)``."""

    def __init__(self, index: int, raw: Any, source: str) -> None:
        ident = raw.get("episode_id") if isinstance(raw, Mapping) else None
        name = f"episode {ident!r}" if isinstance(ident, str) else "episode"
        self.prefix = f"{name} (index {index}{' of ' + source if source else ''})"

    def error(self, field_name: str, must: str, got: Any) -> ValueError:
        return ArgumentError(f"{self.prefix}: field '{field_name}' must be {must}, got {got!r}")


def _is_number(value: Any) -> bool:
    # bool is an int subclass and a string is not a number: both are rejected.
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _number(
    where: _Where, raw: Mapping[str, Any], key: str, name: str, minimum: float | None = None
) -> float:
    if key not in raw:
        raise where.error(name, "present", "nothing")
    value = raw[key]
    if (
        not _is_number(value)
        or not math.isfinite(value)
        or (minimum is not None and value < minimum)
    ):
        bound = "" if minimum is None else f" >= {minimum}"
        raise where.error(name, f"a finite number{bound}", value)
    return float(value)


def _vector(
    where: _Where, raw: Mapping[str, Any], key: str, name: str, size: int
) -> tuple[float, ...]:
    if key not in raw:
        raise where.error(name, "present", "nothing")
    value = raw[key]
    if (
        not isinstance(value, (list, tuple))
        or len(value) != size
        or not all(_is_number(v) and math.isfinite(v) for v in value)
    ):
        raise where.error(name, f"a list of {size} finite numbers", value)
    return tuple(float(v) for v in value)


def _episode_from_json(raw: Any, index: int, source: str, frame: str) -> PointNavEpisode:
    where = _Where(index, raw, source)
    if not isinstance(raw, Mapping):
        raise where.error("episodes[]", "an object", raw)
    for key in ("episode_id", "scene_id"):
        value = raw.get(key)
        if not isinstance(value, str) or not value:
            raise where.error(key, "a non-empty string", value)
    start = _vector(where, raw, "start_position", "start_position", 3)
    rotation = _vector(where, raw, "start_rotation", "start_rotation", 4)
    goals = raw.get("goals")
    if not isinstance(goals, list) or len(goals) != 1 or not isinstance(goals[0], Mapping):
        raise where.error("goals", "a list of one goal object {position, radius}", goals)
    goal = _vector(where, goals[0], "position", "goals[0].position", 3)
    radius = goals[0].get("radius")
    if radius is not None:
        radius = _number(where, goals[0], "radius", "goals[0].radius", minimum=0.0)
        if radius == 0.0:  # success is a distance below the radius: none at 0 m
            raise where.error("goals[0].radius", "a finite number > 0 or null", radius)
    info = raw.get("info")
    if not isinstance(info, Mapping):
        raise where.error("info", "an object with geodesic_distance, floor and robot_radius", info)
    geodesic = _number(where, info, "geodesic_distance", "info.geodesic_distance", minimum=0.0)
    floor = info.get("floor")
    if isinstance(floor, bool) or not isinstance(floor, int) or floor < 0:
        raise where.error("info.floor", "an integer >= 0", floor)
    robot_radius = _number(where, info, "robot_radius", "info.robot_radius", minimum=0.0)
    crowd = records_from_json(info["pedestrians"], frame, where.error) if "pedestrians" in info else None

    norm = math.sqrt(sum(v * v for v in rotation))
    if abs(norm - 1.0) > _QUAT_TOL:
        raise where.error("start_rotation", "a unit quaternion (x, y, z, w)", list(rotation))
    if frame == "habitat":
        if abs(rotation[0]) > _QUAT_TOL or abs(rotation[2]) > _QUAT_TOL:
            raise where.error(
                "start_rotation", "a rotation about Habitat's +y axis only", list(rotation)
            )
        start, goal = from_habitat_position(start), from_habitat_position(goal)
        half = 0.5 * from_habitat_rotation(rotation)
        rotation = (0.0, 0.0, math.sin(half), math.cos(half))
    elif abs(rotation[0]) > _QUAT_TOL or abs(rotation[1]) > _QUAT_TOL:
        raise where.error(
            "start_rotation", "a yaw about +z (0, 0, sin(yaw/2), cos(yaw/2))", list(rotation)
        )
    return PointNavEpisode(
        episode_id=raw["episode_id"],
        scene_id=raw["scene_id"],
        floor=floor,
        start_position=start,  # type: ignore[arg-type]
        start_rotation=rotation,  # type: ignore[arg-type]
        goal_position=goal,  # type: ignore[arg-type]
        goal_radius=radius,
        geodesic_distance=geodesic,
        robot_radius=robot_radius,
        pedestrians=crowd,
    )


@dataclass(frozen=True)
class EpisodeDataset:
    """An ordered collection of :class:`PointNavEpisode` with unique ids, and metadata.

    Parameters
    ----------
    episodes : sequence of PointNavEpisode
    metadata : dict
        Free-form JSON-able facts about the dataset (generator, parameters, split);
        stored under the file's ``pointnav_core`` key.

    Examples
    --------
    >>> ep = PointNavEpisode("0", "rooms:0", 0, (1.0, 1.0, 0.0), (0.0, 0.0, 0.0, 1.0),
    ...                      (3.0, 1.0, 0.0), 0.5, 2.0, 0.18)
    >>> data = EpisodeDataset([ep])
    >>> EpisodeDataset.from_json(data.to_json()) == data
    True
    """

    episodes: tuple[PointNavEpisode, ...]
    metadata: Mapping[str, Any] = field(default_factory=dict)

    def __init__(
        self, episodes: Iterable[PointNavEpisode], metadata: Mapping[str, Any] | None = None
    ) -> None:
        episodes = tuple(episodes)
        seen: dict[str, int] = {}
        for i, ep in enumerate(episodes):
            if not isinstance(ep, PointNavEpisode):
                raise ArgumentError(f"episodes[{i}] must be a PointNavEpisode, got {ep!r}")
            if ep.episode_id in seen:
                raise ArgumentError(
                    f"episode {ep.episode_id!r} (index {i}): field 'episode_id' must be unique, "
                    f"but index {seen[ep.episode_id]} has it too"
                )
            seen[ep.episode_id] = i
        object.__setattr__(self, "episodes", episodes)
        object.__setattr__(self, "metadata", dict(metadata or {}))

    def __len__(self) -> int:
        return len(self.episodes)

    def __iter__(self) -> Iterator[PointNavEpisode]:
        return iter(self.episodes)

    def __getitem__(self, index: int) -> PointNavEpisode:
        return self.episodes[index]

    @property
    def scene_ids(self) -> list[str]:
        """The distinct scene ids, in order of first appearance."""
        return list(dict.fromkeys(ep.scene_id for ep in self.episodes))

    def to_json(self, frame: str = "z-up") -> dict[str, Any]:
        """The dataset as a JSON-able dict in ``frame`` (``"z-up"``, ours, or ``"habitat"``)."""
        if frame not in ("z-up", "habitat"):
            raise ArgumentError(f"frame must be one of ['z-up', 'habitat'], got {frame!r}")
        meta = {**self.metadata, "format_version": FORMAT_VERSION, "frame": frame}
        return {"episodes": [ep.to_json(frame) for ep in self.episodes], "pointnav_core": meta}

    @classmethod
    def from_json(cls, data: Any, source: str = "") -> EpisodeDataset:
        """Read a dict in either frame (Habitat's y-up when there is no ``pointnav_core``
        metadata). Raises ``ValueError`` naming the episode and the field for bad input."""
        where = f" in {source}" if source else ""
        if not isinstance(data, Mapping) or not isinstance(data.get("episodes"), list):
            raise ArgumentError(f"a dataset must be an object with an 'episodes' list{where}")
        meta = data.get("pointnav_core", {"frame": "habitat"})
        if not isinstance(meta, Mapping):
            raise ArgumentError(f"field 'pointnav_core' must be an object{where}, got {meta!r}")
        frame = meta.get("frame", "z-up")
        if frame not in ("z-up", "habitat"):
            raise ArgumentError(
                f"field 'pointnav_core.frame' must be 'z-up' or 'habitat'{where}, got {frame!r}"
            )
        episodes = [
            _episode_from_json(raw, i, source, frame) for i, raw in enumerate(data["episodes"])
        ]
        metadata = {k: v for k, v in meta.items() if k not in ("format_version", "frame")}
        return cls(episodes, metadata)

    def to_bytes(self, frame: str = "z-up") -> bytes:
        """The gzip file's bytes: sorted keys, compact JSON, gzip mtime 0 (reproducible)."""
        text = json.dumps(
            self.to_json(frame), sort_keys=True, separators=(",", ":"), allow_nan=False
        )
        buffer = io.BytesIO()
        with gzip.GzipFile(filename="", mode="wb", fileobj=buffer, compresslevel=9, mtime=0) as gz:
            gz.write(text.encode("utf-8"))
        return buffer.getvalue()

    def save(self, path: str | os.PathLike[str], frame: str = "z-up") -> None:
        """Write the dataset to ``path`` (``.json.gz``; a ``.json`` path is written plain).

        The file is written whole or not at all (a temporary file renamed over ``path``,
        :func:`pointnav_core.utils.outputs.atomic_writer`): a full disk leaves an existing file as
        it was.
        """
        from pointnav_core.utils.outputs import atomic_writer

        data = self.to_bytes(frame)
        if os.fspath(path).endswith(".json"):
            data = gzip.decompress(data)
        with atomic_writer(path) as fh:
            fh.write(data)

    @classmethod
    def load(
        cls, path: str | os.PathLike[str], max_bytes: int | None = None
    ) -> EpisodeDataset:
        """Read a ``.json.gz`` (or plain ``.json``) dataset; see :meth:`from_json`.

        Parameters
        ----------
        path : str or os.PathLike
        max_bytes : int, optional
            Budget of the JSON text, in bytes, after decompression (default
            :data:`MAX_DATASET_BYTES`): a gzip bomb is refused once it inflates past it.

        Raises
        ------
        ValueError
            For a file that is not gzip or JSON, is truncated or corrupt, or is over budget;
            the message names the file.
        """
        where = os.fspath(path)
        limit = MAX_DATASET_BYTES if max_bytes is None else validation.integer("max_bytes", max_bytes, minimum=1)
        if os.path.getsize(where) > limit:
            raise ArgumentError(f"{where} is over the dataset budget of {limit} bytes (max_bytes)")
        with open(where, "rb") as fh:
            raw = fh.read()
        if raw[:2] == b"\x1f\x8b":
            raw = _gunzip(raw, limit, where)
        try:
            data = json.loads(raw.decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError) as err:
            raise ArgumentError(f"{where} is not a JSON dataset: {err}") from None
        return cls.from_json(data, source=os.path.basename(where))


def _gunzip(raw: bytes, limit: int, where: str) -> bytes:
    """Inflate gzip ``raw`` (one or more members), refusing more than ``limit`` bytes out."""
    out = bytearray()
    try:
        while raw:
            inflate = zlib.decompressobj(16 + zlib.MAX_WBITS)
            while raw and not inflate.eof:
                # At most one byte past the budget: enough to know it is over.
                out += inflate.decompress(raw, limit + 1 - len(out))
                if len(out) > limit:
                    raise ArgumentError(
                        f"{where} inflates past the dataset budget of {limit} bytes (max_bytes)"
                    )
                raw = inflate.unconsumed_tail
            if not inflate.eof:
                raise ArgumentError(f"{where} is a truncated gzip file")
            raw = inflate.unused_data
    except zlib.error as err:
        raise ArgumentError(f"{where} is a corrupt gzip file: {err}") from None
    return bytes(out)
