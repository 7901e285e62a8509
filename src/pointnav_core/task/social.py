"""Social-navigation metrics of one recorded episode (issue 33, point 4).

Every function reads a recorded episode: the robot's positions ``(T + 1, 2)`` (m) and
headings ``(T + 1,)`` (rad) at the start and after each of its ``T >= 1`` steps of ``dt``
seconds, and the pedestrians' positions ``(T + 1, P, 2)`` at the same instants (``P`` may
be 0). They are pure numpy, vectorised over time and pedestrians, and check their
arguments (an :class:`~pointnav_core.errors.ArgumentError` naming the argument).
:func:`social_metrics` returns them all under the names of :data:`SOCIAL_METRIC_KEYS`.
Definitions, sources and conventions: ``docs/social_metrics.md``. In short:

- **Distances.** Personal space (PSC, ``personal_space_time``) is judged on the distance
  between *centres*, as iGibson does (``SocialNavRandomTask.step``: ``l2_distance(robot,
  ped) < orca_radius``, 0.5 m). Contacts and time-to-collision are between *discs* (robot
  radius plus pedestrian radius). The minimum distance is reported both ways
  (``min_ped_distance`` between centres, ``min_ped_clearance`` between surfaces, negative
  when they overlap).
- **Samples.** Per-step judgements (PSC, time in personal space) read the ``T`` positions
  after each step, as iGibson checks after each step; minima and contacts read all ``T + 1``
  samples. Velocities are forward differences ``(p[t + 1] - p[t]) / dt``: what the robot
  and each pedestrian actually moved over step ``t``.
- **Undefined values are None, never NaN or inf**: the minimum distance with no
  pedestrian, the minimum time-to-collision when no pedestrian is ever on a collision
  course, path irregularity over a path of length 0, acceleration with fewer than 2 steps
  and jerk with fewer than 3. None is written as JSON ``null`` and left out of means,
  where any finite stand-in (0, a horizon, -1) would be averaged in as if measured.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.task.metrics import spl_values
from pointnav_core.utils.validation import (
    boolean,
    integer,
    is_real,
    is_real_array,
    real,
)

__all__ = [
    "DEFAULT_PERSONAL_SPACE",
    "SOCIAL_METRIC_KEYS",
    "excess_rotation",
    "min_pedestrian_distance",
    "min_time_to_collision",
    "motion_statistics",
    "path_irregularity",
    "pedestrian_collisions",
    "personal_space_steps",
    "personal_space_time",
    "psc",
    "recorded_social_metrics",
    "social_metrics",
    "stl",
    "time_to_collision",
]

#: Personal-space radius (m) between centres: iGibson's ``orca_radius`` default.
DEFAULT_PERSONAL_SPACE = 0.5

# Bounds that keep every difference, square and division by dt**3 finite, so that no
# accepted input yields NaN or inf: coordinates, radii and headings within 1e9 (m, rad),
# steps of at least a microsecond.
_MAX_MAGNITUDE = 1e9
_MIN_DT = 1e-6

#: The keys of :func:`social_metrics`, in order, with their units.
SOCIAL_METRIC_KEYS = (
    "psc",  # 1, in [0, 1]
    "stl",  # 1, in [0, 1]
    "min_ped_distance",  # m, centres; None without pedestrians
    "min_ped_clearance",  # m, surfaces (< 0: overlap); None without pedestrians
    "personal_space_time",  # s
    "min_ttc",  # s; None if never on a collision course
    "path_irregularity",  # rad/m; None if the path length is 0
    "excess_rotation",  # rad
    "speed_mean", "speed_max",  # m/s
    "accel_mean", "accel_max",  # m/s^2; None if T < 2
    "jerk_mean", "jerk_max",  # m/s^3; None if T < 3
    "ped_collisions",  # count (a float), contact onsets
)


# --- argument checks -------------------------------------------------------------------


def _array(name: str, value: Any, shape: tuple[int | None, ...], what: str) -> NDArray[np.float64]:
    """``value`` as a float64 array of finite numbers whose shape matches ``shape`` (None:
    any size), or an ArgumentError naming ``name``."""
    try:
        arr = np.asarray(value) if is_real_array(value) else None
    except ValueError:  # ragged nested lists
        arr = None
    ok = arr is not None and arr.ndim == len(shape) and all(w is None or w == s for w, s in zip(shape, arr.shape))
    if ok:
        arr = arr.astype(np.float64)
        ok = bool((np.abs(arr) <= _MAX_MAGNITUDE).all())  # also refuses NaN and inf
    if not ok:
        want = "(" + ", ".join("n" if w is None else str(w) for w in shape) + ")"
        raise ArgumentError(
            f"{name} must be an array of shape {want} of finite numbers within +-{_MAX_MAGNITUDE:g} "
            f"({what}), got {value!r}"
        )
    return arr  # type: ignore[return-value]


def _robot(robot_positions: Any) -> NDArray[np.float64]:
    robot = _array("robot_positions", robot_positions, (None, 2), "m, one row per sample")
    if robot.shape[0] < 2:
        raise ArgumentError(
            f"robot_positions must hold the start and at least one step (T + 1 >= 2 rows), got {robot.shape[0]}"
        )
    return robot


def _pedestrians(pedestrian_positions: Any, samples: int) -> NDArray[np.float64]:
    return _array("pedestrian_positions", pedestrian_positions, (samples, None, 2), "m, (T + 1, P, 2)")


def _radii(name: str, value: Any, count: int) -> NDArray[np.float64]:
    """A radius (m) >= 0, or one per pedestrian, as a ``(count,)`` array."""
    if is_real(value):
        return np.full(count, real(name, value, minimum=0.0, maximum=_MAX_MAGNITUDE))
    try:
        arr = np.asarray(value) if is_real_array(value) else None
    except ValueError:  # ragged nested lists
        arr = None
    if arr is None or arr.shape != (count,) or not ((arr >= 0).all() and (arr <= _MAX_MAGNITUDE).all()):
        raise ArgumentError(
            f"{name} must be a number >= 0 and <= {_MAX_MAGNITUDE:g} (m), or {count} of them, got {value!r}"
        )
    return arr.astype(np.float64)


def _radius(robot_radius: Any) -> float:
    return real("robot_radius", robot_radius, minimum=0.0, maximum=_MAX_MAGNITUDE)


def _personal_space(personal_space: Any) -> float:
    return real("personal_space", personal_space, minimum=0.0, maximum=_MAX_MAGNITUDE)


def _dt(dt: Any) -> float:
    return real("dt", dt, minimum=_MIN_DT, unit="s")


# --- distances and personal space ------------------------------------------------------


def _center_distances(robot: NDArray[np.float64], peds: NDArray[np.float64]) -> NDArray[np.float64]:
    # (T + 1, P): hypot rather than sqrt of a sum, exact for axis-aligned offsets.
    diff = peds - robot[:, None, :]
    return np.hypot(diff[..., 0], diff[..., 1])


def min_pedestrian_distance(
    robot_positions: Any, pedestrian_positions: Any, *, robot_radius: Any = 0.0, pedestrian_radii: Any = 0.0
) -> float | None:
    """Smallest distance from the robot to a pedestrian over all ``T + 1`` samples (m).

    With both radii 0 (the default) this is the distance between centres; with the radii,
    the clearance between the discs' surfaces (negative when they overlap).

    Returns
    -------
    float or None
        None when there is no pedestrian.
    """
    robot = _robot(robot_positions)
    peds = _pedestrians(pedestrian_positions, robot.shape[0])
    r_robot = _radius(robot_radius)
    r_peds = _radii("pedestrian_radii", pedestrian_radii, peds.shape[1])
    if peds.shape[1] == 0:
        return None
    return float(np.min(_center_distances(robot, peds) - r_robot - r_peds))


def _violations(robot: NDArray[np.float64], peds: NDArray[np.float64], personal_space: float) -> int:
    # Steps 1..T (the state after each step, as iGibson checks) with a centre closer than
    # the personal-space radius; strictly closer, as iGibson's `<`.
    if peds.shape[1] == 0:
        return 0
    return int(np.count_nonzero((_center_distances(robot[1:], peds[1:]) < personal_space).any(axis=1)))


def personal_space_steps(
    robot_positions: Any, pedestrian_positions: Any, personal_space: Any = DEFAULT_PERSONAL_SPACE
) -> int:
    """Number of steps after which some pedestrian's centre is closer to the robot's centre
    than ``personal_space`` (m): iGibson's ``personal_space_violation_steps``."""
    robot = _robot(robot_positions)
    peds = _pedestrians(pedestrian_positions, robot.shape[0])
    return _violations(robot, peds, _personal_space(personal_space))


