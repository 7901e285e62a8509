"""Visual markers: VisualMarker values, waypoint placement, and the task's marker state.

Pixels are checked in ``test_render.py``; here the markers are checked as data: where they
are, which are shown, that they follow the path step by step, that they are hidden when
there is no path, and that they change nothing else (and cost nothing when off).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import pointnav_core.task.markers as markers_module
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.floor.maps import FREE, OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.task import TaskState
from pointnav_core.task.markers import MARKER_KINDS, VisualMarker, place_waypoints

RES = 0.1
ROBOT = RobotSpec(radius=0.1)
FORWARD = np.array([1.0, 0.0], dtype=np.float32)
TURN = np.array([0.6, 1.0], dtype=np.float32)
START, GOAL = (1.0, 1.0), (5.0, 1.5)


def room(rows: int = 20, cols: int = 60) -> np.ndarray:
    """A walled room: free inside x in (0.1, cols/10 - 0.1), y in (0.1, rows/10 - 0.1)."""
    grid = np.full((rows, cols), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return grid


def two_rooms() -> np.ndarray:
    """``room()`` cut in two by a wall at x in [3.0, 3.1): nothing crosses it."""
    grid = room()
    grid[:, 30] = OBSTACLE
    return grid


def with_pillar() -> np.ndarray:
    """``room()`` with a pillar between START and GOAL, so that the path bends."""
    grid = room()
    grid[5:20, 28:32] = OBSTACLE
    return grid


def make_env(grid=None, heights=None, **task) -> PointNavEnv:
    grid = with_pillar() if grid is None else grid
    scene = Scene.from_array(grid, RES, heights=heights)
    task.setdefault("initial_pos", START)
    task.setdefault("goal_pos", GOAL)
    return PointNavEnv(scene=scene, robot=ROBOT, task=task)


def distance_to_polyline(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """Distance (m) from each of ``points`` (M, 2) to the polyline (N, 2)."""
    points = np.atleast_2d(points)
    if len(polyline) == 1:
        return np.hypot(*(points - polyline[0]).T)
    a, b = polyline[:-1], polyline[1:]
    ab = b - a
    t = np.einsum("mnk,nk->mn", points[:, None] - a, ab) / np.maximum((ab * ab).sum(1), 1e-300)
    closest = a + np.clip(t, 0.0, 1.0)[..., None] * ab
    return np.hypot(*(points[:, None] - closest).transpose(2, 0, 1)).min(axis=1)


def cheap_path(env: PointNavEnv) -> np.ndarray | None:
    """The path the task marks: the goal field's cheap path from the robot (public API)."""
    task = env.task
    xy = task.get_current_pos(env)[:2]
    field = env.scene.goal_field(task.floor, task.get_goal_pos(), robot=env.robot)
    return field.path(xy, exact=False)[0]


def waypoints(task) -> list[VisualMarker]:
    return [m for m in task.markers if m.kind == "waypoint"]


# ------------------------------------------------------------------------------ VisualMarker


def test_visual_marker_stores_floats_and_is_frozen():
    marker = VisualMarker(kind="start", position=np.array([1, 2, 3]), radius=1, visible=np.True_)
    assert marker.position == (1.0, 2.0, 3.0) and type(marker.position[0]) is float
    assert marker.radius == 1.0 and type(marker.radius) is float
    assert marker.visible is True
    with pytest.raises(dataclasses.FrozenInstanceError):
        marker.radius = 2.0  # type: ignore[misc]


def test_visual_marker_is_keyword_only():
    with pytest.raises(TypeError):
        VisualMarker("goal", (0.0, 0.0, 0.0), 0.5)  # type: ignore[misc]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"kind": "flag"}, r"kind must be one of \['start', 'goal', 'waypoint'\], got 'flag'"),
        ({"kind": None}, "kind must be one of"),
        ({"position": (0.0, 0.0)}, "position must be a finite"),
        ({"position": (0.0, math.nan, 0.0)}, "position must be a finite"),
        ({"position": "abc"}, "position must be a finite"),
        ({"radius": -0.1}, "radius must be a finite number >= 0"),
        ({"radius": math.inf}, "radius must be a finite number >= 0"),
        ({"radius": True}, "radius must be a finite number >= 0"),
        ({"visible": 1}, "visible must be True or False"),
    ],
)
def test_visual_marker_rejects_bad_fields_naming_them(kwargs, match):
    fields = {"kind": "goal", "position": (0.0, 0.0, 0.0), "radius": 0.5, **kwargs}
    with pytest.raises(ValueError, match=match):
        VisualMarker(**fields)


