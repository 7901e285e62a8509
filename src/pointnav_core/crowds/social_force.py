"""The social force model of pedestrians, as pysocialforce computes it.

:func:`social_force_step` advances a crowd of pedestrians by one time step of the social
force model (Helbing and Molnár, "Social force model for pedestrian dynamics", Physical
Review E 51, 4282, 1995): each pedestrian relaxes towards its desired velocity (its
preferred speed towards its goal) within a relaxation time, and is pushed away from the
other pedestrians and from walls. It follows pysocialforce 1.1.2 (Yuxiang Gao and
Chien-Ming Huang, "Evaluation of Socially-Aware Robot Navigation", Frontiers in Robotics and
AI 8, 2022; https://github.com/yuxiang-gao/PySocialForce, itself a fork of Sven Kreiss's
``socialforce``) formula by formula, with its default parameters (:class:`SocialForceParams`),
so that it gives pysocialforce's positions (``tests/test_social_force.py`` checks them
within 1e-6 m over 200 steps).

Two repulsions between pedestrians, both pysocialforce's:

- ``model="moussaid"``, pysocialforce's default (``forces.SocialForce``): the repulsion of
  Moussaïd, Helbing, Garnier, Johansson, Combe and Theraulaz, "Experimental study of the
  behavioural mechanisms underlying self-organization in human crowds", Proc. R. Soc. B 276,
  2009: an exponential in distance along, and turning away from, the interaction direction
  ``lambda (v_b - v_a) + e``, with pysocialforce's factor 5.1, lambda 2, gamma 0.35, n 2, n' 3.
- ``model="helbing_molnar"`` (``forces.PedRepulsiveForce``): Helbing and Molnár's
  repulsive potential ``V0 exp(-b / sigma)``, ``b`` the semi-minor axis of the ellipse
  around the other pedestrian stretched along its step ``dt |v_b| e_b``, with V0 2.1 m²/s²
  and sigma 0.3 m (the 1995 paper's values), field-of-view weight 1 within 100° of the
  desired direction and 0.5 outside, and factor 1.5. Its gradient is pysocialforce's
  forward difference with a 1e-3 m step (the exact gradient differs by about 1e-3 of it).

What pysocialforce's step does and this follows (``scene.PedState.step``): the force is the
desired force ``(speed e - v) / tau`` (``-v / tau`` within ``goal_threshold`` of the goal),
plus the repulsion summed over the other pedestrians, plus the wall force; the velocity
becomes ``v + dt F`` scaled down to ``max_speed``, and zero within ``stop_distance`` of the
goal; then ``x += dt v``. pysocialforce takes the desired speed and the max speed both as
1.3 times each pedestrian's initial speed (Helbing and Molnár's v_max = 1.3 v0); here both
are arguments.

Walls are pysocialforce's too (``forces.ObstacleForce``): each segment is sampled at
``wall_resolution`` points per metre as ``EnvState`` samples it, and every point closer
than ``wall_threshold`` m (plus twice the pedestrian radius) pushes with
``exp(-(d - radius) / wall_sigma)``, factor 10. pysocialforce's group forces (coherence,
repulsion and gaze within social groups) are not built: its default scene has no groups.

Pedestrians are points for the forces (the radius enters only the wall force); nothing
stops them overlapping. Pairs are O(n²) per step.

>>> import numpy as np
>>> pos, vel = social_force_step([[0.0, 0.0]], [[0.5, 0.0]], [[10.0, 0.0]], 1.0, 1.3, 0.1)
>>> vel.round(12).tolist(), pos.round(12).tolist()  # v + dt (speed - v) / tau = 0.5 + 0.1 * 1.0
([[0.6, 0.0]], [[0.06, 0.0]])
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.crowds._arguments import agents, per_agent
from pointnav_core.crowds._social_force_array import social_force_array
from pointnav_core.errors import ArgumentError
from pointnav_core.utils.compiled import check_method, choose
from pointnav_core.utils.validation import is_real_array, real

__all__ = ["MODELS", "SocialForceParams", "social_force_step"]

KERNEL = ("pointnav_core.crowds._social_force_kernel", "social_force_worlds")

#: The repulsions between pedestrians, by ``model`` name (the kernels' model number).
MODELS = {"moussaid": 0, "helbing_molnar": 1}


@dataclass(frozen=True)
class SocialForceParams:
    """The social force model's parameters: pysocialforce 1.1.2's defaults
    (``utils.config.DefaultConfig`` and the defaults in ``forces`` and ``scene``).

    Attributes
    ----------
    relaxation_time : float
        tau (s), > 0: the desired force is ``(desired velocity - v) / tau``
        (``desired_force.relaxation_time``).
    goal_threshold : float
        Within this distance of its goal (m) a pedestrian is pulled to a stop instead
        (``desired_force.goal_threshold``).
    stop_distance : float
        Within this distance of its goal (m) a pedestrian's velocity is set to zero
        (``PedState.step``'s 0.5).
    social_factor, lambda_importance, gamma, n, n_prime : float
        Moussaïd's repulsion (``social_force.*``): its factor (m/s²), the weight of the
        relative velocity in the interaction direction (s), B = gamma |interaction| (m), and
        the angular widths (1/m).
    repulsion_factor, v0, sigma, fov_phi, fov_factor, gradient_step : float
        Helbing and Molnár's repulsion (``ped_repulsive_force.*``): its factor, V0 (m²/s²),
        sigma (m), the half angle of the field of view (degrees), the weight outside it, and
        the finite-difference step of the gradient (m, ``PedPedPotential.grad_r_ab``).
    wall_factor, wall_sigma, wall_threshold, wall_resolution, radius : float
        The wall force (``obstacle_force.*``, ``scene.agent_radius``, ``scene.resolution``):
        its factor (m/s²), decay length (m), reach (m: points closer than ``wall_threshold +
        2 radius`` to the centre push, as pysocialforce adds the radius on both sides), wall
        points per metre (1/m), and the pedestrians' radius (m).
    """

    relaxation_time: float = 0.5
    goal_threshold: float = 0.2
    stop_distance: float = 0.5
    social_factor: float = 5.1
    lambda_importance: float = 2.0
    gamma: float = 0.35
    n: float = 2.0
    n_prime: float = 3.0
    repulsion_factor: float = 1.5
    v0: float = 2.1
    sigma: float = 0.3
    fov_phi: float = 100.0
    fov_factor: float = 0.5
    gradient_step: float = 1e-3
    wall_factor: float = 10.0
    wall_sigma: float = 0.2
    wall_threshold: float = 3.0
    wall_resolution: float = 10.0
    radius: float = 0.35

    def __post_init__(self) -> None:
        for name, value in asdict(self).items():
            real(name, value, minimum=0.0, strict=name in _POSITIVE, unit=_UNITS.get(name, ""))


#: The parameters something is divided by (> 0; the others may be 0), and the units named in the errors.
_POSITIVE = ("relaxation_time", "gamma", "sigma", "gradient_step", "wall_sigma")
_UNITS = {
    "relaxation_time": "s", "goal_threshold": "m", "stop_distance": "m", "social_factor": "m/s²", "lambda_importance": "s",
    "gamma": "m", "v0": "m²/s²", "sigma": "m", "fov_phi": "degrees", "gradient_step": "m", "wall_factor": "m/s²",
    "wall_sigma": "m", "wall_threshold": "m", "wall_resolution": "1/m", "radius": "m",
}


def packed(params: SocialForceParams, dt: float) -> NDArray[np.float64]:
    """The parameter vector of both paths (``_social_force_array``'s indices)."""
    q = params
    return np.array([
        dt, q.relaxation_time, q.goal_threshold, q.stop_distance, q.social_factor, q.lambda_importance, q.gamma, q.n,
        q.n_prime, q.repulsion_factor, q.v0, q.sigma, np.cos(q.fov_phi / 180.0 * np.pi), q.fov_factor,
        q.gradient_step, q.wall_factor, q.wall_sigma, q.wall_threshold, q.radius,
    ], np.float64)


def wall_points(walls: Any, worlds: int, resolution: float) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Wall segments ``(m, 2, 2)`` (every world's) or ``(w, m, 2, 2)`` (m) sampled as
    pysocialforce's ``EnvState`` samples them: ``int(length * resolution)`` evenly spaced
    points from end to end (none for a segment shorter than one spacing, so degenerate
    segments pad a world's list). Returns the points ``(w, k, 2)`` and each world's count."""
    arr = np.asarray(walls) if walls is not None and is_real_array(walls) else None
    ok = arr is not None and arr.ndim in (3, 4) and arr.shape[-2:] == (2, 2) and (arr.ndim == 3 or arr.shape[0] == worlds)
    ok = ok and bool(np.isfinite(arr.astype(np.float64)).all())
    if not ok:
        raise ArgumentError(
            f"walls must be an (m, 2, 2) array of segments, or ({worlds}, m, 2, 2) for each world, of finite "
            f"numbers (m), got {walls!r}"
        )
    arr = np.broadcast_to(arr.astype(np.float64), (worlds, *arr.shape[-3:]))
    lists = []
    for segments in arr:
        samples = [int(np.linalg.norm((a[0] - b[0], a[1] - b[1])) * resolution) for a, b in segments]
        lists.append([
            np.stack([np.linspace(a[0], b[0], k), np.linspace(a[1], b[1], k)], axis=-1)
            for (a, b), k in zip(segments, samples) if k > 0
        ])
    count = np.array([sum(len(p) for p in pts) for pts in lists], np.int64)
    points = np.zeros((worlds, int(count.max(initial=0)), 2))
    for w, pts in enumerate(lists):
        if pts:
            points[w, : count[w]] = np.concatenate(pts)
    return points, count


def social_force_step(
    positions: Any,
    velocities: Any,
    goals: Any,
    speed: Any,
    max_speed: Any,
    dt: float,
    *,
    model: str = "moussaid",
    walls: Any = None,
    params: SocialForceParams | None = None,
    method: str = "auto",
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """One social force step of a crowd (pysocialforce's ``Simulator.step``): new positions
    and velocities.

    Parameters
    ----------
    positions, velocities, goals : array_like, shape (n, 2) or (w, n, 2)
        Centres (m), current velocities (m/s) and goals (m) of ``n`` pedestrians, or of ``n``
        in each of ``w`` independent worlds (pedestrians of different worlds ignore each other).
    speed : float or array_like, shape (n,) or (w, n)
        Desired speeds (m/s), >= 0: the desired velocity is this towards the goal.
    max_speed : float or array_like, shape (n,) or (w, n)
        Speed limits (m/s), >= 0 (pysocialforce: both 1.3 times the initial speed).
    dt : float
        Time step (s), > 0 (pysocialforce's ``step_width``; its default scene has 1.0).
    model : {"moussaid", "helbing_molnar"}
        The repulsion between pedestrians (see the module notes).
    walls : array_like, shape (m, 2, 2) or (w, m, 2, 2), optional
        Wall segments ``((x0, y0), (x1, y1))`` (m), shared by all worlds or each world's own
        (pad a world's list with zero-length segments).
    params : SocialForceParams, optional
        The model's parameters; pysocialforce's defaults when not given.
    method : {"auto", "array", "numba"}
        The compiled path (numba, the ``fast`` extra), the numpy path, or the compiled path
        where it can run. The two agree to rounding (``exp`` and ``atan2`` of numpy and of
        the C library can differ in the last bit).

    Returns
    -------
    positions, velocities : ndarray of float64, the shape of ``positions``
        After the step.

    Raises
    ------
    ArgumentError
        An argument of the wrong shape or type, not finite, or out of its range.
    """
    check_method(method)
    if model not in MODELS:
        raise ArgumentError(f"model must be one of {', '.join(map(repr, MODELS))}, got {model!r}")
    params = SocialForceParams() if params is None else params
    if not isinstance(params, SocialForceParams):
        raise ArgumentError(f"params must be a SocialForceParams, got {params!r}")
    pos = agents("positions", positions, None)
    vel = agents("velocities", velocities, pos.shape)
    goal = agents("goals", goals, pos.shape)
    batched = pos.ndim == 3
    if not batched:
        pos, vel, goal = pos[None], vel[None], goal[None]
    shape = pos.shape[:2]
    speed_ = per_agent("speed", speed, shape, "m/s")
    limit = per_agent("max_speed", max_speed, shape, "m/s")
    step = real("dt", dt, minimum=0.0, strict=True, unit="s")
    if walls is None:
        points, count = np.zeros((shape[0], 0, 2)), np.zeros(shape[0], np.int64)
    else:
        points, count = wall_points(walls, shape[0], params.wall_resolution)
    fn = choose(method, *KERNEL)
    (fn or social_force_array)(pos, vel, goal, speed_, limit, points, count, packed(params, step), MODELS[model])
    if not batched:
        pos, vel = pos[0], vel[0]
    return pos, vel

