"""Episode metrics of point-goal navigation: SPL and SoftSPL.

Both compare the path the robot drove, of length ``L``, with the shortest path from the
start, of geodesic length ``d0`` (Anderson et al., 2018, "On Evaluation of Embodied
Navigation Agents"; SoftSPL as in Habitat). :func:`spl_values` and :func:`soft_spl_values`
are the one definition every engine calls, on Python floats (the single envs, every control
step) or on numpy or torch arrays (the batched engine, with the array library's ``where``);
:func:`spl` and :func:`soft_spl` check their arguments first. They are defined on the whole
closed domain:

- ``d0 = inf`` (the goal is not reachable from the start): both are 0.
- ``d0 = 0`` (the start is the goal): the efficiency ``d0 / max(d0, L)`` is read as 1 when
  ``L <= d0`` (the robot did not move: it could not have done better) and ``d0 / L = 0``
  otherwise; SoftSPL's progress ``1 - d_T / d0`` is read as 1 when ``d_T = 0`` and 0
  otherwise. So SPL is ``1.0`` for a success that never moved, and no input divides by zero.

Both lie in ``[0, 1]``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from pointnav_core.errors import ArgumentError

__all__ = ["scalar_where", "soft_spl", "soft_spl_values", "spl", "spl_values"]


def _check_distance(name: str, value: float, *, allow_inf: bool) -> float:
    try:
        d = float(value)
    except (TypeError, ValueError):
        raise ArgumentError(f"{name} must be a number >= 0 (m), got {value!r}") from None
    if not d >= 0.0 or (d == math.inf and not allow_inf):  # `not >=` also catches NaN
        kind = "a number >= 0, or inf," if allow_inf else "a finite number >= 0"
        raise ArgumentError(f"{name} must be {kind} (m), got {value!r}")
    return d


def scalar_where(condition: bool, a: Any, b: Any) -> Any:
    """``numpy.where`` for one value: what the single envs pass where the batched engine
    passes ``xp.where`` (the terms defined once for both, here and in ``rewards``)."""
    return a if condition else b


# One definition for every engine: Python floats with the default ``where``, numpy or torch
# arrays with the array library's (the batched engine passes ``xp.where``). Both branches of
# a ``where`` are evaluated on arrays, so each division is guarded. Unchecked: the engines
# call these on values they keep valid (the public functions below check).
def spl_values(success: Any, d0: Any, path_length: Any, where: Callable[..., Any] = scalar_where) -> Any:
    """SPL of one episode or a batch: ``success * d0 / max(d0, L)``, 0 where ``d0`` is inf.

    Parameters
    ----------
    success : bool or bool array
    d0, path_length : float or float array
        Geodesic from the start (m, ``inf`` unreachable) and path driven (m, finite).
    where : callable
        ``where(condition, a, b)``: the default for scalars, ``numpy.where`` or
        ``torch.where`` for arrays.
    """
    return where(success & (d0 < math.inf), _efficiency(d0, path_length, where), 0.0)


def soft_spl_values(d_t: Any, d0: Any, path_length: Any, where: Callable[..., Any] = scalar_where) -> Any:
    """SoftSPL of one episode or a batch: ``max(0, 1 - d_T / d0) * d0 / max(d0, L)`` with the
    module's readings of ``d0 == 0`` and ``inf``; arguments as :func:`spl_values`."""
    positive = d0 > 0.0
    progress = where(positive, 1.0 - d_t / where(positive, d0, 1.0), where(d_t == 0.0, 1.0, 0.0))
    return where((d0 < math.inf) & (progress > 0.0), progress * _efficiency(d0, path_length, where), 0.0)


def _efficiency(d0: Any, path_length: Any, where: Callable[..., Any]) -> Any:
    # d0 / max(d0, L), with 0 / 0 read as 1 (see the module docstring).
    return where(path_length <= d0, 1.0, d0 / where(path_length > 0.0, path_length, 1.0))


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
    return float(spl_values(bool(success), d0, length))


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
    return float(soft_spl_values(d_t, d0, length))
