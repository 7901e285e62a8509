"""ORCA, optimal reciprocal collision avoidance, as RVO2 computes it.

:func:`orca_step` advances a crowd of disc agents by one time step: each agent takes the
velocity closest to its preferred one that is collision-free with its nearest neighbours for
``time_horizon`` seconds, assuming they take half the effort of avoiding it (van den Berg,
Guy, Lin and Manocha, "Reciprocal n-Body Collision Avoidance", Robotics Research, Springer
Tracts in Advanced Robotics 70, 2011, pp. 3-19), then every agent moves with its new
velocity. It follows the RVO2 Library (version 2.0, https://gamma.cs.unc.edu/RVO2/,
``Agent::computeNeighbors``, ``Agent::computeNewVelocity``, ``linearProgram1/2/3`` and
``RVOSimulator::doStep``) statement by statement, in RVO2's float32, so that it gives RVO2's
positions bit for bit (``tests/test_orca.py`` checks it against ``pyrvo``'s build of RVO2).

What RVO2 does and this follows:

- neighbours: the ``max_neighbors`` nearest other agents whose centres are closer than
  ``neighbor_dist``, nearest first; one ORCA line each, in that order;
- the new velocity: the 2-D linear program of the lines and the ``max_speed`` circle, closest
  to the preferred velocity; where it is infeasible (agents already too close), the velocity
  that least violates the lines (``linearProgram3``);
- the update: every agent's new velocity from the old state first, then every position
  (``position += velocity * dt``).

Two differences: an exact tie of two float32 squared distances to an agent is broken by
agent index here and by the visiting order of RVO2's k-d tree there (which depends on its
earlier steps), which can change which of the two is a neighbour or their order; and there are
no static obstacles yet (RVO2's obstacle lines): walls will come from the project's own
geometry. Neighbours are found among all ``n`` agents, O(n²) per step.

>>> import numpy as np
>>> pos, vel = orca_step([[0.0, 0.0], [4.0, 0.0]], np.zeros((2, 2)), [[1.0, 0.0], [-1.0, 0.0]],
...                      radius=0.5, max_speed=1.0, dt=0.5, neighbor_dist=10.0, max_neighbors=5,
...                      time_horizon=2.0)
>>> vel.tolist(), pos.tolist()  # head-on: each takes half of the slowing down
([[0.75, 0.0], [-0.75, 0.0]], [[0.375, 0.0], [3.625, 0.0]])
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.crowds._arguments import agents, per_agent
from pointnav_core.crowds._orca_array import orca_array
from pointnav_core.errors import ArgumentError
from pointnav_core.utils.compiled import check_method, choose
from pointnav_core.utils.validation import integer, real

__all__ = ["orca_step"]

KERNEL = ("pointnav_core.crowds._orca_kernel", "orca_worlds")


def orca_step(
    positions: Any,
    velocities: Any,
    preferred: Any,
    radius: Any,
    max_speed: Any,
    dt: float,
    neighbor_dist: float,
    max_neighbors: int,
    time_horizon: float,
    *,
    method: str = "auto",
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """One ORCA step of a crowd (RVO2's ``doStep``, agents only): new positions and velocities.

    Parameters
    ----------
    positions, velocities, preferred : array_like, shape (n, 2) or (w, n, 2)
        Centres (m), current velocities (m/s) and preferred velocities (m/s) of ``n`` agents,
        or of ``n`` agents in each of ``w`` independent worlds (agents of different worlds
        ignore each other). Rounded to float32, as RVO2 stores them.
    radius : float or array_like, shape (n,) or (w, n)
        Agent radii (m), >= 0.
    max_speed : float or array_like, shape (n,) or (w, n)
        Speed limits (m/s), >= 0: the new velocity is at most this long.
    dt : float
        Time step (s), > 0. Agents that already overlap aim to be apart after one step.
    neighbor_dist : float
        Only agents whose centres are closer than this (m), >= 0, are neighbours.
    max_neighbors : int
        At most this many nearest neighbours are avoided, >= 0.
    time_horizon : float
        The velocities chosen are collision-free with the neighbours' for this long (s), > 0.
    method : {"auto", "array", "numba"}
        The compiled path (numba, the ``fast`` extra), the numpy path, or the compiled path
        where it can run. Both give the same floats.

    Returns
    -------
    positions, velocities : ndarray of float64, the shape of ``positions``
        After the step: float32 values (RVO2's) held in float64 arrays.

    Raises
    ------
    ArgumentError
        An argument of the wrong shape, not finite, or out of its range.
    """
    check_method(method)
    pos = agents("positions", positions, None, np.float32)
    vel = agents("velocities", velocities, pos.shape, np.float32)
    pref = agents("preferred", preferred, pos.shape, np.float32)
    batched = pos.ndim == 3
    if not batched:
        pos, vel, pref = pos[None], vel[None], pref[None]
    shape = pos.shape[:2]
    radius_ = per_agent("radius", radius, shape, "m", np.float32)
    speed = per_agent("max_speed", max_speed, shape, "m/s", np.float32)
    step = np.float32(real("dt", dt, minimum=0.0, strict=True, unit="s"))
    dist = np.float32(real("neighbor_dist", neighbor_dist, minimum=0.0))
    k = integer("max_neighbors", max_neighbors, minimum=0)
    tau = np.float32(real("time_horizon", time_horizon, minimum=0.0, strict=True, unit="s"))
    if step == 0 or tau == 0:
        raise ArgumentError(f"dt and time_horizon must be at least float32's smallest step, got {dt!r}, {time_horizon!r}")
    params = np.array([step, dist * dist, np.float32(1.0) / tau], np.float32)
    fn = choose(method, *KERNEL)
    (fn or orca_array)(pos, vel, pref, radius_, speed, params, k)
    if not batched:
        pos, vel = pos[0], vel[0]
    return pos.astype(np.float64), vel.astype(np.float64)