def test_marker_kinds_are_start_goal_waypoint():
    assert MARKER_KINDS == ("start", "goal", "waypoint")


# ------------------------------------------------------------------------------ place_waypoints


def point_at_arc(polyline: np.ndarray, s: float) -> np.ndarray:
    """Reference: walk the polyline to arc length ``s`` (clamped to its end)."""
    for a, b in zip(polyline[:-1], polyline[1:]):
        seg = math.hypot(*(b - a))
        if s <= seg and seg > 0.0:
            return a + (s / seg) * (b - a)
        s -= seg
    return polyline[-1]


@st.composite
def polylines(draw: st.DrawFn) -> np.ndarray:
    n = draw(st.integers(1, 6))
    coords = st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False)
    return np.array([[draw(coords), draw(coords)] for _ in range(n)])


@given(polylines(), st.integers(1, 12), st.floats(0.05, 2.0))
def test_waypoints_lie_on_the_path_at_even_arc_lengths_and_show_a_prefix(path, count, spacing):
    xy, shown = place_waypoints(path, count, spacing)
    assert xy.shape == (count, 2) and xy.dtype == np.float64
    assert shown.shape == (count,) and shown.dtype == np.bool_
    assert distance_to_polyline(xy, path).max() < 1e-9
    # A prefix is shown: nothing shown after the first hidden one.
    n_shown = int(shown.sum())
    assert shown[:n_shown].all() and not shown[n_shown:].any()
    length = float(np.hypot(*np.diff(path, axis=0).T).sum()) if len(path) > 1 else 0.0
    s = max(spacing, length / (count + 1))
    for k in range(1, count + 1):
        np.testing.assert_allclose(xy[k - 1], point_at_arc(path, k * s), atol=1e-9)
        if k * s < length - 1e-6:
            assert shown[k - 1]
        elif k * s > length - 1e-12:
            assert not shown[k - 1]
            np.testing.assert_allclose(xy[k - 1], path[-1], atol=1e-9)


def test_a_long_path_is_marked_evenly_over_its_whole_length():
    xy, shown = place_waypoints([[0.0, 0.0], [0.0, 3.0], [4.0, 3.0]], 6, 0.2)
    assert shown.all()
    # Length 7 m, 7 gaps of 1 m: from 1 m past the robot to 1 m before the goal.
    np.testing.assert_allclose(xy, [[0, 1], [0, 2], [0, 3], [1, 3], [2, 3], [3, 3]], atol=1e-12)


def test_a_short_path_keeps_min_spacing_and_hides_the_rest_at_the_goal():
    xy, shown = place_waypoints([[0.0, 0.0], [0.7, 0.0]], 10, 0.2)
    assert shown.tolist() == [True] * 3 + [False] * 7
    np.testing.assert_allclose(xy[:3, 0], [0.2, 0.4, 0.6], atol=1e-12)
    np.testing.assert_allclose(xy[3:], np.tile([0.7, 0.0], (7, 1)))


def test_no_waypoint_sits_on_the_goal_even_when_the_spacing_divides_the_path():
    # 0.6 m at 0.2 m: the third would be on the goal; it is hidden.
    assert place_waypoints([[0.0, 0.0], [0.6, 0.0]], 5, 0.2)[1].tolist() == [True, True] + [False] * 3
    # 1.1 m and 10 waypoints would be 0.1 m apart: min_spacing (0.2 m) wins, 5 are shown.
    assert place_waypoints([[0.0, 0.0], [1.1, 0.0]], 10, 0.2)[1].sum() == 5


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (([[0.0, 0.0, 0.0]], 3, 0.2), "path must be a finite"),
        ((np.zeros((0, 2)), 3, 0.2), "path must be a finite"),
        (([[0.0, math.nan]], 3, 0.2), "path must be a finite"),
        (([[0.0, 0.0]], 0, 0.2), "count must be an integer >= 1"),
        (([[0.0, 0.0]], 2.5, 0.2), "count must be an integer >= 1"),
        (([[0.0, 0.0]], True, 0.2), "count must be an integer >= 1"),
        (([[0.0, 0.0]], 3, 0.0), "min_spacing must be a finite number > 0"),
        (([[0.0, 0.0]], 3, math.inf), "min_spacing must be a finite number > 0"),
    ],
)
def test_place_waypoints_rejects_bad_arguments(args, match):
    with pytest.raises(ValueError, match=match):
        place_waypoints(*args)