def personal_space_time(
    robot_positions: Any, pedestrian_positions: Any, dt: Any, personal_space: Any = DEFAULT_PERSONAL_SPACE
) -> float:
    """Time (s) within some pedestrian's personal space: :func:`personal_space_steps` times
    ``dt``."""
    return personal_space_steps(robot_positions, pedestrian_positions, personal_space) * _dt(dt)


def psc(
    robot_positions: Any,
    pedestrian_positions: Any,
    personal_space: Any = DEFAULT_PERSONAL_SPACE,
    max_steps: Any = None,
) -> float:
    """Personal Space Compliance (iGibson): ``1 - violation_steps / N``, in ``[0, 1]``.

    Parameters
    ----------
    robot_positions, pedestrian_positions : array_like
        ``(T + 1, 2)`` and ``(T + 1, P, 2)`` (m).
    personal_space : float
        Radius (m) between centres; 0.5 by default, iGibson's ``orca_radius``.
    max_steps : int, optional
        ``N``. By default ``T``, the episode's steps: PSC is the fraction of the steps that
        complied. iGibson divides by the step limit (``max_step``, 500) whatever the
        episode's length; pass it here to reproduce iGibson's ``info["psc"]`` exactly.
        Must be at least ``T``.
    """
    robot = _robot(robot_positions)
    peds = _pedestrians(pedestrian_positions, robot.shape[0])
    steps = robot.shape[0] - 1
    n = steps if max_steps is None else integer("max_steps", max_steps, minimum=steps)
    return 1.0 - _violations(robot, peds, _personal_space(personal_space)) / n


