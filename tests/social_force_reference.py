"""pysocialforce (the ``dev`` extra) driven like :func:`pointnav_core.crowds.social_force_step`,
and random crowds for both: the reference of ``tests/test_social_force.py``,
``property_tests/test_social_force_props.py`` and ``tests/pairs_crowds.py``.

pysocialforce's import sets the root logger to DEBUG and gives it a console handler and a
``file.log`` in the working folder; :func:`pysocialforce` imports it from a temporary folder
with logging off and puts the root logger back as it was.

pysocialforce 1.1.2's ``PedRepulsiveForce`` (Helbing and Molnár's repulsion, not among its
default forces) fails: ``PedPedPotential.grad_r_ab`` passes the pair returned by
``stateutils.desired_directions`` (directions, distances) where the directions are meant.
:func:`simulator` uses it with that one line corrected (:class:`_Potential`), the rest of
pysocialforce's code (its potential, finite differences and field of view) unchanged.
"""

from __future__ import annotations

import logging
import os
import tempfile
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import NDArray


def skip_without_reference() -> None:
    """Skip the calling test (or module) without pysocialforce, without importing it
    (``pytest.importorskip`` would, from the working folder)."""
    import importlib.util

    import pytest

    if importlib.util.find_spec("pysocialforce") is None:
        pytest.skip("the reference is in the dev extra", allow_module_level=True)


def pysocialforce() -> ModuleType:
    """pysocialforce, imported without touching the logging or the working folder."""
    root = logging.getLogger()
    level, handlers, here, disabled = root.level, list(root.handlers), os.getcwd(), root.manager.disable
    with tempfile.TemporaryDirectory() as folder:
        os.chdir(folder)
        logging.disable(logging.CRITICAL)
        try:
            import pysocialforce as psf
        finally:
            os.chdir(here)
            logging.disable(disabled)
            for handler in root.handlers[len(handlers):]:
                root.removeHandler(handler)
                handler.close()
            root.setLevel(level)
    return psf


@dataclass
class Crowd:
    """A crowd as both sides take it: pysocialforce's state rows (x, y, vx, vy, gx, gy)."""

    positions: NDArray[np.float64]
    velocities: NDArray[np.float64]
    goals: NDArray[np.float64]
    walls: NDArray[np.float64] | None = None  # (m, 2, 2) segments
    dt: float = 0.1


def random_crowd(rng: np.random.Generator, n: int, side: float, walls: int = 0, dt: float = 0.1) -> Crowd:
    """``n`` pedestrians and goals uniform in a ``side`` m square, initial speeds 0.5-1.2 m/s
    in random directions (pysocialforce's desired and max speed are 1.3 times them), and
    ``walls`` random segments in the square."""
    speed = rng.uniform(0.5, 1.2, n)
    angle = rng.uniform(-np.pi, np.pi, n)
    return Crowd(
        positions=rng.uniform(0.0, side, (n, 2)), velocities=np.stack([speed * np.cos(angle), speed * np.sin(angle)], -1),
        goals=rng.uniform(0.0, side, (n, 2)), walls=rng.uniform(0.0, side, (walls, 2, 2)) if walls else None, dt=dt,
    )


def simulator(crowd: Crowd, model: str = "moussaid") -> Any:
    """A pysocialforce ``Simulator`` of the crowd: its default forces (desired, Moussaid's
    social force, obstacles, and group forces that are zero without groups), or with
    ``PedRepulsiveForce`` (Helbing and Molnár) for the social force; ``step_width`` = dt."""
    psf = pysocialforce()
    walls = None if crowd.walls is None else [
        # pysocialforce's EnvState samples a segment shorter than 0.1 m to an empty (0,) array,
        # which ObstacleForce then cannot stack: such a segment has no point on both sides.
        (a[0], b[0], a[1], b[1])
        for a, b in crowd.walls if int(np.linalg.norm(a - b) * 10.0) > 0
    ]
    state = np.concatenate([crowd.positions, crowd.velocities, crowd.goals], axis=-1)
    sim = psf.Simulator(state.copy(), obstacles=walls)
    sim.peds.step_width = crowd.dt
    if model == "helbing_molnar":
        sim.forces = [psf.forces.DesiredForce(), psf.forces.PedRepulsiveForce(), psf.forces.ObstacleForce()]
        psf.forces.PedPedPotential = _potential_class(psf)
        for force in sim.forces:
            force.init(sim, sim.config)
    return sim


def _potential_class(psf: ModuleType) -> type:
    """pysocialforce's ``PedPedPotential`` with ``grad_r_ab`` taking the desired directions
    from ``stateutils.desired_directions``'s pair (its only change)."""
    stateutils = psf.utils.stateutils

    class _Potential(psf.potentials.PedPedPotential):  # type: ignore[misc, name-defined]
        def grad_r_ab(self, state: NDArray[np.float64], delta: float = 1e-3) -> NDArray[np.float64]:
            r_ab = self.r_ab(state)
            speeds = stateutils.speeds(state)
            desired_directions = stateutils.desired_directions(state)[0]  # [0]: the correction
            dx = np.array([[[delta, 0.0]]])
            dy = np.array([[[0.0, delta]]])
            v = self.value_r_ab(r_ab, speeds, desired_directions)
            dvdx = (self.value_r_ab(r_ab + dx, speeds, desired_directions) - v) / delta
            dvdy = (self.value_r_ab(r_ab + dy, speeds, desired_directions) - v) / delta
            np.fill_diagonal(dvdx, 0.0)
            np.fill_diagonal(dvdy, 0.0)
            return np.stack((dvdx, dvdy), axis=-1)

    return _Potential


def worst_gap(
    crowd: Crowd, steps: int, methods: tuple[str, ...] = ("auto",), model: str = "moussaid", **mine: Any
) -> float:
    """The largest difference (m, m/s) between social_force_step's positions and velocities,
    on each of ``methods``, and pysocialforce's over ``steps`` steps. ``mine`` overrides
    social_force_step's arguments."""
    from pointnav_core.crowds import social_force_step

    sim = simulator(crowd, model)
    speed = sim.peds.max_speeds.copy()  # 1.3 x the initial speeds, both desired and max
    args = {"speed": speed, "max_speed": speed, "dt": crowd.dt, "model": model, "walls": crowd.walls, **mine}
    states = {method: (crowd.positions, crowd.velocities) for method in methods}
    worst = 0.0
    for _ in range(steps):
        with np.errstate(divide="ignore", invalid="ignore"):  # pysocialforce divides by zero speeds
            sim.step()
        for method, (pos, vel) in states.items():
            pos, vel = states[method] = social_force_step(pos, vel, crowd.goals, method=method, **args)
            worst = max(worst, float(np.abs(pos - sim.peds.pos()).max()), float(np.abs(vel - sim.peds.vel()).max()))
    return worst
