"""Reading OmniGibson traversability PNGs and MovingAI .map files into cell codes."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from PIL import Image

from pointnav_core.floor.loaders import MOVINGAI_CELLS, read_movingai, read_trav_png
from pointnav_core.floor.maps import FREE, OBSTACLE, TraversableMap


def write_png(path, pixels, mode="L"):
    Image.fromarray(np.asarray(pixels), mode=None if mode == "L" else mode).save(path)
    return path


def free_image(n):
    return np.full((n, n), 255, dtype=np.uint8)


# --------------------------------------------------------------------------- read_trav_png
def test_trav_png_obstacle_lands_in_the_right_cell_with_rows_growing_with_y(tmp_path):
    # 2 m x 2 m at 0.01 m/px; block pixels covering x in [-0.7, -0.6), y in [0.5, 0.6).
    pixels = free_image(200)
    pixels[150:160, 30:40] = 0
    codes, origin = read_trav_png(write_png(tmp_path / "floor_trav_0.png", pixels), resolution=0.1)

    assert codes.dtype == np.uint8 and codes.shape == (20, 20)
    assert origin == pytest.approx((-1.0, -1.0))
    assert np.argwhere(codes == OBSTACLE).tolist() == [[15, 3]]
    floor = TraversableMap(codes, 0.1, origin)
    assert floor.cell_class_at([-0.65, 0.55]) == OBSTACLE
    assert floor.cell_class_at([-0.65, -0.55]) == FREE  # mirrored in y: free
    assert floor.cell_class_at([0.65, 0.55]) == FREE  # mirrored in x: free


def test_trav_png_is_centred_on_the_world_origin(tmp_path):
    pixels = free_image(300)
    pixels[150, 150] = 0  # the pixel just above and right of the world origin
    codes, origin = read_trav_png(write_png(tmp_path / "t.png", pixels), resolution=0.1)
    floor = TraversableMap(codes, 0.1, origin)
    assert floor.extent == pytest.approx((-1.5, 1.5, -1.5, 1.5))
    assert floor.cell_class_at([0.005, 0.005]) == OBSTACLE
    assert floor.cell_class_at([-0.005, -0.005]) == FREE


def test_trav_png_blocks_a_cell_when_any_of_its_pixels_is_below_255(tmp_path):
    pixels = free_image(100)
    pixels[3, 97] = 254
    codes, _ = read_trav_png(write_png(tmp_path / "t.png", pixels), resolution=0.1)
    assert np.argwhere(codes == OBSTACLE).tolist() == [[0, 9]]


def test_trav_png_keeps_source_resolution_when_asked(tmp_path):
    pixels = (np.random.default_rng(0).random((37, 37)) < 0.3).astype(np.uint8) * 255
    codes, origin = read_trav_png(write_png(tmp_path / "t.png", pixels), resolution=0.01)
    assert np.array_equal(codes, np.where(pixels == 255, FREE, OBSTACLE))
    assert origin == pytest.approx((-0.185, -0.185))


def test_trav_png_pads_a_size_not_divisible_by_the_factor_with_blocked_cells(tmp_path):
    # 0.25 m of image in 0.1 m cells: 3 cells covering 0.3 m, 0.025 m missing on each side.
    codes, origin = read_trav_png(write_png(tmp_path / "t.png", free_image(25)), resolution=0.1)
    assert codes.shape == (3, 3)
    assert origin == pytest.approx((-0.15, -0.15))
    expected = np.full((3, 3), OBSTACLE)
    expected[1, 1] = FREE
    assert np.array_equal(codes, expected)


def test_trav_png_upsamples_with_nearest_pixel(tmp_path):
    pixels = np.array([[255, 0], [255, 255]], dtype=np.uint8)
    codes, origin = read_trav_png(write_png(tmp_path / "t.png", pixels), resolution=0.005)
    assert origin == pytest.approx((-0.01, -0.01))
    assert np.array_equal(codes, np.kron(np.where(pixels == 255, FREE, OBSTACLE), np.ones((2, 2))))


@pytest.mark.parametrize("resolution", [0.015, 0.025, 0.07, 0.0075])
def test_trav_png_agrees_with_a_cell_by_cell_reference(tmp_path, resolution):
    n = 23
    pixels = np.where(np.random.default_rng(1).random((n, n)) < 0.1, 0, 255).astype(np.uint8)
    codes, origin = read_trav_png(write_png(tmp_path / "t.png", pixels), resolution=resolution)
    assert codes.shape[0] == math.ceil(round(n * 0.01 / resolution, 9))
    assert np.array_equal(codes, reference_resample(pixels, resolution, 0.01))


def reference_resample(pixels, resolution, source_resolution):
    """Each cell is free iff every pixel its square overlaps is 255 (exact arithmetic)."""
    n = pixels.shape[0]
    res, src = Fraction(str(resolution)), Fraction(str(source_resolution))
    cells = math.ceil(n * src / res)
    lo_edge = -cells * res / 2  # world coordinate of the grid's outer edge
    img_edge = -n * src / 2
    out = np.empty((cells, cells), dtype=np.uint8)
    for r in range(cells):
        for c in range(cells):
            spans = []
            for k in (r, c):
                a = (lo_edge + k * res - img_edge) / src
                b = (lo_edge + (k + 1) * res - img_edge) / src
                spans.append((math.floor(a), math.ceil(b)))
            (r0, r1), (c0, c1) = spans
            inside = r0 >= 0 and c0 >= 0 and r1 <= n and c1 <= n
            out[r, c] = FREE if inside and (pixels[r0:r1, c0:c1] == 255).all() else OBSTACLE
    return out


def test_trav_png_refuses_a_non_square_image(tmp_path):
    path = write_png(tmp_path / "t.png", np.full((10, 12), 255, np.uint8))
    with pytest.raises(ValueError, match=r"path .* square .*12x10"):
        read_trav_png(path)


@pytest.mark.parametrize(
    "image",
    [
        Image.new("RGB", (10, 10), (255, 255, 255)),
        Image.new("RGBA", (10, 10)),
        Image.fromarray(np.full((10, 10), 65535, np.uint16)),
        Image.new("1", (10, 10), 1),
        Image.new("P", (10, 10)),
    ],
    ids=["rgb", "rgba", "16-bit", "1-bit", "palette"],
)
def test_trav_png_refuses_anything_but_8_bit_greyscale(tmp_path, image):
    path = tmp_path / "t.png"
    image.save(path)
    with pytest.raises(ValueError, match=r"path .*8-bit greyscale .*mode 'L'.*got mode"):
        read_trav_png(path)


def test_trav_png_refuses_an_unreadable_file(tmp_path):
    path = tmp_path / "t.png"
    path.write_bytes(b"\x89PNG\r\n\x1a\n this is not a png")
    with pytest.raises(ValueError, match=r"path .* not a readable image"):
        read_trav_png(path)


def test_trav_png_refuses_a_truncated_file(tmp_path):
    noise = np.random.default_rng(0).integers(0, 256, (64, 64), dtype=np.uint8)
    good = write_png(tmp_path / "good.png", noise)
    bad = tmp_path / "bad.png"
    bad.write_bytes(good.read_bytes()[:-40])
    with pytest.raises(ValueError, match=r"path .* not a readable image"):
        read_trav_png(bad)


def test_trav_png_missing_file_is_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError):
        read_trav_png(tmp_path / "nope.png")


@pytest.mark.parametrize("name", ["resolution", "source_resolution"])
@pytest.mark.parametrize("value", [0.0, -0.1, math.nan, math.inf, "fine"])
def test_trav_png_refuses_a_bad_resolution(tmp_path, name, value):
    path = write_png(tmp_path / "t.png", free_image(10))
    with pytest.raises(ValueError, match=rf"^{name} must be a finite number > 0"):
        read_trav_png(path, **{name: value})


# --------------------------------------------------------------------------- read_movingai
def write_map(tmp_path, rows, height=None, width=None, header=None, newline="\n"):
    if header is None:
        header = [
            "type octile",
            f"height {len(rows) if height is None else height}",
            f"width {len(rows[0]) if width is None else width}",
            "map",
        ]
    path = tmp_path / "test.map"
    path.write_bytes(newline.join([*header, *rows, ""]).encode("ascii"))
    return path


def test_movingai_maps_each_character_and_keeps_row_order(tmp_path):
    codes = read_movingai(write_map(tmp_path, [".G", "S@", "OT", "W."]))
    assert codes.dtype == np.uint8
    assert codes.tolist() == [[FREE, FREE], [FREE, OBSTACLE], [OBSTACLE, OBSTACLE], [OBSTACLE, FREE]]


def test_movingai_first_text_row_is_row_0_so_y_points_down_the_file(tmp_path):
    codes = read_movingai(write_map(tmp_path, ["@..", "...", "..."]))
    floor = TraversableMap(codes, 1.0)
    assert floor.cell_class_at([0.5, 0.5]) == OBSTACLE  # low y: first line of the file
    assert floor.cell_class_at([0.5, 2.5]) == FREE


def test_movingai_cell_codes_cover_the_documented_characters():
    assert {c for c, v in MOVINGAI_CELLS.items() if v == FREE} == set(".GS")
    assert {c for c, v in MOVINGAI_CELLS.items() if v == OBSTACLE} == set("@OTW")


def test_movingai_accepts_crlf_and_trailing_blank_lines(tmp_path):
    path = write_map(tmp_path, [".@", "@."], newline="\r\n")
    path.write_bytes(path.read_bytes() + b"\r\n\r\n")
    assert read_movingai(path).tolist() == [[FREE, OBSTACLE], [OBSTACLE, FREE]]


def test_movingai_names_an_unknown_character_with_its_place_and_the_valid_set(tmp_path):
    path = write_map(tmp_path, ["...", "..x"])
    with pytest.raises(ValueError, match=r"unknown character 'x' at map row 1, column 2; valid: '\.GS@OTW'"):
        read_movingai(path)


@pytest.mark.parametrize(
    ("rows", "kwargs", "message"),
    [
        (["...", ".."], {}, r"map row 1 has 2 characters, expected width 3"),
        (["...", "...."], {}, r"map row 1 has 4 characters, expected width 3"),
        (["...", "..."], {"height": 3}, r"height 3 but the map has 2 rows"),
        (["...", "...", "..."], {"height": 2}, r"height 2 but the map has 3 rows"),
    ],
)
def test_movingai_refuses_wrong_row_length_or_count(tmp_path, rows, kwargs, message):
    with pytest.raises(ValueError, match=message):
        read_movingai(write_map(tmp_path, rows, **kwargs))


@pytest.mark.parametrize(
    ("header", "message"),
    [
        (["type octile", "height 1", "width 1"], r"header at line 4; .*then 'map'"),
        (["height 1", "width 1", "map"], r"missing type"),
        (["type octile", "width 1", "map"], r"missing height"),
        (["type grid", "height 1", "width 1", "map"], r"type must be 'octile', got 'grid'"),
        (["type octile", "height one", "width 1", "map"], r"height must be an integer >= 1, got 'one'"),
        (["type octile", "height 1", "width 0", "map"], r"width must be an integer >= 1, got '0'"),
        (["type octile", "height 1", "height 1", "width 1", "map"], r"bad MovingAI header at line 3"),
        (["type octile", "colour red", "height 1", "width 1", "map"], r"bad MovingAI header at line 2"),
    ],
)
def test_movingai_refuses_a_bad_header(tmp_path, header, message):
    with pytest.raises(ValueError, match=message):
        read_movingai(write_map(tmp_path, ["."], header=header))


def test_movingai_refuses_a_file_that_ends_in_the_header(tmp_path):
    path = tmp_path / "test.map"
    path.write_text("type octile\nheight 1\nwidth 1\n")
    with pytest.raises(ValueError, match=r"no 'map' line before the end of the file"):
        read_movingai(path)


def test_movingai_refuses_non_ascii(tmp_path):
    path = tmp_path / "test.map"
    path.write_bytes("type octile\nheight 1\nwidth 1\nmap\n\u00e9\n".encode())
    with pytest.raises(ValueError, match=r"path .* ASCII"):
        read_movingai(path)


def test_movingai_missing_file_is_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError):
        read_movingai(tmp_path / "nope.map")
