"""Hypothesis strategies for robot specs and the actions they take.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import strategies as st

from pointnav_core.errors import ArgumentError

__all__ = [
    "robot_specs",
    "robot_actions",
]


def robot_specs(
    drives: tuple[str, ...] = ("differential", "holonomic"),
    max_radius: float = 0.5,
    max_speed: float = 2.0,
) -> st.SearchStrategy:
    """Valid :class:`~pointnav_core.backends.protocol.RobotSpec` values.

    Radii lie in ``[0, max_radius]`` metres (shrinking to 0, a point robot), linear speed
    limits in ``[0.01, max_speed]`` m/s, yaw-rate limits in ``[0.01, 2 pi]`` rad/s, and the
    drive is drawn from ``drives`` (shrinking to the first).

    Parameters
    ----------
    drives : tuple of str
        A non-empty subset of ``("differential", "holonomic")``.
    max_radius : float
        Largest radius in metres, >= 0.
    max_speed : float
        Largest ``max_linear_velocity`` in m/s, >= 0.01.
    """
    from pointnav_core.backends.robot_spec import DRIVES, RobotSpec

    drives = tuple(drives)
    if not drives or any(d not in DRIVES for d in drives):
        raise ArgumentError(f"drives must be a non-empty subset of {tuple(DRIVES)}, got {drives!r}")
    if not (math.isfinite(max_radius) and max_radius >= 0.0):
        raise ArgumentError(f"max_radius must be a finite number >= 0 (metres), got {max_radius!r}")
    if not (math.isfinite(max_speed) and max_speed >= 0.01):
        raise ArgumentError(f"max_speed must be a finite number >= 0.01 (m/s), got {max_speed!r}")
    return st.builds(
        RobotSpec,
        radius=st.floats(0.0, max_radius),
        max_linear_velocity=st.floats(0.01, max_speed),
        max_angular_velocity=st.floats(0.01, 2 * math.pi),
        drive=st.sampled_from(drives),
    )


def robot_actions(spec: object, overshoot: float = 0.0) -> st.SearchStrategy[np.ndarray]:
    """Actions for a robot of ``spec``: float64 arrays of shape ``(spec.action_dim,)``.

    Components lie in ``[-1 - overshoot, 1 + overshoot]``; a positive ``overshoot`` also
    exercises clipping. Shrinks towards the zero action (standing still).

    Parameters
    ----------
    spec : RobotSpec
        The robot the actions are for.
    overshoot : float
        How far beyond ``[-1, 1]`` components may go, >= 0.
    """
    if not (math.isfinite(overshoot) and overshoot >= 0.0):
        raise ArgumentError(f"overshoot must be a finite number >= 0, got {overshoot!r}")
    bound = 1.0 + overshoot
    n = int(spec.action_dim)  # type: ignore[attr-defined]
    return st.lists(st.floats(-bound, bound), min_size=n, max_size=n).map(
        lambda values: np.array(values, dtype=np.float64)
    )




# ----------------------------------------------------------------------- maps
