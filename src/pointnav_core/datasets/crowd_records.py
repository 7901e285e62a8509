"""An episode's recorded crowd in a dataset file: ``info["pedestrians"]``, one object per
pedestrian (:class:`~pointnav_core.crowds.record.PedestrianRecord`)::

    {"start": [x, y], "goals": [[x, y], ...], "loop": false, "seed": 8190317,
     "radius": 0.27, "speed": 0.81}

Points are ``[x, y]`` (m) in pointnav-core's frame; in Habitat's frame (``frame="habitat"``)
they are 3-D like the episode's positions, ``[x, h, -y]`` with ``h`` the episode's floor
height (:func:`~pointnav_core.datasets.format.to_habitat_position`). Habitat's episode keeps
``info`` as a free-form dict, so it reads such a file unchanged.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from pointnav_core.crowds.record import PedestrianRecord, make_record
from pointnav_core.utils import validation

__all__ = ["KEYS", "records_from_json", "records_to_json"]

#: The keys of one pedestrian's object, all required.
KEYS = ("start", "goals", "loop", "seed", "radius", "speed")


def records_to_json(records: Sequence[PedestrianRecord], frame: str, height: float) -> list[dict[str, Any]]:
    """``records`` as JSON objects in ``frame`` (``"z-up"`` or ``"habitat"``; ``height`` (m)
    is the floor's, the Habitat points' up coordinate)."""

    def point(xy: Sequence[float]) -> list[float]:
        # Habitat's (x, y, z) is ours (x, z, -y): the same map as the episode's positions.
        return [float(xy[0]), float(xy[1])] if frame != "habitat" else [float(xy[0]), float(height), -float(xy[1])]

    return [
        {
            "start": point(r.start),
            "goals": [point(g) for g in r.goals],
            "loop": r.loop,
            "seed": r.seed,
            "radius": r.radius,
            "speed": r.speed,
        }
        for r in records
    ]


def records_from_json(
    raw: Any, frame: str, error: Callable[[str, str, Any], Exception]
) -> tuple[PedestrianRecord, ...]:
    """The records of ``info["pedestrians"]`` ``raw`` written in ``frame``, checked;
    ``error(field, must, got)`` builds the exception for the first bad field (named
    ``info.pedestrians[i].seed`` and so on)."""
    if not isinstance(raw, list):
        raise error("info.pedestrians", "a list of pedestrian objects", raw)
    size = 3 if frame == "habitat" else 2
    records = []
    for i, item in enumerate(raw):
        name = f"info.pedestrians[{i}]"
        if not isinstance(item, Mapping) or set(item) != set(KEYS):
            raise error(name, f"an object with exactly the keys {list(KEYS)}", item)

        def point(field: str, value: Any) -> Any:
            if not isinstance(value, (list, tuple)) or len(value) != size:
                raise error(field, f"a list of {size} finite numbers", value)
            if size == 2:
                return value
            if not all(validation.is_real(v) and math.isfinite(v) for v in value):
                raise error(field, "a list of 3 finite numbers", value)
            return [value[0], -value[2]]  # Habitat's (x, h, -y) back to our (x, y)

        goals = item["goals"]
        if isinstance(goals, list):
            goals = [point(f"{name}.goals[{k}]", g) for k, g in enumerate(goals)]
        start = point(f"{name}.start", item["start"])
        records.append(make_record(name, start, goals, item["loop"], item["seed"], item["radius"], item["speed"], error))
    return tuple(records)
