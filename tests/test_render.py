"""Top-down rendering: floor colours and orientation, robots, heading ticks, markers, files,
and the frames of environments (``render_env``, ``record_episode``).

The tests read pixels back at known world positions through ``world_to_pixel``.
"""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest
from PIL import Image

from pointnav_core.backends.protocol import make_backend
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID, TraversableMap
from pointnav_core.policies.oracle import ShortestPathFollower
from pointnav_core.render.glyphs import (
    GOAL_COLOR,
    START_COLOR,
    WAYPOINT_COLOR,
    Marker,
    RobotGlyph,
)
from pointnav_core.render.recording import (
    record_episode,
    render_env,
    save_gif,
    save_png,
)
from pointnav_core.render.top_down import (
    FLOOR_COLORS,
    ROBOT_PALETTE,
    TopDownRenderer,
    contrast_color,
)
from pointnav_core.scenes import Scene
from pointnav_core.task import PointNavigationTask

F, O, V = FREE, OBSTACLE, VOID
# Row 0 is the bottom of the map (smallest y); the picture shows it at the bottom.
CODES = np.array(
    [
        [F, F, F, O, V],
        [F, F, F, O, V],
        [F, F, F, F, V],
        [O, O, F, F, F],
    ],
    dtype=np.uint8,
)
RESOLUTION = 0.5
ORIGIN = (-1.0, 2.0)


@pytest.fixture
def tmap() -> TraversableMap:
    return TraversableMap(CODES, RESOLUTION, ORIGIN)


@pytest.fixture
def open_floor() -> TraversableMap:
    """A 10 m x 10 m free floor at 0.1 m/cell centred on the origin (200 x 200 px)."""
    return TraversableMap(np.zeros((100, 100), dtype=np.uint8), 0.1, (-5.0, -5.0))


def pixel_at(renderer: TopDownRenderer, frame: np.ndarray, xy) -> tuple[int, ...]:
    """The pixel of ``frame`` at world point ``xy`` ((x, y), or (x, y, z) with z ignored)."""
    col, row = renderer.world_to_pixel(np.asarray(xy, dtype=np.float64)[:2])
    return tuple(frame[int(math.floor(row)), int(math.floor(col))].tolist())


def pixel_centres_world(renderer: TopDownRenderer) -> np.ndarray:
    """World (x, y) of every pixel centre, shape (H, W, 2)."""
    h, w = renderer.shape
    xmin, _, _, ymax = renderer.tmap.extent
    rows, cols = np.mgrid[0:h, 0:w] + 0.5
    return np.stack([xmin + cols / renderer.scale[0], ymax - rows / renderer.scale[1]], axis=-1)


# ------------------------------------------------------------------------------ the floor
def test_floor_colour_at_free_obstacle_and_void_cells(tmap):
    renderer = TopDownRenderer(tmap, pixels_per_meter=10)
    frame = renderer.draw([])
    for code, name in [(FREE, "free"), (OBSTACLE, "obstacle"), (VOID, "void")]:
        for cell in np.argwhere(CODES == code):
            xy = tmap.cell_to_world(cell)
            assert pixel_at(renderer, frame, xy) == FLOOR_COLORS[name], (name, cell)


def test_floor_colours_are_distinct_free_light_obstacle_dark():
    free, obstacle, void = (np.mean(FLOOR_COLORS[k]) for k in ("free", "obstacle", "void"))
    assert free > void > obstacle
    assert len(set(FLOOR_COLORS.values())) == 3


def test_picture_has_y_up_and_x_right(tmap):
    """Image row 0 is the map's top (largest y): the whole picture is the flipped grid."""
    renderer = TopDownRenderer(tmap, pixels_per_meter=4)  # 2 px per cell
    lut = np.zeros((3, 3), dtype=np.uint8)
    for code, name in [(FREE, "free"), (OBSTACLE, "obstacle"), (VOID, "void")]:
        lut[code] = FLOOR_COLORS[name]
    expected = lut[np.repeat(np.repeat(CODES[::-1], 2, axis=0), 2, axis=1)]
    np.testing.assert_array_equal(renderer.draw([]), expected)
    # The free cell at the top right of the map (row 3, col 4) is the top-right pixel.
    assert tuple(renderer.floor_image[0, -1]) == FLOOR_COLORS["free"]
    assert tuple(renderer.floor_image[-1, -1]) == FLOOR_COLORS["void"]


@pytest.mark.parametrize("ppm", [7.3, 13.0, 20.0, 33.3])
def test_every_pixel_shows_the_cell_under_its_centre(tmap, ppm):
    renderer = TopDownRenderer(tmap, pixels_per_meter=ppm)
    classes = tmap.cell_class_at(pixel_centres_world(renderer))
    names = {FREE: "free", OBSTACLE: "obstacle", VOID: "void"}
    expected = np.array([FLOOR_COLORS[names[c]] for c in range(3)], dtype=np.uint8)[classes]
    np.testing.assert_array_equal(renderer.floor_image, expected)


