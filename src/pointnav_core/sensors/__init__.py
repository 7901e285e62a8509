"""Sensors: observation terms that look at the world around a robot.

=====================  ===============  ===================================================
class                  name             what it observes
=====================  ===============  ===================================================
:class:`RangeScan`     ``"scan"``       ranges (m) along ``n_rays`` rays to the blocked set
                                        and other robots: a planar lidar
:class:`LocalMap`      ``"local_map"``  an egocentric grid of the floor, heading up
=====================  ===============  ===================================================

Both are :class:`~pointnav_core.task.observations.ObservationTerm` objects: name them in the
envs' ``sensors`` argument (:func:`make_sensors`), or pass them in a task's
``observation_terms``. The exact ray casting is :mod:`pointnav_core.sensors.raycast`; with
numba installed (the ``fast`` extra) it runs the compiled kernel of
:mod:`pointnav_core.sensors.raycast_jit`, which gives the same ranges.
"""

from pointnav_core.sensors.config import SENSOR_ORDER, SENSORS, make_sensors
from pointnav_core.sensors.local_map import (
    LOCAL_BLOCKED,
    LOCAL_FREE,
    LOCAL_MAP_DTYPES,
    LOCAL_PEDESTRIAN,
    LOCAL_ROBOT,
    LOCAL_VOID,
    LocalMap,
)
from pointnav_core.sensors.raycast import TOUCH_EPS, ScanGeometry, cast_rays
from pointnav_core.sensors.scan import (
    RangeScan,
    other_robot_discs,
    pedestrian_discs,
    scan_angles,
)

__all__ = [
    "LOCAL_BLOCKED",
    "LOCAL_FREE",
    "LOCAL_MAP_DTYPES",
    "LOCAL_PEDESTRIAN",
    "LOCAL_ROBOT",
    "LOCAL_VOID",
    "SENSORS",
    "SENSOR_ORDER",
    "TOUCH_EPS",
    "LocalMap",
    "RangeScan",
    "ScanGeometry",
    "cast_rays",
    "make_sensors",
    "other_robot_discs",
    "pedestrian_discs",
    "scan_angles",
]