# --- time and efficiency ---------------------------------------------------------------


def stl(success: Any, geodesic_dist: Any, duration: Any, max_speed: Any) -> float:
    """Success weighted by Time Length: ``success * t_opt / max(t_opt, t)``, in ``[0, 1]``.

    ``t_opt = geodesic_dist / max_speed`` (s), the time the robot needs at its top speed
    along the shortest path; ``t`` is the episode's ``duration`` (s, ``T * dt``). iGibson
    takes ``t_opt`` from an ORCA agent's time on the same episode (``orca_timesteps``),
    which this library does not simulate: pass that time as ``geodesic_dist / max_speed``
    to reproduce it. Read as SPL on times (:func:`~pointnav_core.task.metrics.spl`), with
    the same conventions: 0 when the goal is unreachable (``geodesic_dist = inf``), and
    ``t_opt = 0`` counts as 1 only when ``t = 0``.

    Examples
    --------
    >>> stl(True, 4.0, 10.0, 0.5)  # 8 s at top speed, 10 s taken
    0.8
    >>> stl(False, 4.0, 10.0, 0.5), stl(True, 4.0, 6.0, 0.5)
    (0.0, 1.0)
    """
    ok = boolean("success", success)
    d0 = real("geodesic_dist", geodesic_dist, minimum=0.0, finite=False)
    t = real("duration", duration, minimum=0.0, unit="s")
    speed = real("max_speed", max_speed, minimum=0.0, strict=True, unit="m/s")
    return float(spl_values(ok, d0 / speed, t))


