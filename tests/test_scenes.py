"""Scene construction, sampling and error handling."""

import types

import numpy as np
import pytest
from PIL import Image
from shapely.geometry import Point, box

from pointnav_core.errors import SamplingError
from pointnav_core.floor.maps import OBSTACLE, VOID
from pointnav_core.floorplans import FloorPlan
from pointnav_core.scenes import Scene, clutter, maze, robot_radius, rooms


def test_from_array_accepts_one_floor_a_stack_or_a_list():
    one = Scene.from_array(np.ones((4, 4), bool), resolution=0.5)
    stack = Scene.from_array(np.ones((3, 4, 4), bool), resolution=0.5)
    listed = Scene.from_array([np.ones((4, 4), bool), np.zeros((2, 2), np.uint8)], 0.5, heights=[1.0, 4.0])
    assert (one.n_floors, stack.n_floors, listed.n_floors) == (1, 3, 2)
    assert [stack.get_floor_height(i) for i in range(3)] == [0.0, 3.0, 6.0]
    assert listed.get_floor_height(1) == 4.0


def test_heights_must_match_the_floors():
    with pytest.raises(ValueError, match="heights"):
        Scene.from_array(np.ones((2, 4, 4), bool), 0.5, heights=[0.0])


@pytest.mark.parametrize("floor", [-1, 2, 1.5, True, "0"])
def test_floor_out_of_range_names_the_parameter(floor):
    scene = Scene.from_array(np.ones((2, 4, 4), bool), 0.5)
    with pytest.raises(ValueError, match="floor"):
        scene.get_floor_height(floor)


def test_map_without_free_cells_cannot_be_sampled():
    scene = Scene.from_array(np.full((5, 5), OBSTACLE, np.uint8), 1.0)
    with pytest.raises(SamplingError, match="usable"):
        scene.get_random_point(0, rng=0)
    with pytest.raises(SamplingError):
        scene.get_random_point(rng=0)


def test_radius_too_large_for_the_room_is_a_sampling_error():
    scene = Scene.from_array(np.ones((4, 4), bool), 0.1)
    with pytest.raises(SamplingError, match="radius"):
        scene.get_random_point(0, robot=1.0, rng=0)


def test_reference_point_on_an_obstacle_is_rejected():
    grid = np.ones((5, 5), bool)
    grid[2, 2] = False
    scene = Scene.from_array(grid, 1.0)
    with pytest.raises(ValueError, match="reference_point"):
        scene.get_random_point(0, reference_point=(2.5, 2.5), rng=0)
    with pytest.raises(ValueError, match="reference_point"):
        scene.get_random_point(0, reference_point=(-7.0, 2.5), rng=0)


def test_random_points_are_cell_centres_on_the_floor_height_and_seeded():
    scene = Scene.from_array(np.ones((2, 6, 6), bool), 0.5, heights=[0.0, 2.5])
    a = scene.get_random_point(rng=7)
    b = scene.get_random_point(rng=7)
    assert a[0] == b[0] and np.array_equal(a[1], b[1])
    floor, p = scene.get_random_point(1, rng=np.random.default_rng(1))
    assert floor == 1 and p[2] == 2.5
    assert ((p[:2] / 0.5) % 1.0 == pytest.approx(0.5))


def test_robot_may_be_a_spec_a_radius_or_none():
    assert robot_radius(None) == 0.0
    assert robot_radius(0.3) == 0.3
    assert robot_radius(types.SimpleNamespace(radius=0.18)) == 0.18
    for bad in (-1.0, "wide", float("nan")):
        with pytest.raises(ValueError, match="robot"):
            robot_radius(bad)


def test_from_polygons_marks_void_outside_and_keeps_the_plan():
    outline = box(0, 0, 4, 3)
    scene = Scene.from_polygons(outline, [Point(2, 1.5).buffer(0.5)], resolution=0.1)
    tmap = scene.floors[0]
    assert int(tmap.cell_class_at([2.0, 1.5])) == OBSTACLE
    assert int(tmap.cell_class_at([4.5, 1.5])) == VOID
    assert scene.floor_plans[0].outline.equals(outline)


