"""Episode metrics of point-goal navigation: SPL and SoftSPL.

Both compare the path the robot drove, of length ``L``, with the shortest path from the
start, of geodesic length ``d0`` (Anderson et al., 2018, "On Evaluation of Embodied
Navigation Agents"; SoftSPL as in Habitat). They are pure functions of Python floats, cheap
enough for every control step, and they are defined on the whole closed domain:

- ``d0 = inf`` (the goal is not reachable from the start): both are 0.
- ``d0 = 0`` (the start is the goal): the efficiency ``d0 / max(d0, L)`` is read as 1 when
  ``L <= d0`` (the robot did not move: it could not have done better) and ``d0 / L = 0``
  otherwise; SoftSPL's progress ``1 - d_T / d0`` is read as 1 when ``d_T = 0`` and 0
  otherwise. So SPL is ``1.0`` for a success that never moved, and no input divides by zero.

Both lie in ``[0, 1]``.
"""

from __future__ import annotations

import math

from pointnav_core.errors import ArgumentError

__all__ = ["spl", "soft_spl"]


def _check_distance(name: str, value: float, *, allow_inf: bool) -> float:
    try:
        d = float(value)
    except (TypeError, ValueError):
        raise ArgumentError(f"{name} must be a number >= 0 (m), got {value!r}") from None
    if not d >= 0.0 or (d == math.inf and not allow_inf):  # `not >=` also catches NaN
        kind = "a number >= 0, or inf," if allow_inf else "a finite number >= 0"
        raise ArgumentError(f"{name} must be {kind} (m), got {value!r}")
    return d


def _efficiency(d0: float, path_length: float) -> float:
    # d0 / max(d0, L), with 0 / 0 read as 1 (see the module docstring).
    return 1.0 if path_length <= d0 else d0 / path_length


# Unchecked kernels: the task calls these on every step with values it keeps valid.
def _spl(success: bool, d0: float, path_length: float) -> float:
    if not success or d0 == math.inf:
        return 0.0
    return _efficiency(d0, path_length)


def _soft_spl(d_t: float, d0: float, path_length: float) -> float:
    if d0 == math.inf:
        return 0.0
    if d0 > 0.0:
        progress = 1.0 - d_t / d0
        if progress <= 0.0:
            return 0.0
    else:
        progress = 1.0 if d_t == 0.0 else 0.0
    return progress * _efficiency(d0, path_length)


def spl(success: bool, geodesic_dist: float, path_length: float) -> float:
    """Return Success weighted by (normalised inverse) Path Length.

    ``SPL = success * d0 / max(d0, L)``.

    Parameters
    ----------
    success : bool
        Whether the episode ended in success.
    geodesic_dist : float
        ``d0``: geodesic distance from the start to the goal in metres, >= 0; ``inf`` when
        the goal is not reachable.
    path_length : float
        ``L``: length of the path driven in metres, finite and >= 0, including the last
        step.

    Returns
    -------
    float
        In ``[0, 1]``; 0 unless ``success``, and 0 when ``d0`` is infinite. With
        ``d0 == 0`` it is 1 when ``L == 0`` and 0 otherwise.

    Raises
    ------
    ValueError
        If a distance is negative or NaN, or ``path_length`` is infinite.

    See Also
    --------
    soft_spl : Replaces ``success`` by the progress made towards the goal.

    Examples
    --------
    >>> spl(True, 4.0, 5.0)
    0.8
    >>> spl(True, 4.0, 3.5)  # shorter than the geodesic (it stopped within tolerance)
    1.0
    >>> spl(False, 4.0, 4.0), spl(True, float("inf"), 4.0)
    (0.0, 0.0)

    A start on the goal is a perfect success only if the robot stayed put:

    >>> spl(True, 0.0, 0.0), spl(True, 0.0, 0.3)
    (1.0, 0.0)
    """
    d0 = _check_distance("geodesic_dist", geodesic_dist, allow_inf=True)
    length = _check_distance("path_length", path_length, allow_inf=False)
    return _spl(bool(success), d0, length)


def soft_spl(distance_to_goal: float, geodesic_dist: float, path_length: float) -> float:
    """Return SoftSPL: progress towards the goal weighted by path efficiency (Habitat).

    ``SoftSPL = max(0, 1 - d_T / d0) * d0 / max(d0, L)``.

    Parameters
    ----------
    distance_to_goal : float
        ``d_T``: geodesic distance from the robot to the goal now (or at the episode's end)
        in metres, >= 0; ``inf`` when the robot cannot reach the goal from where it is.
    geodesic_dist : float
        ``d0``: geodesic distance from the start to the goal in metres, >= 0, or ``inf``.
    path_length : float
        ``L``: length of the path driven in metres, finite and >= 0.

    Returns
    -------
    float
        In ``[0, 1]``; 0 when ``d0`` or ``d_T`` is infinite or the robot ended farther
        from the goal than it started. With ``d0 == 0`` the progress is 1 if ``d_T == 0``
        and 0 otherwise.

    Raises
    ------
    ValueError
        If a distance is negative or NaN, or ``path_length`` is infinite.

    See Also
    --------
    spl : The success-only version.

    Examples
    --------
    >>> soft_spl(2.0, 4.0, 5.0)  # half way there, 80 % efficient
    0.4
    >>> soft_spl(5.0, 4.0, 2.0), soft_spl(1.0, float("inf"), 2.0)
    (0.0, 0.0)
    >>> soft_spl(0.0, 0.0, 0.0)
    1.0
    """
    d_t = _check_distance("distance_to_goal", distance_to_goal, allow_inf=True)
    d0 = _check_distance("geodesic_dist", geodesic_dist, allow_inf=True)
    length = _check_distance("path_length", path_length, allow_inf=False)
    return _soft_spl(d_t, d0, length)