# --- time-to-collision -----------------------------------------------------------------


def time_to_collision(relative_positions: Any, relative_velocities: Any, radius: Any) -> NDArray[np.float64]:
    """Constant-velocity time-to-collision (s) of pairs of discs, element-wise.

    The first ``tau >= 0`` with ``|dp + dv * tau| <= radius``: 0 for discs already in
    contact, ``inf`` when they never touch (parallel, moving apart, or passing wide).

    Parameters
    ----------
    relative_positions, relative_velocities : array_like
        ``dp`` (m) and ``dv`` (m/s) of one disc relative to the other, shape ``(..., 2)``.
    radius : float or array_like
        Sum of both radii (m), broadcast against ``(...)``.

    Examples
    --------
    >>> time_to_collision([[4.0, 0.0]], [[-2.0, 0.0]], 1.0)  # 3 m gap closed at 2 m/s
    array([1.5])
    """
    dp = _array("relative_positions", relative_positions, (None, 2), "m")
    dv = _array("relative_velocities", relative_velocities, (dp.shape[0], 2), "m/s")
    r = _radii("radius", radius, dp.shape[0])
    return _ttc(dp, dv, r)


def _ttc(dp: NDArray[np.float64], dv: NDArray[np.float64], r: Any) -> NDArray[np.float64]:
    # Along the unit direction u of dv: the gap closes while dp.u < 0, and the path passes
    # the other centre at the miss distance |dp x u|; it touches iff that is <= r, first at
    # tau = (-dp.u - s) / |dv| with s = sqrt(r^2 - (dp x u)^2), written as
    # (|dp|^2 - r^2) / ((s - dp.u) |dv|) to avoid cancellation near contact. Working with
    # u rather than the quadratic's dv.dv keeps a tiny |dv| from underflowing to a false
    # contact.
    speed = np.hypot(dv[..., 0], dv[..., 1])
    u = dv / np.where(speed > 0.0, speed, 1.0)[..., None]
    along = dp[..., 0] * u[..., 0] + dp[..., 1] * u[..., 1]
    cross = dp[..., 0] * u[..., 1] - dp[..., 1] * u[..., 0]
    gap2 = dp[..., 0] * dp[..., 0] + dp[..., 1] * dp[..., 1] - np.square(r)
    room = np.square(r) - cross * cross
    closing = (speed > 0.0) & (along < 0.0) & (room >= 0.0)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        tau = np.where(closing, gap2 / ((np.sqrt(np.where(closing, room, 0.0)) - along) * speed), np.inf)
    return np.where(gap2 <= 0.0, 0.0, tau)


def min_time_to_collision(
    robot_positions: Any, pedestrian_positions: Any, dt: Any, *, robot_radius: Any, pedestrian_radii: Any
) -> float | None:
    """Smallest constant-velocity time-to-collision (s) between the robot's disc and a
    pedestrian's, over samples ``t = 0..T - 1``, each with the velocities of step ``t``.

    Returns
    -------
    float or None
        0 if they ever touch at a sample; None when no pedestrian is ever on a collision
        course (or there is none).
    """
    robot = _robot(robot_positions)
    peds = _pedestrians(pedestrian_positions, robot.shape[0])
    step = _dt(dt)
    r = _radius(robot_radius) + _radii("pedestrian_radii", pedestrian_radii, peds.shape[1])
    if peds.shape[1] == 0:
        return None
    v_robot = np.diff(robot, axis=0) / step  # (T, 2)
    v_peds = np.diff(peds, axis=0) / step  # (T, P, 2)
    tau = _ttc(peds[:-1] - robot[:-1, None, :], v_peds - v_robot[:, None, :], r)
    best = float(np.min(tau))
    return None if math.isinf(best) else best


