"""ROS map_server maps: thresholds against a hand table, frames, real maps, round trip, bad files.

The references are map_server's rules written out here: the hand tables below were worked
out with exact fractions from ``occ = 1 - p / 255`` (``p / 255`` with ``negate``), the
strict comparisons ``occ > occupied_thresh`` / ``occ < free_thresh``, and
``rint((occ - free) / (occupied - free) * 100)`` in scale mode.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from pointnav_core.datasets import load_scene
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID
from pointnav_core.floor.ros_maps import read_ros_map
from pointnav_core.scenes import Scene

DATA = Path(__file__).parent / "data"
U = -1  # unknown

# occupied_thresh 0.65, free_thresh 0.196. negate 0: occ = 1 - p/255 > 0.65 iff p <= 89;
# < 0.196 iff p >= 206. negate 1: occ = p/255 > 0.65 iff p >= 166; < 0.196 iff p <= 49.
SCALE_GREY = [  # scale mode, negate 0, p = 90 .. 205
    99, 98, 98, 97, 96, 95, 94, 93, 92, 92, 91, 90, 89, 88, 87, 86, 86, 85, 84, 83, 82, 81,
    80, 79, 79, 78, 77, 76, 75, 74, 73, 73, 72, 71, 70, 69, 68, 67, 67, 66, 65, 64, 63, 62,
    61, 60, 60, 59, 58, 57, 56, 55, 54, 54, 53, 52, 51, 50, 49, 48, 48, 47, 46, 45, 44, 43,
    42, 41, 41, 40, 39, 38, 37, 36, 35, 35, 34, 33, 32, 31, 30, 29, 29, 28, 27, 26, 25, 24,
    23, 22, 22, 21, 20, 19, 18, 17, 16, 16, 15, 14, 13, 12, 11, 10, 10, 9, 8, 7, 6, 5, 4, 3,
    3, 2, 1, 0,
]
SCALE_GREY_NEGATED = [  # scale mode, negate 1, p = 50 .. 165
    0, 1, 2, 3, 3, 4, 5, 6, 7, 8, 9, 10, 10, 11, 12, 13, 14, 15, 16, 16, 17, 18, 19, 20, 21,
    22, 22, 23, 24, 25, 26, 27, 28, 29, 29, 30, 31, 32, 33, 34, 35, 35, 36, 37, 38, 39, 40,
    41, 41, 42, 43, 44, 45, 46, 47, 48, 48, 49, 50, 51, 52, 53, 54, 54, 55, 56, 57, 58, 59,
    60, 60, 61, 62, 63, 64, 65, 66, 67, 67, 68, 69, 70, 71, 72, 73, 73, 74, 75, 76, 77, 78,
    79, 79, 80, 81, 82, 83, 84, 85, 86, 86, 87, 88, 89, 90, 91, 92, 92, 93, 94, 95, 96, 97,
    98, 98, 99,
]
EXPECTED = {
    ("trinary", 0): [100] * 90 + [U] * 116 + [0] * 50,
    ("trinary", 1): [0] * 50 + [U] * 116 + [100] * 90,
    ("scale", 0): [100] * 90 + SCALE_GREY + [0] * 50,
    ("scale", 1): [0] * 50 + SCALE_GREY_NEGATED + [100] * 90,
    ("raw", 0): list(range(101)) + [U] * 155,  # nav2 reads raw values as they are
    ("raw", 1): list(range(101)) + [U] * 155,  # and ignores negate in raw mode
}


def write_map(folder: Path, pixels: np.ndarray, name: str = "map", fmt: str = "pgm", **keys) -> Path:
    """A map_server map: the image (row 0 = top) and its yaml, with ``keys`` overriding."""
    image = folder / f"{name}.{fmt}"
    Image.fromarray(np.asarray(pixels, np.uint8)).save(image)
    doc = {"image": image.name, "resolution": 0.05, "origin": "[0.0, 0.0, 0.0]", "negate": 0,
           "occupied_thresh": 0.65, "free_thresh": 0.196}
    doc.update(keys)
    text = "".join(f"{k}: {v}\n" for k, v in doc.items() if v is not None)
    (folder / f"{name}.yaml").write_text(text)
    return folder / f"{name}.yaml"


@pytest.mark.parametrize("mode, negate", sorted(EXPECTED))
def test_every_pixel_value_is_thresholded_as_map_server_does(tmp_path, mode, negate):
    assert all(len(v) == 256 for v in EXPECTED.values())
    yaml_path = write_map(tmp_path, np.arange(256)[None, :], mode=mode, negate=negate)
    assert read_ros_map(yaml_path).data[0].tolist() == EXPECTED[(mode, negate)]


def test_plain_pgm_p2_reads_like_p5(tmp_path):
    (tmp_path / "p2.pgm").write_text("P2\n# plain\n4 1\n255\n0 205 206 254\n")
    yaml_path = tmp_path / "p2.yaml"
    yaml_path.write_text("image: p2.pgm\nresolution: 0.1\norigin: [0, 0, 0]\nnegate: 0\n"
                         "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    assert read_ros_map(yaml_path).data.tolist() == [[100, U, 0, 0]]


def test_alpha_is_averaged_in_trinary_and_unknown_in_scale(tmp_path):
    # White, fully transparent: trinary averages (255, 255, 255, 0) to 191.25, occ 0.25.
    pixels = np.array([[[255, 255, 255, 0], [255, 255, 255, 255], [0, 0, 0, 254]]], np.uint8)
    for mode, expected in (("trinary", [U, 0, 100]), ("scale", [U, 0, U])):
        yaml_path = write_map(tmp_path, pixels, fmt="png", mode=mode)
        assert read_ros_map(yaml_path).data[0].tolist() == expected


def test_rows_flip_and_origin_is_the_bottom_left_corner(tmp_path):
    pixels = np.array([[0, 254, 254], [254, 254, 205]])  # top row first
    yaml_path = write_map(tmp_path, pixels, origin="[-1.0, 2.0, 0.0]")
    tmap = Scene.from_ros_map(yaml_path).floors[0]
    assert tmap.codes.tolist() == [[FREE, FREE, VOID], [OBSTACLE, FREE, FREE]]
    assert tmap.origin == (-1.0, 2.0) and tmap.resolution == 0.05
    assert int(tmap.cell_class_at([-1.0 + 0.025, 2.0 + 0.075])) == OBSTACLE  # top-left pixel


@pytest.mark.parametrize("quarter", [0, 1, 2, 3, -1])
def test_a_quarter_turn_yaw_turns_the_grid(tmp_path, quarter):
    rng = np.random.default_rng(quarter % 4)
    pixels = rng.choice([0, 205, 254], size=(5, 7))
    code = {0: OBSTACLE, 205: VOID, 254: FREE}
    yaw = quarter * math.pi / 2
    yaml_path = write_map(tmp_path, pixels, origin=f"[0.3, -0.7, {yaw!r}]")
    tmap = Scene.from_ros_map(yaml_path, unknown="void").floors[0]
    assert sorted(tmap.shape) == [5, 7]
    res, h = 0.05, pixels.shape[0]
    c, s = math.cos(yaw), math.sin(yaw)
    for y in range(pixels.shape[0]):
        for x in range(pixels.shape[1]):
            lx, ly = (x + 0.5) * res, (h - 1 - y + 0.5) * res  # the pixel's centre, map frame
            world = (0.3 + c * lx - s * ly, -0.7 + s * lx + c * ly)
            assert int(tmap.cell_class_at(world)) == code[pixels[y, x]], (x, y)


def test_a_yaw_that_is_not_a_quarter_turn_is_refused_or_ignored(tmp_path):
    yaml_path = write_map(tmp_path, np.full((3, 4), 254), origin="[1.0, 2.0, 0.5]")
    with pytest.raises(ValueError, match=r"map\.yaml.*yaw 0\.5.*ignore_yaw=True"):
        Scene.from_ros_map(yaml_path)
    tmap = Scene.from_ros_map(yaml_path, ignore_yaw=True).floors[0]
    assert tmap.shape == (3, 4) and tmap.origin == (1.0, 2.0)


def test_unknown_and_lethal_threshold_are_configurable(tmp_path):
    # 150: occ = 105/255 = 0.4118, scaled rint((0.4118 - 0.196) / 0.454 * 100) = 48; 205 is
    # just above free_thresh in scale mode: rint(0.0173) = 0.
    yaml_path = write_map(tmp_path, np.array([[205, 150, 254]]), mode="scale")
    assert read_ros_map(yaml_path).data.tolist() == [[0, 48, 0]]
    assert Scene.from_ros_map(yaml_path).floors[0].codes.tolist() == [[FREE, FREE, FREE]]
    codes = Scene.from_ros_map(yaml_path, lethal_threshold=48).floors[0].codes
    assert codes.tolist() == [[FREE, OBSTACLE, FREE]]
    trinary = write_map(tmp_path, np.array([[205, 0, 254]]), name="tri")
    for unknown, code in (("void", VOID), ("obstacle", OBSTACLE), ("free", FREE)):
        codes = Scene.from_ros_map(trinary, unknown=unknown).floors[0].codes
        assert codes.tolist() == [[code, OBSTACLE, FREE]]
    with pytest.raises(ValueError, match="unknown must be one of"):
        Scene.from_ros_map(yaml_path, unknown="maybe")
    with pytest.raises(ValueError, match="lethal_threshold"):
        Scene.from_ros_map(yaml_path, lethal_threshold=True)


def usable_reference(codes: np.ndarray, radius_cells: float) -> np.ndarray:
    """Cells whose centre is at least ``radius_cells`` from every non-FREE cell square and
    from outside the grid, by brute force over offsets (squared distances in half cells)."""
    reach = math.ceil(radius_cells) + 1
    blocked = np.pad(codes != FREE, reach, constant_values=True)
    hit = np.zeros(codes.shape, bool)
    h, w = codes.shape
    for di in range(-reach, reach + 1):
        for dj in range(-reach, reach + 1):
            gap2 = max(2 * abs(di) - 1, 0) ** 2 + max(2 * abs(dj) - 1, 0) ** 2  # (2 * distance)^2
            if gap2 < (2 * radius_cells) ** 2:
                hit |= blocked[reach + di : reach + di + h, reach + dj : reach + dj + w]
    return (codes == FREE) & ~hit


@pytest.mark.parametrize(
    "folder, name, free_shades, origin, shape",
    [
        ("nav2_maps", "tb3_sandbox", (254,), (-10.0, -10.0), (384, 384)),
        ("nav2_maps", "depot", (205, 254), (0.0, 0.0), (307, 604)),  # free_thresh 0.25 > 50/255
        ("bookstore", "map", (254,), (-10.0, -10.0), (384, 384)),
    ],
)
def test_real_ros_maps_give_exactly_the_usable_cells(folder, name, free_shades, origin, shape):
    pixels = np.asarray(Image.open(DATA / folder / f"{name}.pgm"))
    assert set(np.unique(pixels).tolist()) <= {0, 205, 254}
    codes = np.full(pixels.shape, VOID, np.uint8)
    codes[np.isin(pixels, free_shades)] = FREE
    codes[pixels == 0] = OBSTACLE
    codes = codes[::-1]
    tmap = Scene.from_ros_map(DATA / folder / f"{name}.yaml").floors[0]
    assert tmap.shape == shape and tmap.origin == origin and tmap.resolution == 0.05
    np.testing.assert_array_equal(tmap.codes, codes)
    usable = tmap.usable(0.18)
    expected = usable_reference(codes, 0.18 / 0.05)
    assert usable.sum() > 1000
    np.testing.assert_array_equal(usable, expected)


def test_to_ros_map_round_trips(tmp_path):
    rng = np.random.default_rng(3)
    codes = rng.choice([FREE, FREE, OBSTACLE, VOID], size=(9, 14)).astype(np.uint8)
    scene = Scene.from_array(codes, resolution=0.05, origin=(-1.25, 3.5))
    image = scene.to_ros_map(tmp_path / "out.yaml")
    assert Path(image).name == "out.pgm" and np.asarray(Image.open(image)).shape == (9, 14)
    back = Scene.from_ros_map(tmp_path / "out.yaml").floors[0]
    np.testing.assert_array_equal(back.codes, codes)
    assert back.origin == (-1.25, 3.5) and back.resolution == 0.05
    for name in ("tb3_sandbox", "depot"):  # real maps: the same cells after a save and a load
        real = Scene.from_ros_map(DATA / "nav2_maps" / f"{name}.yaml")
        real.to_ros_map(tmp_path / f"{name}.yaml")
        again = Scene.from_ros_map(tmp_path / f"{name}.yaml").floors[0]
        np.testing.assert_array_equal(again.codes, real.floors[0].codes)
        assert again.origin == real.floors[0].origin


def test_from_png_refuses_a_ros_map_and_names_from_ros_map(tmp_path):
    with pytest.raises(ValueError, match=r"tb3_sandbox\.pgm.*from_ros_map"):
        Scene.from_png(DATA / "nav2_maps" / "tb3_sandbox.pgm")
    png = tmp_path / "ros.png"
    Image.fromarray(np.asarray(Image.open(DATA / "nav2_maps" / "tb3_sandbox.pgm"))).save(png)
    with pytest.raises(ValueError, match=r"254.*205.*from_ros_map"):
        Scene.from_png(png)


BAD = {
    "no resolution": ({"resolution": None}, ValueError, r"bad\.yaml.*'resolution'"),
    "negative resolution": ({"resolution": -0.05}, ValueError, r"bad\.yaml.*resolution must be .*> 0.*-0\.05"),
    "missing image": ({"image": "nowhere.pgm"}, FileNotFoundError, r"bad\.yaml.*image .*nowhere\.pgm"),
    "origin of two numbers": ({"origin": "[0, 0]"}, ValueError, r"bad\.yaml.*origin must be \[x, y, yaw\]"),
    "unknown mode": ({"mode": "binary"}, ValueError, r"bad\.yaml.*mode must be one of"),
    "thresholds crossed": ({"free_thresh": 0.7}, ValueError, r"bad\.yaml.*free_thresh"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_map_files_are_refused_naming_the_file_and_the_field(tmp_path, case):
    keys, error, message = BAD[case]
    write_map(tmp_path, np.full((4, 4), 254), name="bad", **keys)
    with pytest.raises(error, match=message):
        Scene.from_ros_map(tmp_path / "bad.yaml")


def test_a_truncated_pgm_is_refused_and_nothing_half_built_is_kept(tmp_path):
    yaml_path = write_map(tmp_path, np.full((40, 40), 254), name="cut")
    whole = (tmp_path / "cut.pgm").read_bytes()
    (tmp_path / "cut.pgm").write_bytes(whole[: len(whole) // 2])
    with pytest.raises(ValueError, match=r"cut\.yaml.*image .*cut\.pgm.*not a readable image"):
        load_scene(str(yaml_path))
    (tmp_path / "cut.pgm").write_bytes(whole)  # mended: the same scene_id now builds afresh
    assert load_scene(str(yaml_path)).floors[0].free.sum() == 1600


def test_a_16_bit_pgm_is_read_at_its_own_depth(tmp_path):
    # occupancy 1 - v / 65535: 0 -> 1 (occupied), 65535 -> 0 (free), 50000 -> 0.237 (unknown)
    body = np.array([[0, 65535, 50000]], ">u2").tobytes()
    (tmp_path / "deep.pgm").write_bytes(b"P5\n3 1\n65535\n" + body)
    (tmp_path / "deep.yaml").write_text("image: deep.pgm\nresolution: 0.1\norigin: [0, 0, 0]\nnegate: 0\n"
                                        "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    assert read_ros_map(tmp_path / "deep.yaml").data.tolist() == [[100, 0, U]]


def test_an_image_over_the_cell_budget_is_refused_before_it_is_decoded(tmp_path):
    # A P5 header for 20000 x 20000 pixels and almost no data: decoding it would need
    # 400 MB; the budget is checked on the header's size.
    (tmp_path / "huge.pgm").write_bytes(b"P5\n20000 20000\n255\n" + bytes(16))
    (tmp_path / "huge.yaml").write_text(
        "image: huge.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    with pytest.raises(ValueError, match=r"huge\.pgm.*over the cell budget"):
        Scene.from_ros_map(tmp_path / "huge.yaml")