@pytest.mark.parametrize("ppm", [1.0, 7.3, 20.0, 50.0])
def test_frame_is_uint8_rgb_sized_by_pixels_per_meter(tmap, ppm):
    renderer = TopDownRenderer(tmap, pixels_per_meter=ppm)
    frame = renderer.draw([RobotGlyph(position_xy=(0.0, 3.0), yaw=0.0, radius=0.2)])
    width_m, height_m = CODES.shape[1] * RESOLUTION, CODES.shape[0] * RESOLUTION
    assert frame.dtype == np.uint8
    height, width = math.floor(height_m * ppm + 0.5), math.floor(width_m * ppm + 0.5)
    assert frame.shape == (height, width, 3)
    assert renderer.shape == (height, width)
    assert renderer.scale == (width / width_m, height / height_m)


def test_default_scale_draws_a_20_m_house_at_400_px():
    renderer = TopDownRenderer(TraversableMap(np.zeros((200, 200), np.uint8), 0.1, (-10.0, -10.0)))
    assert renderer.pixels_per_meter == 20.0
    assert renderer.shape == (400, 400)


def test_colors_override_floor_colours(tmap):
    renderer = TopDownRenderer(tmap, pixels_per_meter=10, colors={"void": (255, 0, 255)})
    frame = renderer.draw([])
    assert pixel_at(renderer, frame, tmap.cell_to_world([0, 4])) == (255, 0, 255)
    assert pixel_at(renderer, frame, tmap.cell_to_world([0, 0])) == FLOOR_COLORS["free"]


# ---------------------------------------------------------------------- world_to_pixel
def test_world_to_pixel_maps_map_corners_to_picture_corners(tmap):
    renderer = TopDownRenderer(tmap, pixels_per_meter=10)
    xmin, xmax, ymin, ymax = tmap.extent
    h, w = renderer.shape
    np.testing.assert_allclose(renderer.world_to_pixel([xmin, ymax]), [0.0, 0.0])
    np.testing.assert_allclose(renderer.world_to_pixel([xmax, ymin]), [w, h])
    corners = np.array([[[xmin, ymin], [xmax, ymax]]])
    np.testing.assert_allclose(renderer.world_to_pixel(corners), [[[0.0, h], [w, 0.0]]])


def test_world_to_pixel_rejects_a_bad_shape(tmap):
    with pytest.raises(ValueError, match=r"^xy must have shape \(\.\.\., 2\)"):
        TopDownRenderer(tmap).world_to_pixel([1.0, 2.0, 3.0])


# ------------------------------------------------------------------------------- robots
def test_robot_disc_is_drawn_where_the_robot_is(open_floor):
    renderer = TopDownRenderer(open_floor, pixels_per_meter=20)
    robot = RobotGlyph(position_xy=(1.3, -2.1), yaw=0.0, radius=0.5, color=(200, 0, 200))
    frame = renderer.draw([robot])
    assert pixel_at(renderer, frame, robot.position_xy) == (200, 0, 200)
    # Just outside radius + 1 px on every side (tick side included): floor.
    col, row = renderer.world_to_pixel(robot.position_xy)
    r_px = robot.radius * renderer.scale[0]
    for dc, dr in [(1, 0), (-1, 0), (0, 1), (0, -1), (0.7, 0.7), (-0.7, 0.7)]:
        norm = math.hypot(dc, dr)
        c, r = col + dc / norm * (r_px + 1.5), row + dr / norm * (r_px + 1.5)
        assert tuple(frame[int(r), int(c)]) == FLOOR_COLORS["free"], (dc, dr)
    # Inside the rim, away from the tick: robot colour.
    assert tuple(frame[int(row), int(col - r_px + 1.5)]) == (200, 0, 200)
    coloured = np.all(frame == (200, 0, 200), axis=-1).sum() + np.all(frame == (255, 255, 255), axis=-1).sum()
    assert coloured == pytest.approx(math.pi * r_px**2, rel=0.1)


@pytest.mark.parametrize("yaw", [0.0, math.pi / 2, math.pi, -math.pi / 2, math.pi / 4, 2.5, -2.0])
def test_heading_tick_points_along_yaw(open_floor, yaw):
    renderer = TopDownRenderer(open_floor, pixels_per_meter=20)
    color = ROBOT_PALETTE[0]
    robot = RobotGlyph(position_xy=(0.33, 0.71), yaw=yaw, radius=0.5)
    frame = renderer.draw([robot])
    tick = contrast_color(color)
    assert tick != color
    near_rim = robot.radius - 1.5 / renderer.scale[0]  # 1.5 px inside the rim
    x, y = robot.position_xy
    ahead = (x + near_rim * math.cos(yaw), y + near_rim * math.sin(yaw))
    behind = (x - near_rim * math.cos(yaw), y - near_rim * math.sin(yaw))
    left = (x - near_rim * math.sin(yaw), y + near_rim * math.cos(yaw))
    assert pixel_at(renderer, frame, ahead) == tick
    assert pixel_at(renderer, frame, behind) == color
    assert pixel_at(renderer, frame, left) == color


