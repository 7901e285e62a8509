"""Plain and compiled paths of :func:`pointnav_core.crowds.orca_step`,
:func:`pointnav_core.crowds.social_force_step` and an ORCA crowd's step
(:meth:`pointnav_core.crowds.Crowd.step_contacts`): the checks of
``property_tests/test_compiled_paths.py`` for ``crowds._orca_kernel``,
``crowds._social_force_kernel`` and ``crowds._crowd_kernel``.

Both paths give the same floats, bit for bit, on random crowds in batches of worlds (one
to 30 agents, more than RVO2's k-d tree leaf of 10), with per-agent radii and speeds, ties of
distances (agents on a grid) and overlaps, over several steps. Each is also checked against
RVO2 itself (``tests/test_orca.py``, ``property_tests/test_orca_props.py``).

The crowd's step gives the same floats on both paths, bit for bit, over whole env rollouts:
random walled rooms with boxes (and the default house, whose furniture is polygons), random
crowds, radius and speed ranges, ORCA settings, with and without seeing the robot, under
random actions and resets; every step's positions, velocities, headings, goals, next
waypoints and contact count are compared.
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager
from unittest import mock

import numpy as np
from crowd_reference import env_in, room, world_episode
from hypothesis import given, settings
from hypothesis import strategies as st
from orca_reference import preferred, random_crowd
from social_force_reference import random_crowd as random_pedestrians

from pointnav_core import scenes
from pointnav_core.crowds import orca_step, social_force_step
from pointnav_core.crowds.crowd import KERNEL as CROWD_KERNEL
from pointnav_core.crowds.crowd import Crowd
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.utils.compiled import kernel
from pointnav_core.vector import VectorPointNavEnv

Plain = Callable[[], AbstractContextManager[None]]


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    worlds=st.integers(1, 3),
    n=st.integers(1, 30),
    side=st.floats(0.5, 10.0),
    snap=st.sampled_from([0.0, 0.5]),
    max_neighbors=st.integers(0, 12),
    time_horizon=st.floats(0.1, 5.0),
    steps=st.integers(1, 10),
)
def check_orca(
    seed: int, worlds: int, n: int, side: float, snap: float, max_neighbors: int, time_horizon: float, steps: int,
    plain_paths: Plain,
) -> None:
    """orca_step with its kernel and inside ``plain_paths()``."""
    rng = np.random.default_rng(seed)
    crowds = [random_crowd(rng, n, side, snap) for _ in range(worlds)]
    pos, vel, goals, radius, speed = (
        np.stack([getattr(c, name) for c in crowds]) for name in ("positions", "velocities", "goals", "radius", "max_speed")
    )
    args = (radius, speed, 0.1, 4.0, max_neighbors, time_horizon)
    got = want = (pos, vel)
    for _ in range(steps):
        pref = np.stack([preferred(p, g) for p, g in zip(got[0], goals)])
        got = orca_step(*got, pref, *args)
        with plain_paths():
            assert kernel("pointnav_core.crowds._orca_kernel", "orca_worlds") is None
            want = orca_step(*want, pref, *args)
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])
    assert kernel("pointnav_core.crowds._orca_kernel", "orca_worlds") is not None


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    worlds=st.integers(1, 3),
    n=st.integers(1, 20),
    side=st.floats(0.5, 10.0),
    walls=st.integers(0, 3),
    model=st.sampled_from(["moussaid", "helbing_molnar"]),
    steps=st.integers(1, 10),
)
def check_social_force(
    seed: int, worlds: int, n: int, side: float, walls: int, model: str, steps: int, plain_paths: Plain,
) -> None:
    """social_force_step with its kernel and inside ``plain_paths()``: within 1e-9 m (and
    m/s). Not bit for bit: numpy's ``exp`` and ``arctan2`` and the C library's, which the
    kernel calls, differ in the last bit for some arguments; the sums run in the same order."""
    rng = np.random.default_rng(seed)
    crowds = [random_pedestrians(rng, n, side, walls) for _ in range(worlds)]
    pos, vel, goals = (np.stack([getattr(c, name) for c in crowds]) for name in ("positions", "velocities", "goals"))
    segments = np.stack([c.walls for c in crowds]) if walls else None
    speed = rng.uniform(0.5, 1.5, (worlds, n))
    args = (goals, speed, 1.3 * speed, 0.1)
    got = want = (pos, vel)
    for _ in range(steps):
        got = social_force_step(*got, *args, model=model, walls=segments)
        with plain_paths():
            assert kernel("pointnav_core.crowds._social_force_kernel", "social_force_worlds") is None
            want = social_force_step(*want, *args, model=model, walls=segments)
        np.testing.assert_allclose(got[0], want[0], rtol=0, atol=1e-9)
        np.testing.assert_allclose(got[1], want[1], rtol=0, atol=1e-9)
    assert kernel("pointnav_core.crowds._social_force_kernel", "social_force_worlds") is not None


_HOUSE: list[scenes.Scene] = []  # the default house, built once


def _crowd_rollout(seed: int, house: bool, pedestrians: dict, steps: int) -> np.ndarray:
    """Every step's crowd state and contact count, one row per step, of an env rollout
    under random actions (a new episode where one ends)."""
    if house:
        if not _HOUSE:
            _HOUSE.append(scenes.rooms(seed=0))
        env = PointNavEnv(scene=_HOUSE[0], pedestrians=pedestrians)
    else:
        env = env_in(room(60, 40, boxes=seed % 8, seed=seed % 1000), pedestrians=pedestrians)
    env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(steps):
        _, _, terminated, truncated, info = env.step(rng.uniform(-1.0, 1.0, 2).astype(np.float32))
        c = env.crowd
        rows.append(np.concatenate([c.positions.ravel(), c.velocities.ravel(), c.headings, c.goals.ravel(),
                                    c._next, [info["pedestrian_collisions"]]]))
        if terminated or truncated:
            env.reset()
    return np.array(rows)


def assert_same_plan(own: np.ndarray, path: np.ndarray) -> None:
    """Two sides' plans of one pedestrian: equal within 1e-9 m, or, where one side draws an
    arc in one piece more (its angle rounds across a piece's), the same ends and length."""
    if own.shape == path.shape:
        np.testing.assert_allclose(own, path, rtol=0, atol=1e-9)
        return
    np.testing.assert_allclose(own[[0, -1]], path[[0, -1]], rtol=0, atol=1e-9)
    lengths = [np.linalg.norm(np.diff(p, axis=0), axis=1).sum() for p in (own, path)]
    assert abs(lengths[0] - lengths[1]) <= 1e-6, lengths


@settings(max_examples=15, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    house=st.booleans(),
    count=st.integers(1, 12),
    low=st.floats(0.1, 0.3),
    spread=st.floats(0.0, 0.15),
    speed=st.tuples(st.floats(0.0, 1.0), st.floats(0.0, 1.0)).map(sorted),
    sees_robots=st.booleans(),
    max_neighbors=st.integers(0, 12),
    time_horizon=st.floats(0.2, 5.0),
    steps=st.integers(1, 80),
)
def check_crowd_step(
    seed: int, house: bool, count: int, low: float, spread: float, speed: list[float], sees_robots: bool,
    max_neighbors: int, time_horizon: float, steps: int, plain_paths: Plain,
) -> None:
    """An env's ORCA crowd stepped by its kernel and inside ``plain_paths()``: bit for bit."""
    pedestrians = {"count": count, "radius": (low, low + spread), "speed": tuple(speed), "sees_robots": sees_robots,
                   "orca": {"max_neighbors": max_neighbors, "time_horizon": time_horizon}}
    # Every step of the compiled side goes through the kernel (else the check compares the
    # numpy path with itself).
    plan, plans = Crowd._plan, []

    def recorded(crowd: Crowd, i: int, *args: object) -> np.ndarray:
        plans.append((i, path := plan(crowd, i, *args)))
        return path

    with mock.patch.object(Crowd, "_step_compiled", autospec=True, side_effect=Crowd._step_compiled) as compiled, \
            mock.patch.object(Crowd, "_plan", recorded):
        got = _crowd_rollout(seed, house, pedestrians, steps)
    assert compiled.call_count == steps

    # The plain side plans with the plain geometry, whose drawn paths may differ from the
    # compiled ones in the last bit (pairs_geodesic holds them within 1e-9 m), and a
    # pedestrian can land exactly on a waypoint: it walks the compiled side's plans, once
    # they are checked equal to its own, so that the crowd's step is compared bit for bit.
    def replayed(crowd: Crowd, i: int, *args: object) -> np.ndarray:
        own = plan(crowd, i, *args)
        j, path = plans.pop(0)
        assert j == i
        assert_same_plan(own, path)
        return path.copy()

    with plain_paths(), mock.patch.object(Crowd, "_plan", replayed):
        assert kernel(*CROWD_KERNEL) is None
        want = _crowd_rollout(seed, house, pedestrians, steps)
    assert plans == []
    np.testing.assert_array_equal(got, want)
    assert kernel(*CROWD_KERNEL) is not None


@settings(max_examples=10, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    count=st.integers(1, 10),
    worlds=st.integers(1, 4),
    sees_robots=st.booleans(),
    steps=st.integers(1, 60),
)
def check_crowd_worlds(seed: int, count: int, worlds: int, sees_robots: bool, steps: int, plain_paths: Plain) -> None:
    """The batched engine's crowds (``orca_crowd_worlds``, all worlds in one call) against
    one single env per world on the plain path: bit for bit, step for step. The single
    envs are placed from the worlds' records (on the compiled path, as the engine placed
    them) and walk the engine's plans of each step, once checked within 1e-9 m of their
    own (the plain geometry's paths may differ in the last bits; see ``check_crowd_step``)."""
    import pointnav_core.vector.crowd as batched

    grid = room(60, 40, boxes=seed % 6, seed=seed % 1000)
    scene = scenes.Scene.from_array(np.where(grid, 0, 1).astype(np.uint8), 0.1)
    pedestrians = {"count": count, "sees_robots": sees_robots}
    venv = VectorPointNavEnv(worlds, scene=scene, seed=seed, pedestrians=pedestrians, pool_size=2)
    venv.reset(seed=seed)
    singles = []
    for w in range(worlds):
        env = PointNavEnv(scene=scene, flatten_obs=True, pedestrians=pedestrians)
        env.reset(seed=w, options={"episode": world_episode(venv, w)})
        singles.append(env)
    # This step's plans, by where the pedestrian stood (worlds of one episode plan alike).
    plans: dict[bytes, list[np.ndarray]] = {}
    walk = batched.plan_walk

    def recorded(*args: object) -> object:
        planned = walk(*args)
        plans.setdefault(np.asarray(args[3]).tobytes(), []).append(planned.points)
        return planned

    plan = Crowd._plan

    def replayed(crowd: Crowd, i: int, *args: object) -> np.ndarray:
        own, key = plan(crowd, i, *args), crowd.positions[i].tobytes()
        path = plans[key].pop(0)
        if not plans[key]:
            del plans[key]
        assert_same_plan(own, path)
        return path.copy()

    actions = np.random.default_rng(seed).uniform(-1.0, 1.0, (steps, worlds, 2)).astype(np.float32)
    live = [True] * worlds
    for t, act in enumerate(actions):
        with mock.patch.object(batched, "plan_walk", recorded):
            venv.step(act)
        with plain_paths(), mock.patch.object(Crowd, "_plan", replayed):
            assert kernel(*CROWD_KERNEL) is None
            for w, env in enumerate(singles):
                if live[w]:
                    _, _, terminated, truncated, _ = env.step(act[w])
                    live[w] = not (terminated or truncated)
                    k, where = env.crowd.n, f"world {w}, step {t}"
                    np.testing.assert_array_equal(venv.crowd.positions[w, :k], env.crowd.positions, err_msg=where)
                    np.testing.assert_array_equal(venv.crowd.velocities[w, :k], env.crowd.velocities, err_msg=where)
        if all(live):
            assert plans == {}, "a plan of the engine's that no single env made"
        plans.clear()