def pedestrian_collisions(
    robot_positions: Any, pedestrian_positions: Any, *, robot_radius: Any, pedestrian_radii: Any
) -> int:
    """Number of contacts with pedestrians: for each pedestrian, the samples at which its
    disc touches or overlaps the robot's (clearance <= 0) while it did not at the sample
    before (a contact held over several steps counts once; one at the start counts)."""
    robot = _robot(robot_positions)
    peds = _pedestrians(pedestrian_positions, robot.shape[0])
    r = _radius(robot_radius) + _radii("pedestrian_radii", pedestrian_radii, peds.shape[1])
    touch = _center_distances(robot, peds) <= r  # (T + 1, P)
    onsets = touch[1:] & ~touch[:-1]
    return int(np.count_nonzero(onsets) + np.count_nonzero(touch[0]))


# --- the robot's own motion ------------------------------------------------------------


def _wrap(angle: NDArray[np.float64]) -> NDArray[np.float64]:
    return (angle + np.pi) % (2.0 * np.pi) - np.pi


def _rotation_terms(
    robot_positions: Any, headings: Any, goal: Any
) -> tuple[float, float, float]:
    """(total rotation, rotation needed, path length) of the episode."""
    robot = _robot(robot_positions)
    yaw = _array("headings", headings, (robot.shape[0],), "rad, one per sample")
    target = robot[-1] if goal is None else _array("goal", goal, (2,), "m")
    # Each step's turn is read as the shorter way round (|turn| <= pi per step).
    total = float(np.sum(np.abs(_wrap(np.diff(yaw)))))
    offset = target - robot[0]
    needed = 0.0
    if offset.any():  # a goal at the start needs no turn
        needed = float(abs(_wrap(np.arctan2(offset[1], offset[0]) - yaw[0])))
    seg = np.diff(robot, axis=0)
    return total, needed, float(np.sum(np.hypot(seg[:, 0], seg[:, 1])))


def excess_rotation(robot_positions: Any, headings: Any, goal: Any = None) -> float:
    """Rotation (rad) beyond what the most direct path needs: the sum of the heading
    changes minus the turn from the initial heading to the bearing of ``goal`` (the final
    position by default), clipped at 0 (a holonomic robot can reach a goal without the
    turn)."""
    total, needed, _ = _rotation_terms(robot_positions, headings, goal)
    return max(0.0, total - needed)


def path_irregularity(robot_positions: Any, headings: Any, goal: Any = None) -> float | None:
    """Path irregularity (rad/m): :func:`excess_rotation` per metre of path driven (Guzzi
    et al., 2013; SocNavBench's ``path_irregularity`` docstring). None when the robot did
    not move (a turn on the spot has no length to spread over; :func:`excess_rotation`
    still counts it)."""
    total, needed, length = _rotation_terms(robot_positions, headings, goal)
    return max(0.0, total - needed) / length if length > 0.0 else None


def motion_statistics(robot_positions: Any, dt: Any) -> dict[str, float | None]:
    """Mean and maximum of the robot's speed (m/s), acceleration (m/s²) and jerk (m/s³)
    magnitudes, from successive finite differences of its positions.

    Velocities ``v[t] = (p[t + 1] - p[t]) / dt`` (``T`` of them), accelerations
    ``(v[t + 1] - v[t]) / dt`` (``T - 1``), jerks likewise (``T - 2``). Keys ``speed_mean``,
    ``speed_max``, ``accel_mean``, ``accel_max``, ``jerk_mean``, ``jerk_max``; None where
    there are no differences to take (acceleration with ``T < 2``, jerk with ``T < 3``).
    """
    robot = _robot(robot_positions)
    step = _dt(dt)
    out: dict[str, float | None] = {}
    values = robot
    for name in ("speed", "accel", "jerk"):
        values = np.diff(values, axis=0) / step
        norms = np.hypot(values[:, 0], values[:, 1])
        out[f"{name}_mean"] = float(np.mean(norms)) if norms.size else None
        out[f"{name}_max"] = float(np.max(norms)) if norms.size else None
    return out