def test_default_robot_at_default_scale_shows_disc_and_tick(open_floor):
    renderer = TopDownRenderer(open_floor)
    frame = renderer.draw([RobotGlyph(position_xy=(0.0, 0.0), yaw=1.0, radius=0.18)])
    body = np.all(frame == ROBOT_PALETTE[0], axis=-1).sum()
    tick = np.all(frame == contrast_color(ROBOT_PALETTE[0]), axis=-1).sum()
    assert tick >= 3
    assert body > 2 * tick


def test_robots_without_a_colour_take_the_palette_by_index(open_floor):
    renderer = TopDownRenderer(open_floor, pixels_per_meter=20)
    n = len(ROBOT_PALETTE) + 2
    robots = [RobotGlyph(position_xy=(-4.5 + i, 0.0), yaw=math.pi, radius=0.3) for i in range(n)]
    robots[1] = dataclasses.replace(robots[1], color=(1, 2, 3))
    frame = renderer.draw(robots)
    expected = [ROBOT_PALETTE[i % len(ROBOT_PALETTE)] for i in range(n)]
    expected[1] = (1, 2, 3)
    for robot, color in zip(robots, expected):
        x, y = robot.position_xy
        assert pixel_at(renderer, frame, (x + 0.15, y)) == color  # behind the tick


def test_palette_avoids_marker_and_floor_colours():
    others = {START_COLOR, GOAL_COLOR, WAYPOINT_COLOR, *FLOOR_COLORS.values()}
    assert len(set(ROBOT_PALETTE)) == len(ROBOT_PALETTE) >= 8
    assert not others & set(ROBOT_PALETTE)


def test_later_robots_are_drawn_over_earlier_ones(open_floor):
    renderer = TopDownRenderer(open_floor, pixels_per_meter=20)
    a = RobotGlyph(position_xy=(0.0, 0.0), yaw=0.0, radius=0.5, color=(10, 10, 10))
    b = RobotGlyph(position_xy=(0.3, 0.0), yaw=0.0, radius=0.5, color=(250, 250, 0))
    frame = renderer.draw([a, b])
    assert pixel_at(renderer, frame, (0.1, -0.2)) == (250, 250, 0)
    assert pixel_at(renderer, frame, (-0.4, 0.0)) == (10, 10, 10)


def test_a_robot_smaller_than_a_pixel_still_shows(open_floor):
    renderer = TopDownRenderer(open_floor, pixels_per_meter=20)
    frame = renderer.draw([RobotGlyph(position_xy=(0.01, 0.02), yaw=0.0, radius=0.0, color=(9, 9, 9))])
    assert pixel_at(renderer, frame, (0.01, 0.02)) in {(9, 9, 9), contrast_color((9, 9, 9))}


def test_discs_off_the_picture_are_clipped(open_floor):
    renderer = TopDownRenderer(open_floor, pixels_per_meter=20)
    floor = renderer.floor_image
    far = RobotGlyph(position_xy=(50.0, 50.0), yaw=0.0, radius=0.5)
    off_marker = Marker(position_xy=(-9.0, 0.0), radius=1.0, color=GOAL_COLOR)
    np.testing.assert_array_equal(renderer.draw([far], [off_marker]), floor)
    edge = RobotGlyph(position_xy=(5.0, -5.0), yaw=0.0, radius=0.5, color=(1, 1, 1))
    frame = renderer.draw([edge])
    assert tuple(frame[-1, -1]) == (1, 1, 1)
    assert np.all(frame == (1, 1, 1), axis=-1).sum() == pytest.approx(math.pi * 100 / 4, rel=0.15)


# ------------------------------------------------------------------------------ markers
def test_goal_marker_tints_its_disc_towards_blue_and_nothing_else(open_floor):
    renderer = TopDownRenderer(open_floor, pixels_per_meter=20)
    floor = renderer.floor_image
    goal = Marker(position_xy=(2.0, 1.0), radius=0.5, color=GOAL_COLOR, alpha=0.5)
    frame = renderer.draw([], [goal])
    below = np.array(FLOOR_COLORS["free"], dtype=float)
    expected = tuple(np.floor(0.5 * below + 0.5 * np.array(GOAL_COLOR) + 0.5).astype(int).tolist())
    got = pixel_at(renderer, frame, goal.position_xy)
    assert got == expected
    assert got[2] > got[0] and got[2] > got[1]  # bluish
    assert pixel_at(renderer, frame, (-2.0, -3.0)) == FLOOR_COLORS["free"]
    changed = np.any(frame != floor, axis=-1)
    assert changed.sum() == pytest.approx(math.pi * (0.5 * 20) ** 2, rel=0.1)
    rows, cols = np.nonzero(changed)
    centre = renderer.world_to_pixel(goal.position_xy)
    assert np.hypot(cols + 0.5 - centre[0], rows + 0.5 - centre[1]).max() <= 10.0