# ------------------------------------------------------------------------------ the task's markers


def test_no_markers_when_visualisation_is_off():
    env = make_env()
    assert env.task.markers == ()
    env.reset(seed=0)
    env.step(FORWARD)
    assert env.task.markers == ()


def test_no_markers_before_the_first_reset():
    env = make_env(visualize_goal=True, visualize_path=True)
    assert env.task.markers == ()


def test_start_and_goal_markers_with_visualize_goal():
    env = make_env(visualize_goal=True, goal_tolerance=0.4, goal_height=0.07)
    env.reset(seed=0)
    start, goal = env.task.markers
    assert (start.kind, goal.kind) == ("start", "goal")
    assert start.position == pytest.approx((*START, 0.07))
    assert goal.position == pytest.approx((*GOAL, 0.07))
    np.testing.assert_allclose(start.position[:2], env.task.get_start_pos()[:2])
    np.testing.assert_allclose(goal.position[:2], env.task.get_goal_pos()[:2])
    assert start.radius == goal.radius == 0.4
    assert start.visible and goal.visible
    # They stay put while the robot drives.
    env.step(FORWARD)
    assert env.task.markers == (start, goal)


def test_sampled_episodes_put_start_and_goal_markers_at_the_sampled_positions():
    env = PointNavEnv(task={"visualize_goal": True})
    for seed in range(3):
        env.reset(seed=seed)
        start, goal = env.task.markers
        np.testing.assert_allclose(start.position[:2], env.task.get_start_pos()[:2])
        np.testing.assert_allclose(goal.position[:2], env.task.get_goal_pos()[:2])


def test_marker_heights_are_above_the_tasks_floor():
    env = make_env([room(), with_pillar()], heights=[0.0, 3.0], floor=1,
                   visualize_goal=True, visualize_path=True, goal_height=0.06, waypoint_height=0.05)
    env.reset(seed=0)
    zs = {m.kind: m.position[2] for m in env.task.markers}
    assert zs == {"start": pytest.approx(3.06), "goal": pytest.approx(3.06), "waypoint": pytest.approx(3.05)}


def test_waypoint_markers_follow_the_path_from_the_robot_after_every_step():
    env = make_env(visualize_path=True, n_vis_waypoints=7, waypoint_width=0.08)
    env.reset(seed=0)
    previous = None
    for step in range(40):
        marks = waypoints(env.task)
        assert len(marks) == len(env.task.markers) == 7
        assert all(m.radius == 0.08 and m.position[2] == pytest.approx(0.05) for m in marks)
        path = cheap_path(env)
        xy = np.array([m.position[:2] for m in marks])
        expected_xy, expected_shown = place_waypoints(path, 7, env.scene.waypoint_spacing)
        np.testing.assert_allclose(xy, expected_xy, atol=1e-12)
        assert [m.visible for m in marks] == expected_shown.tolist()
        assert distance_to_polyline(xy, path).max() < 1e-9
        if previous is not None:
            assert marks != previous  # the robot moved, so did the path's waypoints
        previous = marks
        _, _, terminated, truncated, _ = env.step(TURN if step % 3 else FORWARD)
        assert not (terminated or truncated)


def test_the_path_bends_around_the_pillar_and_so_do_the_waypoints():
    env = make_env(visualize_path=True)
    env.reset(seed=0)
    xy = np.array([m.position[:2] for m in waypoints(env.task) if m.visible])
    assert len(xy) == 10
    # Straight from START to GOAL would cross the pillar (x in [2.8, 3.2), y >= 0.5); the
    # marked path passes below it.
    near_pillar = xy[(xy[:, 0] > 2.6) & (xy[:, 0] < 3.4)]
    assert len(near_pillar) and (near_pillar[:, 1] < 0.5).all()


def test_waypoints_are_hidden_near_the_goal_and_all_shown_far_from_it():
    env = make_env(room(), visualize_path=True, n_vis_waypoints=10,
                   initial_pos=(4.0, 1.0), goal_pos=(4.7, 1.0), goal_tolerance=0.1)
    env.reset(seed=0)
    assert [m.visible for m in env.task.markers] == [True] * 3 + [False] * 7
    env2 = make_env(room(), visualize_path=True, initial_pos=(1.0, 1.0), goal_pos=(5.0, 1.0))
    env2.reset(seed=0)
    assert all(m.visible for m in env2.task.markers)


