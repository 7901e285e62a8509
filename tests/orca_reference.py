"""RVO2 (``pyrvo``, the ``dev`` extra) driven like :func:`pointnav_core.crowds.orca_step`,
and random crowds for both: the reference of ``tests/test_orca.py``,
``property_tests/test_orca_props.py`` and ``tests/pairs_crowds.py``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray


@dataclass
class Crowd:
    """A crowd and ORCA's parameters, as both sides take them."""

    positions: NDArray[np.float64]
    velocities: NDArray[np.float64]
    radius: NDArray[np.float64]
    max_speed: NDArray[np.float64]
    goals: NDArray[np.float64]
    dt: float = 0.1
    neighbor_dist: float = 5.0
    max_neighbors: int = 10
    time_horizon: float = 2.0

    def args(self) -> tuple[object, ...]:
        """orca_step's arguments after (positions, velocities, preferred)."""
        return self.radius, self.max_speed, self.dt, self.neighbor_dist, self.max_neighbors, self.time_horizon


def random_crowd(rng: np.random.Generator, n: int, side: float, snap: float = 0.0) -> Crowd:
    """``n`` agents and goals uniform in a ``side`` m square (on a ``snap`` m grid, distinct
    cells, when ``snap`` > 0: exact ties of distances), radii 0.2-0.35 m, speeds 1-1.6 m/s."""
    if snap > 0:
        cells = max(int(side / snap), 1)
        pick = rng.choice(max(cells * cells, n), n, replace=False)
        positions = np.stack([pick % cells, pick // cells], axis=-1) * snap
    else:
        positions = rng.uniform(0.0, side, (n, 2))
    return Crowd(
        positions=positions, velocities=rng.uniform(-1.0, 1.0, (n, 2)), radius=rng.uniform(0.2, 0.35, n),
        max_speed=rng.uniform(1.0, 1.6, n), goals=rng.uniform(0.0, side, (n, 2)),
    )


def preferred(positions: NDArray[np.float64], goals: NDArray[np.float64]) -> NDArray[np.float64]:
    """Towards the goal at 1 m/s, slower within 1 m of it (RVO2's examples' rule)."""
    d = goals - positions
    length = np.hypot(d[:, 0], d[:, 1])[:, None]
    return np.where(length > 1.0, d / np.maximum(length, 1e-12), d)


class Reference:
    """One ``pyrvo.RVOSimulator`` holding the crowd (``time_horizon_obst`` = ``time_horizon``,
    no obstacles)."""

    def __init__(self, crowd: Crowd) -> None:
        import pyrvo

        self.sim = pyrvo.RVOSimulator()
        self.sim.set_time_step(crowd.dt)
        self.n = len(crowd.positions)
        for i in range(self.n):
            self.sim.add_agent(
                tuple(map(float, crowd.positions[i])), crowd.neighbor_dist, crowd.max_neighbors,
                crowd.time_horizon, crowd.time_horizon, float(crowd.radius[i]), float(crowd.max_speed[i]),
                tuple(map(float, crowd.velocities[i])),
            )

    def step(self, pref: NDArray[np.float64]) -> None:
        for i in range(self.n):
            self.sim.set_agent_pref_velocity(i, (float(pref[i, 0]), float(pref[i, 1])))
        self.sim.do_step()

    def positions(self) -> NDArray[np.float64]:
        return np.array([self.sim.get_agent_position(i).to_tuple() for i in range(self.n)])

    def velocities(self) -> NDArray[np.float64]:
        return np.array([self.sim.get_agent_velocity(i).to_tuple() for i in range(self.n)])


def worst_gap(crowd: Crowd, steps: int, method: str = "auto", mine: dict[str, float] | None = None) -> float:
    """The largest difference (m, m/s) between orca_step's positions and velocities and
    RVO2's over ``steps`` steps, each agent walking to its goal (preferred velocities from
    RVO2's positions, given to both sides). ``mine`` changes orca_step's parameters only."""
    from dataclasses import replace

    from pointnav_core.crowds import orca_step

    ref = Reference(crowd)
    args = replace(crowd, **(mine or {})).args()
    pos, vel = crowd.positions, crowd.velocities
    worst = 0.0
    for _ in range(steps):
        pref = preferred(ref.positions(), crowd.goals)
        ref.step(pref)
        pos, vel = orca_step(pos, vel, pref, *args, method=method)
        worst = max(worst, float(np.abs(pos - ref.positions()).max()), float(np.abs(vel - ref.velocities()).max()))
    return worst