@pytest.mark.parametrize(("alpha", "weight"), [(0.0, 0.0), (0.25, 0.25), (1.0, 1.0)])
def test_marker_alpha_blends_linearly(tmap, alpha, weight):
    renderer = TopDownRenderer(tmap, pixels_per_meter=20)
    xy = tmap.cell_to_world([0, 3])  # an obstacle cell
    frame = renderer.draw([], [Marker(position_xy=xy, radius=0.1, color=START_COLOR, alpha=alpha)])
    below = np.array(FLOOR_COLORS["obstacle"], dtype=float)
    expected = np.floor((1 - weight) * below + weight * np.array(START_COLOR) + 0.5).astype(int)
    assert pixel_at(renderer, frame, xy) == tuple(expected.tolist())


def test_overlapping_markers_blend_in_order_and_robots_go_on_top(open_floor):
    renderer = TopDownRenderer(open_floor, pixels_per_meter=20)
    start = Marker(position_xy=(0.0, 0.0), radius=0.5, color=START_COLOR)
    goal = Marker(position_xy=(0.0, 0.0), radius=0.5, color=GOAL_COLOR)
    waypoint = Marker(position_xy=(1.0, 0.0), radius=0.1, color=WAYPOINT_COLOR, alpha=1.0)
    frame = renderer.draw([], [start, goal, waypoint])
    once = np.floor(0.5 * np.array(FLOOR_COLORS["free"]) + 0.5 * np.array(START_COLOR) + 0.5)
    twice = np.floor(0.5 * once + 0.5 * np.array(GOAL_COLOR) + 0.5).astype(int)
    assert pixel_at(renderer, frame, (0.0, 0.0)) == tuple(twice.tolist())
    assert pixel_at(renderer, frame, (1.0, 0.0)) == WAYPOINT_COLOR
    robot = RobotGlyph(position_xy=(0.0, 0.0), yaw=0.0, radius=0.2, color=(5, 5, 5))
    assert pixel_at(renderer, renderer.draw([robot], [start, goal]), (-0.1, 0.0)) == (5, 5, 5)


# -------------------------------------------------------------------- fresh frames, cache
def test_each_frame_is_a_fresh_array(open_floor):
    renderer = TopDownRenderer(open_floor, pixels_per_meter=20)
    robots = [RobotGlyph(position_xy=(0.0, 0.0), yaw=0.0, radius=0.3)]
    first = renderer.draw(robots)
    reference = first.copy()
    assert first.flags.writeable
    first[:] = 0
    second = renderer.draw(robots)
    assert second is not first
    assert not np.shares_memory(second, renderer.floor_image)
    np.testing.assert_array_equal(second, reference)
    assert tuple(renderer.floor_image[0, 0]) == FLOOR_COLORS["free"]
    with pytest.raises(ValueError):
        renderer.floor_image[0, 0] = 0


# ---------------------------------------------------------------------------- validation
def test_glyphs_are_keyword_only_frozen_and_normalised():
    with pytest.raises(TypeError):
        RobotGlyph((0.0, 0.0), 0.0, 0.2)  # type: ignore[misc]
    robot = RobotGlyph(position_xy=np.array([1, 2, 0.5]), yaw=1, radius=np.float32(0.25), color=np.uint8([1, 2, 3]))
    assert robot.position_xy == (1.0, 2.0) and robot.yaw == 1.0 and robot.radius == 0.25
    assert robot.color == (1, 2, 3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        robot.yaw = 0.0  # type: ignore[misc]
    marker = Marker(position_xy=[0, 0], radius=1, color=[0, 0, 255])
    assert marker.color == (0, 0, 255) and marker.alpha == 0.5
    assert hash(marker) == hash(Marker(position_xy=(0.0, 0.0), radius=1.0, color=(0, 0, 255)))


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: RobotGlyph(position_xy=(0, math.nan), yaw=0, radius=1), r"^position_xy must be a finite"),
        (lambda: RobotGlyph(position_xy=(0, 0, 0, 0), yaw=0, radius=1), r"^position_xy must be a finite"),
        (lambda: RobotGlyph(position_xy=(0, 0), yaw=math.inf, radius=1), r"^yaw must be a finite number"),
        (lambda: RobotGlyph(position_xy=(0, 0), yaw=0, radius=-1), r"^radius must be a finite number >= 0 \(m\)"),
        (lambda: RobotGlyph(position_xy=(0, 0), yaw=0, radius=1, color=(0, 0, 256)), r"^color must be three ints"),
        (lambda: RobotGlyph(position_xy=(0, 0), yaw=0, radius=1, color=(0.5, 0, 0)), r"^color must be three ints"),
        (lambda: Marker(position_xy=(0, 0), radius=1, color="red"), r"^color must be three ints"),
        (
            lambda: Marker(position_xy=(0, 0), radius=1, color=GOAL_COLOR, alpha=1.5),
            r"^alpha must be a finite number in \[0, 1\], got 1.5",
        ),
        (lambda: Marker(position_xy=(0, 0), radius="x", color=GOAL_COLOR), r"^radius must be a finite number"),
    ],
)
def test_glyphs_reject_bad_fields_naming_them(make, message):
    with pytest.raises(ValueError, match=message):
        make()


