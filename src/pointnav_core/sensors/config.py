"""Sensors by name: the ``sensors`` argument of the environments.

``sensors`` maps a sensor name to the keyword arguments of its class (or to None, or an
empty dict, for its defaults), or to a ready term:

>>> terms = make_sensors({"scan": {"n_rays": 8}, "local_map": None})
>>> [type(t).__name__ for t in terms], terms[0].size
(['RangeScan', 'LocalMap'], 8)

The terms come in the fixed order of :data:`SENSOR_ORDER` whatever the order of the dict,
so the flat observation's layout depends only on which sensors are on: OmniGibson's eight
``low_dim`` values, then ``scan`` (``n_rays`` ranges in the order of its ``angles``), then
``local_map`` (``cells * cells`` codes, row by row), then any other observation terms of the
task.

>>> make_sensors({"lidar": {}})
Traceback (most recent call last):
...
pointnav_core.errors.ArgumentError: sensors has an unknown sensor 'lidar'; valid sensors are ['scan', 'local_map']
>>> make_sensors({"scan": {"rays": 8}})
Traceback (most recent call last):
...
pointnav_core.errors.ArgumentError: sensors['scan'] has an unknown key 'rays'; valid keys are ['n_rays', 'fov', 'min_range', 'max_range', 'noise_std', 'dropout']
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping
from typing import Any

from pointnav_core.errors import ArgumentError
from pointnav_core.sensors.local_map import LocalMap
from pointnav_core.sensors.scan import RangeScan
from pointnav_core.task.observations import ObservationTerm

__all__ = ["SENSORS", "SENSOR_ORDER", "make_sensors"]

#: Sensor name -> its observation term class.
SENSORS: Mapping[str, type[ObservationTerm]] = {"scan": RangeScan, "local_map": LocalMap}
#: The order of the sensors' terms in the observation.
SENSOR_ORDER = tuple(SENSORS)


def make_sensors(sensors: Mapping[str, Any] | None, name: str = "sensors") -> list[ObservationTerm]:
    """Build the sensor terms a ``sensors`` config names, in :data:`SENSOR_ORDER`.

    Parameters
    ----------
    sensors : dict or None
        Sensor name -> keyword arguments (dict), None (defaults) or a term of that sensor's
        class. None or an empty dict: no sensors.
    name : str
        What to call ``sensors`` in error messages.

    Raises
    ------
    ValueError
        For an unknown sensor name, an unknown key, or a bad value (naming it).
    """
    if sensors is None:
        return []
    if not isinstance(sensors, Mapping):
        raise ArgumentError(
            f"{name} must be None or a dict of sensor name -> arguments, with names in "
            f"{list(SENSOR_ORDER)}, got {sensors!r}"
        )
    for key in sensors:
        if key not in SENSORS:
            raise ArgumentError(
                f"{name} has an unknown sensor {key!r}; valid sensors are {list(SENSOR_ORDER)}"
            )
    terms: list[ObservationTerm] = []
    for key in SENSOR_ORDER:
        if key not in sensors:
            continue
        cls, args = SENSORS[key], sensors[key]
        if isinstance(args, cls):
            terms.append(args)
            continue
        if args is None:
            args = {}
        if not isinstance(args, Mapping):
            raise ArgumentError(
                f"{name}[{key!r}] must be a dict of {cls.__name__} arguments, None, or a "
                f"{cls.__name__}, got {args!r}"
            )
        valid = list(inspect.signature(cls).parameters)
        for arg in args:
            if arg not in valid:
                raise ArgumentError(
                    f"{name}[{key!r}] has an unknown key {arg!r}; valid keys are {valid}"
                )
        try:
            terms.append(cls(**args))
        except ValueError as err:
            raise ArgumentError(f"{name}[{key!r}]: {err}") from None
    return terms