def test_from_png_reads_omnigibson_traversability_images(tmp_path):
    img = np.full((200, 200), 255, np.uint8)
    img[150:, :] = 0  # the top quarter (+y) is blocked
    path = tmp_path / "floor_trav_0.png"
    Image.fromarray(img, mode="L").save(path)
    scene = Scene.from_png([path], resolution=0.1)
    tmap = scene.floors[0]
    assert tmap.shape == (20, 20)
    assert tmap.extent == pytest.approx((-1.0, 1.0, -1.0, 1.0))
    assert int(tmap.cell_class_at([0.0, 0.9])) == OBSTACLE
    assert scene.is_usable(0, (0.0, -0.9))


def test_from_png_rejects_colour_images(tmp_path):
    path = tmp_path / "floor_trav_0.png"
    Image.new("RGB", (10, 10)).save(path)
    with pytest.raises(ValueError):
        Scene.from_png(path)


def test_from_movingai_reads_walls_as_obstacles(tmp_path):
    path = tmp_path / "tiny.map"
    path.write_text("type octile\nheight 3\nwidth 4\nmap\n....\n.@@.\n....\n")
    scene = Scene.from_movingai(path, resolution=1.0)
    tmap = scene.floors[0]
    # Character (1, 0..3) still covers x in [0, 4), y in [1, 2).
    assert tmap.cell_class_at([[0.5, 1.5], [1.5, 1.5], [2.5, 1.5], [3.5, 1.5]]).tolist() == [0, 1, 1, 0]
    assert scene.get_shortest_path(0, (0.5, 1.5), (3.5, 1.5), entire_path=True)[1] > 3.0


def test_from_movingai_out_of_bounds_is_a_wall_not_a_drop(tmp_path):
    # SPEC: out of bounds in a game map is a wall. A passable border must not be a cliff.
    path = tmp_path / "open.map"
    path.write_text("type octile\nheight 2\nwidth 2\nmap\n..\n..\n")
    tmap = Scene.from_movingai(path, resolution=1.0).floors[0]
    just_outside = [[-0.5, 0.5], [2.5, 0.5], [0.5, -0.5], [0.5, 2.5], [-0.5, -0.5]]
    assert tmap.cell_class_at(just_outside).tolist() == [OBSTACLE] * 5


def test_from_movingai_names_an_unknown_character(tmp_path):
    path = tmp_path / "bad.map"
    path.write_text("type octile\nheight 1\nwidth 2\nmap\n.x\n")
    with pytest.raises(ValueError, match="'x'"):
        Scene.from_movingai(path)


@pytest.mark.parametrize("generator", [rooms, maze, clutter])
def test_generated_scenes_are_deterministic_and_navigable(generator):
    a, b = generator(seed=3), generator(seed=3)
    assert np.array_equal(a.floors[0].codes, b.floors[0].codes)
    _, p = a.get_random_point(0, robot=0.18, rng=0)
    _, q = a.get_random_point(0, reference_point=p, robot=0.18, rng=1)
    assert a.get_shortest_path(0, p, q, robot=0.18)[1] is not None


def test_a_floor_plan_lives_on_its_map_once():
    plan = FloorPlan(outline=box(0, 0, 3, 2), obstacles=[box(1, 0.5, 1.5, 1.5)])
    scene = Scene.from_polygons(plan.outline, plan.obstacles, resolution=0.1)
    assert scene.floor_plans == (scene.floors[0].geometry,)
    bare = Scene.from_array(np.ones((10, 10), bool), 0.1)
    assert bare.floor_plans == (None,)
    with pytest.raises(ValueError, match=r"floor_plans\[0\] is not floor 0's geometry"):
        Scene(bare.floors, floor_plans=[plan])