def test_renderer_rejects_bad_arguments(tmap):
    with pytest.raises(TypeError, match="^tmap must be a TraversableMap"):
        TopDownRenderer(CODES)  # type: ignore[arg-type]
    for bad in (0, -1.0, math.nan, math.inf):
        with pytest.raises(ValueError, match=r"^pixels_per_meter must be a finite number > 0"):
            TopDownRenderer(tmap, pixels_per_meter=bad)
    valid = r"valid keys: \['free', 'obstacle', 'void'\]"
    with pytest.raises(ValueError, match=rf"^colors has an unknown key 'wall'; {valid}"):
        TopDownRenderer(tmap, colors={"wall": (0, 0, 0)})
    with pytest.raises(ValueError, match=r"^colors\['free'\] must be three ints"):
        TopDownRenderer(tmap, colors={"free": (0, 0)})
    with pytest.raises(ValueError, match=r"^pixels_per_meter=1e\+06 gives a 2500000 x 2000000 px picture"):
        TopDownRenderer(tmap, pixels_per_meter=1e6)


def test_draw_rejects_items_of_the_wrong_type(tmap):
    renderer = TopDownRenderer(tmap)
    marker = Marker(position_xy=(0, 3), radius=0.2, color=GOAL_COLOR)
    with pytest.raises(TypeError, match=r"^robots\[0\] must be a RobotGlyph, got Marker"):
        renderer.draw([marker])
    with pytest.raises(TypeError, match=r"^markers\[1\] must be a Marker, got tuple"):
        renderer.draw([], [marker, (0.0, 3.0)])  # type: ignore[list-item]


def test_contrast_color_is_black_on_light_and_white_on_dark():
    assert contrast_color((255, 255, 255)) == (0, 0, 0)
    assert contrast_color((0, 0, 0)) == (255, 255, 255)
    for color in ROBOT_PALETTE:
        tick = np.array(contrast_color(color))
        assert np.abs(tick - np.array(color)).max() >= 100


# --------------------------------------------------------------------------------- files
def test_save_png_writes_the_frame_exactly(tmp_path, tmap):
    renderer = TopDownRenderer(tmap, pixels_per_meter=10)
    frame = renderer.draw([RobotGlyph(position_xy=(0.0, 3.0), yaw=0.0, radius=0.4)])
    path = tmp_path / "frame.png"
    save_png(frame, path)
    with Image.open(path) as im:
        assert im.format == "PNG" and im.mode == "RGB"
        np.testing.assert_array_equal(np.asarray(im), frame)
    save_png(frame, str(tmp_path / "again.png"))
    assert (tmp_path / "again.png").stat().st_size > 0


def test_save_gif_writes_a_looping_animation(tmp_path, open_floor):
    renderer = TopDownRenderer(open_floor, pixels_per_meter=5)
    frames = [
        renderer.draw([RobotGlyph(position_xy=(-3.0 + i, 0.0), yaw=0.3 * i, radius=0.5)]) for i in range(5)
    ]
    path = tmp_path / "episode.gif"
    save_gif(iter(frames), path, fps=10)
    with Image.open(path) as im:
        assert im.format == "GIF"
        assert im.n_frames == 5
        assert im.info["loop"] == 0
        assert im.info["duration"] == 100
        for i, frame in enumerate(frames):
            im.seek(i)
            # Few colours: the GIF palette holds them all exactly.
            np.testing.assert_array_equal(np.asarray(im.convert("RGB")), frame)


@pytest.mark.parametrize(("fps", "duration"), [(4, 250), (30, 30), (1000, 20)])
def test_save_gif_duration_comes_from_fps(tmp_path, tmap, fps, duration):
    renderer = TopDownRenderer(tmap, pixels_per_meter=4)
    markers = [Marker(position_xy=(0, 3), radius=0.5, color=GOAL_COLOR, alpha=a) for a in (0.2, 1.0)]
    frames = [renderer.draw([], [marker]) for marker in markers]
    save_gif(frames, tmp_path / "a.gif", fps=fps)
    with Image.open(tmp_path / "a.gif") as im:
        assert im.info["duration"] == duration


