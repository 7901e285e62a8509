"""No pedestrian ever starts overlapping a robot, a wall or another pedestrian (issue 33).

Random walled rooms with boxes, crowds of 0 to 14 with random radius ranges, robots of
random radii; the check (``tests/crowd_reference.py``) measures every distance to the wall
cells by brute force over their squares.
"""

from __future__ import annotations

from crowd_reference import env_in, room, spawn_is_clear
from hypothesis import given, settings
from hypothesis import strategies as st


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    count=st.integers(0, 14),
    low=st.floats(0.05, 0.3),
    spread=st.floats(0.0, 0.2),
    boxes=st.integers(0, 12),
    robot_radius=st.floats(0.1, 0.4),
)
def test_pedestrians_start_clear_of_walls_robots_and_each_other(
    seed: int, count: int, low: float, spread: float, boxes: int, robot_radius: float
) -> None:
    grid = room(70, 50, boxes=boxes, seed=seed % 1000)
    env = env_in(grid, robot={"radius": robot_radius}, pedestrians={"count": count, "radius": (low, low + spread)})
    env.reset(seed=seed)
    assert env.crowd.n == count
    spawn_is_clear(grid, env)
