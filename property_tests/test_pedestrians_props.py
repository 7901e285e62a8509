"""No pedestrian ever starts overlapping a robot, a wall or another pedestrian (issue 33),
and the paths they walk keep their radius from the walls.

Random walled rooms with boxes, crowds of 0 to 14 with random radius ranges, robots of
random radii; the check (``tests/crowd_reference.py``) measures every distance to the wall
cells by brute force over their squares. The paths are measured with shapely.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
import shapely
from crowd_reference import RES, env_in, room, spawn_is_clear
from hypothesis import given, settings
from hypothesis import strategies as st

from pointnav_core.crowds.walks import MIN_GOAL_DISTANCE, WALK_PIECE, Walk, plan_walk
from pointnav_core.floor.draw import nearest_usable
from pointnav_core.scenes import Scene


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


#: A walk's random room (its seed and boxes) and the radius it is planned for (m).
WALKS = {"seed": st.integers(0, 2**31 - 1), "boxes": st.integers(0, 16), "radius": st.floats(0.1, 0.4)}


def _room(seed: int, boxes: int) -> tuple[np.ndarray, Scene]:
    grid = room(70, 50, boxes=boxes, seed=seed % 1000)
    return grid, Scene.from_array(grid, RES)


@settings(max_examples=25, deadline=None)
@given(**WALKS)
def test_a_pedestrians_path_keeps_its_radius_from_the_walls_and_turns_at_most_a_piece_at_a_time(
    seed: int, boxes: int, radius: float
) -> None:
    grid, scene = _room(seed, boxes)
    rng = np.random.default_rng(seed)
    here = scene.get_random_point(0, robot=radius, rng=rng)[1][:2]
    walk = Walk((), False, -1, here.copy())
    path = plan_walk(scene, 0, radius, here, walk, True, rng).points
    assert np.array_equal(path[0], here) and np.array_equal(path[-1], walk.goal)
    # Independent reference: every blocked square and the map's outside, as shapely geometry.
    h, w = grid.shape
    squares = [shapely.box(c * RES, r * RES, (c + 1) * RES, (r + 1) * RES) for r, c in np.argwhere(~grid)]
    outside = shapely.box(-1, -1, w * RES + 1, h * RES + 1).difference(shapely.box(0, 0, w * RES, h * RES))
    blocked = shapely.union_all([*squares, outside])
    pieces = shapely.linestrings(np.stack([path[:-1], path[1:]], axis=1)) if len(path) > 1 else []
    assert all(blocked.distance(piece) >= radius - 1e-9 for piece in pieces)
    # Drawn in pieces of at most WALK_PIECE: no bend between two steps turns more.
    steps = np.diff(path, axis=0)
    steps = steps[np.hypot(*steps.T) > 1e-9]
    heading = np.arctan2(steps[:, 1], steps[:, 0])
    turns = np.abs((np.diff(heading) + math.pi) % (2 * math.pi) - math.pi)
    assert (turns <= WALK_PIECE + 1e-9).all(), np.degrees(turns.max())


@settings(max_examples=40, deadline=None)
@given(**WALKS)
def test_a_pedestrians_new_goal_is_scene_get_random_points_draw_and_its_path_the_planners(
    seed: int, boxes: int, radius: float
) -> None:
    # plan_walk draws a goal from the component it finds on the way (draw_point) and skips
    # the reachability proof for it; by its definition the goal is Scene.get_random_point's
    # from where it plans (again while nearer than MIN_GOAL_DISTANCE, 10 tries), with the
    # same draws, and the path the planner's to it.
    _, scene = _room(seed, boxes)
    rng = np.random.default_rng(seed)
    here = rng.uniform((0.0, 0.0), (7.0, 5.0))  # anywhere: near walls, inside boxes, at corners
    ours, theirs = np.random.default_rng(seed + 1), np.random.default_rng(seed + 1)
    start = here if scene.is_usable(0, here, radius) else nearest_usable(scene.floors[0], here, radius)
    walk = Walk((), False, -1, here.copy())
    if start is None:
        assert len(plan_walk(scene, 0, radius, here, walk, True, ours).points) == 1
        return
    try:
        for _ in range(10):
            goal = scene.get_random_point(0, reference_point=start, robot=radius, rng=theirs)[1][:2]
            if math.dist(goal, start) >= MIN_GOAL_DISTANCE:
                break
    except ValueError as error:  # a start that sees no usable cell centre: the same refusal
        with pytest.raises(type(error), match=re.escape(str(error))):
            plan_walk(scene, 0, radius, here, walk, True, ours)
        return
    path = plan_walk(scene, 0, radius, here, walk, True, ours).points
    assert np.array_equal(walk.goal, goal)
    assert ours.bit_generator.state == theirs.bit_generator.state
    want, _ = scene.planner(0, radius).shortest_path(start, goal, WALK_PIECE)
    assert want is not None
    np.testing.assert_array_equal(path, want if start is here else np.concatenate([here[None], want]))