def test_save_functions_reject_bad_input(tmp_path):
    good = np.zeros((4, 5, 3), np.uint8)
    with pytest.raises(ValueError, match=r"^frame must be a uint8 RGB image of shape \(H, W, 3\), got dtype float"):
        save_png(good.astype(float), tmp_path / "x.png")
    with pytest.raises(ValueError, match=r"^frames must hold at least one frame"):
        save_gif([], tmp_path / "x.gif")
    with pytest.raises(ValueError, match=r"^frames\[1\] has shape \(5, 4, 3\), but frames\[0\] has \(4, 5, 3\)"):
        save_gif([good, np.zeros((5, 4, 3), np.uint8)], tmp_path / "x.gif")
    with pytest.raises(ValueError, match=r"^frames\[0\] must be a uint8 RGB image"):
        save_gif([good[..., 0]], tmp_path / "x.gif")
    with pytest.raises(ValueError, match=r"^fps must be a finite number > 0"):
        save_gif([good], tmp_path / "x.gif", fps=0)
    assert not list(tmp_path.iterdir())


# ------------------------------------------------------------------ environments: render_env
# The frames of PointNavEnv.render() (and of any env with scene, backend, robots and tasks),
# read back through a renderer of the same floor at the same (default) scale.


def env_room() -> np.ndarray:
    """A 6 m x 2 m walled room at 0.1 m/cell, with a pillar the path must go around."""
    grid = np.full((20, 60), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[5:20, 28:32] = OBSTACLE
    return grid


def make_env(grid=None, **task):
    task.setdefault("initial_pos", (1.0, 1.0))
    task.setdefault("initial_quat", (0.0, 0.0, 0.0, 1.0))
    task.setdefault("goal_pos", (5.0, 1.5))
    scene = Scene.from_array(env_room() if grid is None else grid, 0.1)
    return PointNavEnv(scene=scene, robot=RobotSpec(radius=0.1), task=task, render_mode="rgb_array")


def blend(below, color, alpha: float = 0.5) -> tuple[int, ...]:
    """A pixel ``below`` under a translucent marker of ``color`` (as ``draw`` blends)."""
    below = np.asarray(below, dtype=np.float32)
    return tuple((below + np.float32(alpha) * (np.asarray(color, np.float32) - below) + 0.5).astype(np.uint8).tolist())


def drive(env, steps: int) -> None:
    oracle = ShortestPathFollower(env)
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(oracle.act())
        assert not (terminated or truncated)


def reader(env, floor: int = 0) -> TopDownRenderer:
    return TopDownRenderer(env.scene.floors[floor])


@pytest.mark.parametrize("visualize_goal", [True, False])
def test_goal_pixel_has_the_goal_colour_only_with_visualize_goal(visualize_goal):
    env = make_env(visualize_goal=visualize_goal)
    env.reset(seed=0)
    drive(env, 15)  # off the start, so that the start marker shows too
    frame, ref = env.render(), reader(env)
    floor = ref.floor_image
    goal, start = env.task.get_goal_pos(), env.task.get_start_pos()
    free = FLOOR_COLORS["free"]
    if visualize_goal:
        assert pixel_at(ref, frame, goal) == blend(free, GOAL_COLOR)
        assert pixel_at(ref, frame, start) == blend(free, START_COLOR)
        got = np.array(pixel_at(ref, frame, goal))
        # Moved towards the goal colour, and blue is its strongest channel.
        assert np.abs(got - GOAL_COLOR).sum() < np.abs(np.array(free) - GOAL_COLOR).sum()
        assert got.argmax() == 2
    else:
        assert pixel_at(ref, frame, goal) == pixel_at(ref, floor, goal) == free
        assert pixel_at(ref, frame, start) == free
    # The goal disc has radius goal_tolerance: 0.45 m away it is tinted, 0.6 m away it is not.
    tinted = pixel_at(ref, frame, goal[:2] + (0.45, 0.0))
    assert (tinted == blend(free, GOAL_COLOR)) is visualize_goal
    assert pixel_at(ref, frame, goal[:2] + (0.6, 0.0)) == free


def test_waypoint_pixels_are_green_and_lie_on_the_path():
    env = make_env(visualize_path=True, n_vis_waypoints=8)
    env.reset(seed=0)
    drive(env, 10)
    frame, ref = env.render(), reader(env)
    task = env.task
    robot_xy = task.get_current_pos(env)[:2]
    marks = [m for m in task.markers if m.visible]
    assert len(marks) == 8
    green = blend(FLOOR_COLORS["free"], WAYPOINT_COLOR)
    for m in marks:
        if math.dist(m.position[:2], robot_xy) > 0.1 + 0.15:  # clear of the robot's disc
            got = pixel_at(ref, frame, m.position)
            assert got == green
            assert got[1] > got[0] and got[1] > got[2]  # greenish
    # Every green pixel is within waypoint_width (+ one pixel) of the path from the robot.
    path, _ = env.scene.goal_field(0, task.get_goal_pos(), robot=env.robot).path(robot_xy, exact=False)
    rows, cols = np.nonzero(np.all(frame == green, axis=-1))
    assert len(rows) > 8 * 4
    centres = pixel_centres_world(ref)[rows, cols]
    a, b = path[:-1], path[1:]
    t = np.clip(np.einsum("mnk,nk->mn", centres[:, None] - a, b - a) / ((b - a) ** 2).sum(1), 0, 1)
    dist = np.hypot(*(centres[:, None] - (a + t[..., None] * (b - a))).transpose(2, 0, 1)).min(1)
    assert dist.max() <= task.waypoint_width + 1.0 / ref.scale[0]


def test_robot_disc_is_drawn_where_the_env_robot_is():
    env = make_env()
    env.reset(seed=0)
    drive(env, 12)
    frame, ref = env.render(), reader(env)
    position, quat = env.backend.get_pose(0)
    yaw = math.atan2(2 * quat[3] * quat[2], 1 - 2 * quat[2] ** 2)
    color = ROBOT_PALETTE[0]
    assert pixel_at(ref, frame, position) == color
    behind = position[:2] - 0.07 * np.array([math.cos(yaw), math.sin(yaw)])
    assert pixel_at(ref, frame, behind) == color
    ahead = position[:2] + 0.07 * np.array([math.cos(yaw), math.sin(yaw)])
    assert pixel_at(ref, frame, ahead) == contrast_color(color)  # the heading tick
    outside = position[:2] + (0.0, 0.1 + 2.0 / ref.scale[1])
    assert pixel_at(ref, frame, outside) != color
    # Everything else is the floor: one robot, no markers.
    changed = np.any(frame != ref.floor_image, axis=-1)
    assert changed.sum() == pytest.approx(math.pi * (0.1 * 20) ** 2, abs=8)


def test_hidden_waypoints_are_not_drawn():
    grid = np.full((20, 60), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[:, 30] = OBSTACLE  # two rooms, no door: the goal is unreachable
    env = make_env(grid, visualize_goal=True, visualize_path=True, goal_pos=(5.0, 1.0))
    env.reset(seed=0)
    frame, ref = env.render(), reader(env)
    assert not any(m.visible for m in env.task.markers if m.kind == "waypoint")
    assert not np.all(frame == blend(FLOOR_COLORS["free"], WAYPOINT_COLOR), axis=-1).any()
    assert pixel_at(ref, frame, (5.0, 1.0)) == blend(FLOOR_COLORS["free"], GOAL_COLOR)


def test_render_before_reset_shows_the_floor_only():
    env = make_env(visualize_goal=True, visualize_path=True)
    np.testing.assert_array_equal(env.render(), reader(env).floor_image)


def test_render_returns_a_fresh_frame_each_call_from_a_cached_renderer(monkeypatch):
    env = make_env(visualize_goal=True)
    env.reset(seed=0)
    attributes = dict(vars(env))
    first = env.render()
    assert vars(env) == attributes  # the env owns its renderers; drawing sets nothing on it
    reference = first.copy()
    first[:] = 0
    built = []
    real_init = TopDownRenderer.__init__
    monkeypatch.setattr(TopDownRenderer, "__init__", lambda self, *a, **k: built.append(1) or real_init(self, *a, **k))
    np.testing.assert_array_equal(env.render(), reference)
    assert built == []  # the floor picture was prepared once, at the first frame
    render_env(env, pixels_per_meter=10)
    assert built == [1]  # no renderers given: the floor is drawn anew
    env.scene = Scene.from_array(np.zeros((30, 40), np.uint8), 0.5)
    env.render()
    assert built == [1, 1]  # a new floor: a new renderer, not the old floor's picture


def test_default_scale_and_the_pixels_per_meter_options():
    env = PointNavEnv(render_mode="rgb_array")  # the default 20 m x 15 m house
    env.reset(seed=0)
    assert env.render().shape == (300, 400, 3)
    assert render_env(env, pixels_per_meter=40).shape == (600, 800, 3)
    env.render_pixels_per_meter = 10
    assert env.render().shape == (150, 200, 3)
    assert render_env(env, pixels_per_meter=20).shape == (300, 400, 3)  # the argument wins
    with pytest.raises(ValueError, match="^pixels_per_meter must be a finite number > 0"):
        render_env(env, pixels_per_meter=0)


class TwoRobotEnv:
    """A minimal multi-robot env: what render_env and the tasks read, nothing more."""

    def __init__(self, scene, n: int = 2, **task):
        self.scene = scene
        self.robots = tuple(RobotSpec(radius=0.15) for _ in range(n))
        self.backend = make_backend("kinematic")
        self.backend.load(scene, self.robots, 10.0)
        self.tasks = [PointNavigationTask(robot_idn=i, **task) for i in range(n)]
        self.np_random = np.random.default_rng(0)

    def reset(self) -> None:
        self.backend.reset()
        for task in self.tasks:
            task.reset(self)


def test_render_env_draws_every_robot_in_its_colour_and_every_tasks_markers():
    scene = Scene.from_array(env_room(), 0.1)
    env = TwoRobotEnv(scene, visualize_goal=True, goal_tolerance=0.3)
    np.testing.assert_array_equal(render_env(env), reader(env).floor_image)  # nobody placed yet
    env.reset()
    frame, ref = render_env(env), reader(env)
    for idn, task in enumerate(env.tasks):
        position, _ = env.backend.get_pose(idn)
        assert pixel_at(ref, frame, position) == ROBOT_PALETTE[idn]
        goal = task.get_goal_pos()
        got = np.array(pixel_at(ref, frame, goal))
        assert got.argmax() == 2 and not np.array_equal(got, FLOOR_COLORS["free"])  # bluish
    # A robot out of the world is not drawn.
    env.backend.set_present(1, False)
    frame = render_env(env)
    assert pixel_at(ref, frame, env.backend.get_pose(1)[0]) != ROBOT_PALETTE[1]
    assert pixel_at(ref, frame, env.backend.get_pose(0)[0]) == ROBOT_PALETTE[0]


def test_render_env_shows_the_first_tasks_floor_and_what_is_on_it():
    grid = env_room()
    scene = Scene.from_array([grid, grid[:, ::-1].copy()], 0.1, heights=[0.0, 3.0])
    env = TwoRobotEnv(scene, visualize_goal=True)
    env.tasks[1] = PointNavigationTask(robot_idn=1, floor=1, visualize_goal=True)
    env.reset()
    assert env.backend.get_robot_floor(1) == 1
    frame, ref = render_env(env), reader(env, floor=0)
    assert np.all(frame == ROBOT_PALETTE[0], axis=-1).any()
    assert not np.all(frame == ROBOT_PALETTE[1], axis=-1).any()  # on the other floor
    goal1 = env.tasks[1].get_goal_pos()
    assert pixel_at(ref, frame, goal1) == pixel_at(ref, ref.floor_image, goal1)


def test_record_episode_returns_the_episode_frames_and_writes_a_gif(tmp_path):
    env = make_env(visualize_goal=True, visualize_path=True)
    oracle = ShortestPathFollower(env)
    frames = record_episode(env, lambda obs: oracle.act(), seed=0)
    steps = env.task.episode_length
    assert env.task.success and len(frames) == steps + 1
    assert all(f.shape == frames[0].shape and f.dtype == np.uint8 for f in frames)
    np.testing.assert_array_equal(frames[-1], env.render())
    every = record_episode(env, lambda obs: oracle.act(), tmp_path / "episode.gif", seed=0, every=5)
    assert len(every) == 1 + steps // 5 + (steps % 5 != 0)
    np.testing.assert_array_equal(every[0], frames[0])
    np.testing.assert_array_equal(every[-1], frames[-1])
    with Image.open(tmp_path / "episode.gif") as im:
        assert im.n_frames == len(every)
        assert im.info["duration"] == 500  # 10 fps / 5: real time
    with pytest.raises(ValueError, match="^every must be an integer >= 1"):
        record_episode(env, lambda obs: oracle.act(), every=0)



def test_demo_cli_writes_a_gif_and_a_png_with_markers(tmp_path, capsys):
    from pointnav_core.cli import main

    gif, png = tmp_path / "episode.gif", tmp_path / "episode.png"
    argv = ["demo", "--episodes", "1", "--houses", "1", "--max-steps", "40", "--every", "10", "--quiet"]
    assert main([*argv, "--gif", str(gif), "--png", str(png), "--pixels-per-meter", "10"]) == 0
    # After the reset, then every 10th step and the last: at most steps 10..40 (the
    # default path_range keeps the episode within reach, so it may end sooner).
    frames = int(re.search(rf"wrote {re.escape(str(gif))} \((\d+) frames\)", capsys.readouterr().out)[1])
    assert 2 <= frames <= 5
    with Image.open(gif) as im:
        assert im.n_frames == frames and im.size == (200, 150)
        assert im.info["duration"] == 1000  # 10 fps / 10: real time
    with Image.open(png) as im:
        last = np.asarray(im.convert("RGB"))
    # The demo shows the markers: the start disc is tinted red, the goal disc blue.
    for color in (START_COLOR, GOAL_COLOR):
        assert np.all(last == blend(FLOOR_COLORS["free"], color), axis=-1).any()