def test_waypoints_are_hidden_not_a_crash_when_the_goal_is_unreachable():
    env = make_env(two_rooms(), visualize_goal=True, visualize_path=True,
                   initial_pos=(1.0, 1.0), goal_pos=(5.0, 1.0))
    _, info = env.reset(seed=0)
    assert info["geodesic_dist"] == math.inf
    start, goal, *marks = env.task.markers
    assert start.visible and goal.visible
    assert len(marks) == 10 and not any(m.visible for m in marks)
    for _ in range(5):
        env.step(FORWARD)
        assert len(env.task.markers) == 12
        assert not any(m.visible for m in waypoints(env.task))


def test_waypoints_hide_when_the_robot_loses_its_path_and_come_back_with_it(monkeypatch):
    env = make_env(visualize_path=True)
    env.reset(seed=0)
    assert any(m.visible for m in env.task.markers)
    before = env.task.markers
    field = env.task.goal_field  # the field the task holds: make it find no path once
    real_path = field.path
    monkeypatch.setattr(field, "path", lambda xy, exact=True: (None, math.inf))
    env.step(FORWARD)
    hidden = env.task.markers
    assert not any(m.visible for m in hidden)
    assert [m.position for m in hidden] == [m.position for m in before]  # kept, just hidden
    monkeypatch.setattr(field, "path", real_path)
    env.step(FORWARD)
    assert all(m.visible for m in env.task.markers)


def test_markers_is_the_same_tuple_until_the_next_step():
    env = make_env(visualize_goal=True, visualize_path=True)
    env.reset(seed=0)
    first = env.task.markers
    assert env.task.markers is first
    env.step(FORWARD)
    assert env.task.markers is not first
    assert env.task.markers[:2] == first[:2]


def test_a_failed_reset_clears_the_markers():
    env = make_env(visualize_goal=True, visualize_path=True)
    task = env.task
    env.reset(seed=0)
    assert len(task.markers) == 12
    small = PointNavEnv(scene=Scene.from_array(room(20, 20), RES), robot=ROBOT)  # 2 m: GOAL is off it
    with pytest.raises(ValueError, match="goal_pos"):
        task.reset(small)
    assert task.state is TaskState.ERROR
    assert task.markers == ()


def test_markers_change_nothing_else_in_an_episode():
    # Markers are not part of the world: the same seeded episode and actions give the same
    # observations, rewards and infos with visualisation on or off.
    rng = np.random.default_rng(0)
    actions = rng.uniform(-1.0, 1.0, size=(120, 2)).astype(np.float32)
    runs = []
    for flags in ({}, {"visualize_goal": True, "visualize_path": True}):
        env = PointNavEnv(task={**flags, "goal_tolerance": 0.2})
        trace = [env.reset(seed=3)]
        for action in actions:
            obs, reward, terminated, truncated, info = env.step(action)
            trace.append((obs, reward, terminated, truncated, info))
            if terminated or truncated:
                break
        runs.append(trace)
    off, on = runs
    assert len(off) == len(on)
    for a, b in zip(off, on):
        np.testing.assert_equal(a, b)


def test_a_robot_drives_through_a_marker_untouched():
    # A waypoint marker lies right ahead of the robot: driving over it is no collision.
    env = make_env(room(), visualize_goal=True, visualize_path=True,
                   initial_pos=(1.0, 1.0), initial_quat=(0, 0, 0, 1), goal_pos=(5.0, 1.0))
    env.reset(seed=0)
    first = waypoints(env.task)[0].position
    for _ in range(10):
        _, _, _, _, info = env.step(FORWARD)
    assert env.task.get_current_pos(env)[0] > first[0]
    assert info["collisions"] == 0


def test_no_marker_work_when_visualisation_is_off(monkeypatch):
    def boom(*args, **kwargs):
        raise AssertionError("marker work with visualisation off")

    monkeypatch.setattr(markers_module, "_waypoints_along", boom)
    monkeypatch.setattr(markers_module, "VisualMarker", boom)
    env = make_env()
    env.reset(seed=0)
    for _ in range(5):
        env.step(FORWARD)
    assert env.task.markers == ()


def test_visualize_goal_alone_does_no_path_work(monkeypatch):
    def boom(*args, **kwargs):
        raise AssertionError("waypoint work without visualize_path")

    monkeypatch.setattr(markers_module, "_waypoints_along", boom)
    env = make_env(visualize_goal=True)
    env.reset(seed=0)
    env.step(FORWARD)
    assert [m.kind for m in env.task.markers] == ["start", "goal"]