# --- all of them -----------------------------------------------------------------------


def social_metrics(
    robot_positions: Any,
    headings: Any,
    pedestrian_positions: Any,
    *,
    dt: Any,
    robot_radius: Any,
    pedestrian_radii: Any,
    success: Any,
    geodesic_dist: Any,
    max_speed: Any,
    personal_space: Any = DEFAULT_PERSONAL_SPACE,
    goal: Any = None,
) -> dict[str, float | None]:
    """Every social metric of one recorded episode, under :data:`SOCIAL_METRIC_KEYS`.

    Parameters
    ----------
    robot_positions : array_like, shape (T + 1, 2)
        The robot's centre (m) at the start and after each of ``T >= 1`` steps.
    headings : array_like, shape (T + 1,)
        The robot's heading (rad) at the same instants.
    pedestrian_positions : array_like, shape (T + 1, P, 2)
        The pedestrians' centres (m); ``P`` may be 0.
    dt : float
        Duration of a step (s), > 0.
    robot_radius : float
        The robot's radius (m), >= 0.
    pedestrian_radii : float or array_like, shape (P,)
        The pedestrians' radii (m), >= 0.
    success : bool
        Whether the episode succeeded (for STL).
    geodesic_dist : float
        Shortest-path length from the start to the goal (m), >= 0 or ``inf`` (for STL).
    max_speed : float
        The robot's top speed (m/s), > 0 (for STL's optimal time).
    personal_space : float
        Personal-space radius between centres (m), 0.5 by default.
    goal : array_like, shape (2,), optional
        The target of path irregularity's direct path; the final position by default.

    Returns
    -------
    dict
        Python floats, or None where a value is undefined (see the module docstring);
        ``psc`` divides by ``T`` (see :func:`psc` for iGibson's step-limit form).
    """
    robot = _robot(robot_positions)
    peds = _pedestrians(pedestrian_positions, robot.shape[0])
    step = _dt(dt)
    steps = robot.shape[0] - 1
    out: dict[str, float | None] = {
        "psc": psc(robot, peds, personal_space),
        "stl": stl(success, geodesic_dist, steps * step, max_speed),
        "min_ped_distance": min_pedestrian_distance(robot, peds),
        "min_ped_clearance": min_pedestrian_distance(
            robot, peds, robot_radius=robot_radius, pedestrian_radii=pedestrian_radii
        ),
        "personal_space_time": personal_space_time(robot, peds, step, personal_space),
        "min_ttc": min_time_to_collision(
            robot, peds, step, robot_radius=robot_radius, pedestrian_radii=pedestrian_radii
        ),
        "path_irregularity": path_irregularity(robot, headings, goal),
        "excess_rotation": excess_rotation(robot, headings, goal),
    }
    out.update(motion_statistics(robot, step))
    out["ped_collisions"] = float(
        pedestrian_collisions(robot, peds, robot_radius=robot_radius, pedestrian_radii=pedestrian_radii)
    )
    return {key: out[key] for key in SOCIAL_METRIC_KEYS}


def recorded_social_metrics(robot_positions: Any, headings: Any, pedestrian_positions: Any,
                            **kwargs: Any) -> dict[str, float | None]:
    """:func:`social_metrics` of an episode recorded from its start (``kwargs`` as there): one
    that ended before any control step holds its start alone, which counts twice, a step of
    standing still (the envs' and the batched engine's trackers)."""
    robot, heading = np.asarray(robot_positions, dtype=np.float64), np.asarray(headings, dtype=np.float64)
    peds = np.asarray(pedestrian_positions, dtype=np.float64)
    if len(robot) < 2:
        robot, heading, peds = (np.repeat(v, 2, axis=0) for v in (robot, heading, peds))
    return social_metrics(robot, heading, peds, **kwargs)
