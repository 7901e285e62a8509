"""The oracle (ShortestPathFollower) reaches its goals on every backend.

A quick version of ``benchmarks/bench_oracle.py`` (200 episodes per backend, where the
targets are success >= 97 % and mean SPL >= 0.85 on pymunk): a few episodes in generated
``rooms`` houses through ``pointnav_core.cli.run_demo``, the code behind ``pointnav demo``.
"""

from __future__ import annotations

import pytest

from pointnav_core import scenes
from pointnav_core.backend import available_backends
from pointnav_core.cli import run_demo
from pointnav_core.env import PointNavEnv
from pointnav_core.policies import ShortestPathFollower

BACKENDS = available_backends()


@pytest.mark.parametrize("drive", ["differential", "holonomic"])
@pytest.mark.parametrize("backend", BACKENDS)
def test_oracle_reaches_most_goals_in_generated_houses(backend, drive):
    summary = run_demo(episodes=10, seed=1, houses=2, backend=backend, drive=drive, progress=False)
    assert summary["episodes"] == 10
    assert summary["success"] >= 0.9
    assert summary["spl"] >= 0.8
    assert 0.0 <= summary["soft_spl"] <= 1.0


@pytest.mark.parametrize("backend", BACKENDS)
def test_holonomic_oracle_does_not_cycle_between_two_cheap_paths(backend):
    # From neighbouring points near (-0.77, -0.9) the goal field's cheap paths (each cell's
    # root) lead in opposite directions, and a holonomic robot, which moves at once, used to
    # step back and forth between them until the timeout.
    env = PointNavEnv(
        scene=scenes.rooms(seed=2),
        robot={"drive": "holonomic"},
        task={"termination_config": {"max_steps": 1000}},
        backend=backend,
    )
    _, info = env.reset(seed=100_006)
    d0 = info["geodesic_dist"]
    oracle = ShortestPathFollower(env)
    done = False
    while not done:
        _, _, terminated, truncated, info = env.step(oracle.act())
        done = terminated or truncated
    assert info["success"] is True
    assert info["path_length"] < d0 + 1.0
