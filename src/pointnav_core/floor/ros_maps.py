"""ROS occupancy maps: the ``map.yaml`` + image pair of ROS ``map_server`` / ``nav2_map_server``.

Reading follows map_server's rules (nav2_map_server's ``map_io`` as released up to Jazzy,
which kept ROS 1's documented semantics); see ``docs/your-own-map.md``:

* each pixel's *shade* is the mean of its colour channels over the maximum value (0 black,
  1 white); its *occupancy* is ``1 - shade``, or ``shade`` with ``negate: 1``;
* ``mode: trinary`` (the default): occupancy ``> occupied_thresh`` is occupied (100),
  ``< free_thresh`` free (0), anything else unknown (-1); in an image with an alpha channel
  the alpha is averaged in with the colour channels;
* ``mode: scale``: as trinary, but an in-between occupancy becomes
  ``rint((occ - free_thresh) / (occupied_thresh - free_thresh) * 100)``, and a pixel that is
  not fully opaque is unknown;
* ``mode: raw``: ``round(255 * shade)`` if it is 0..100, else unknown; ``negate`` is ignored.

Image row 0 is the map's top (largest y), so rows are flipped; the yaml's ``origin: [x, y,
yaw]`` is the pose of the outer corner of the bottom-left pixel. A floor grid is axis-aligned,
so a yaw must be a quarter turn (the grid is turned, exactly) unless ``ignore_yaw`` reads the
map in its own frame, as most ROS nodes do.

Cells become codes by the rule of nav2's costmap static layer (``trinary_costmap``): unknown
(-1) is ``unknown`` (VOID by default), occupancy ``>= lethal_threshold`` (100) an OBSTACLE,
anything else FREE.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID, TraversableMap
from pointnav_core.utils import validation

__all__ = ["MODES", "RosMap", "occupancy", "read_ros_map", "ros_map_floor", "write_ros_map"]

#: Map modes of map_server's yaml ``mode`` key.
MODES = ("trinary", "scale", "raw")
#: Cell codes an unknown (-1) map cell may become.
UNKNOWN_AS = {"void": VOID, "obstacle": OBSTACLE, "free": FREE}
#: A yaw within this of a quarter turn is one (map_saver writes three digits: 3.14 for pi).
_YAW_TOL = 2e-3
#: Pixel values map_saver writes in trinary mode.
_SAVED = {FREE: 254, OBSTACLE: 0, VOID: 205}


@dataclass(frozen=True)
class RosMap:
    """A ROS map as map_server publishes it.

    Attributes
    ----------
    data : ndarray of int8, shape (H, W)
        Occupancy per cell: -1 unknown, 0..100; ``data[row, col]`` with row 0 at the origin
        (the image's bottom row), as ``OccupancyGrid.data`` reshaped.
    resolution : float
        Metres per cell.
    origin : (float, float, float)
        Pose ``(x, y, yaw)`` (m, m, rad) of the outer corner of cell (0, 0).
    image : str
        The image file read.
    """

    data: NDArray[np.int8]
    resolution: float
    origin: tuple[float, float, float]
    image: str


def _shade(pixels: NDArray[Any], full: float) -> NDArray[np.float64]:
    """Mean of the channels (last axis) over ``full``, as map_server's 16-bit pixels give it."""
    # map_server's GraphicsMagick (16-bit quanta) holds an 8-bit value as v * 257 of 65535 and
    # divides the channels' mean by 65535; the same operations give the same doubles.
    scale = 65535.0 / full
    total = pixels.astype(np.float64).sum(axis=-1) * scale
    return total / pixels.shape[-1] / 65535.0


def occupancy(
    colour: NDArray[Any],
    alpha: NDArray[Any] | None = None,
    *,
    mode: str = "trinary",
    negate: bool = False,
    occupied_thresh: float = 0.65,
    free_thresh: float = 0.196,
    full: float = 255.0,
) -> NDArray[np.int8]:
    """map_server's occupancy (-1, 0..100) of each pixel (see the module notes).

    Parameters
    ----------
    colour : ndarray, shape (H, W) or (H, W, C)
        Grey or colour channel values, 0..``full``.
    alpha : ndarray (H, W), optional
        Alpha (``full`` = opaque), for images that have one.
    mode, negate, occupied_thresh, free_thresh
        The yaml's keys.
    full : float
        The channels' maximum value (255 for 8-bit images, 65535 for 16-bit).
    """
    colour = colour[..., None] if colour.ndim == 2 else colour
    if mode == "raw":
        value = np.floor(_shade(colour, full) * 255.0 + 0.5)  # std::round, values are >= 0
        return np.where(value <= 100, value, -1).astype(np.int8)
    with_alpha = colour
    if alpha is not None and mode == "trinary":  # a grey pixel is three equal channels there
        grey3 = np.repeat(colour, 3, axis=-1) if colour.shape[-1] == 1 else colour
        with_alpha = np.concatenate([grey3, alpha[..., None]], -1)
    shade = _shade(with_alpha, full)
    occ = shade if negate else 1.0 - shade
    out = np.full(occ.shape, -1, np.int8)
    if mode == "scale":
        ratio = (occ - free_thresh) / (occupied_thresh - free_thresh) if occupied_thresh > free_thresh else occ * 0
        out = np.rint(ratio * 100.0).clip(-1, 100).astype(np.int8)
    out[occ > occupied_thresh] = 100
    out[(occ < free_thresh) & (occ <= occupied_thresh)] = 0
    if mode == "scale" and alpha is not None:
        out[alpha != full] = -1
    return out


def _field(doc: dict[str, Any], key: str, where: str, **bounds: Any) -> float:
    if key not in doc:
        raise ArgumentError(f"{where}: no {key!r} (map_server needs it)")
    return validation.real(f"{where}: {key}", doc[key], **bounds)


def _parse_yaml(path: str) -> dict[str, Any]:
    import yaml

    with open(path, encoding="utf-8") as file:
        try:
            doc = yaml.safe_load(file)
        except yaml.YAMLError as exc:
            raise ArgumentError(f"{path!r} is not valid YAML: {exc}") from None
    if not isinstance(doc, dict):
        raise ArgumentError(f"{path!r} must be a map_server yaml (a mapping with image, resolution, ...)")
    where = repr(path)
    out: dict[str, Any] = {"resolution": _field(doc, "resolution", where, minimum=0.0, strict=True, unit="m per pixel")}
    image = doc.get("image")
    if not isinstance(image, str) or not image:
        raise ArgumentError(f"{where}: image must name the map's image file, got {image!r}")
    out["image"] = os.path.join(os.path.dirname(path), image)
    origin = doc.get("origin")
    if not (isinstance(origin, list) and len(origin) == 3 and all(validation.is_real(v) for v in origin)
            and all(math.isfinite(v) for v in origin)):
        raise ArgumentError(f"{where}: origin must be [x, y, yaw] (m, m, rad), got {origin!r}")
    out["origin"] = tuple(float(v) for v in origin)
    mode = doc.get("mode", "trinary")
    if mode not in MODES:
        raise ArgumentError(f"{where}: mode must be one of {list(MODES)}, got {mode!r}")
    negate = doc.get("negate")
    if negate not in (0, 1):  # True and False compare equal to 1 and 0, as yaml-cpp reads them
        raise ArgumentError(f"{where}: negate must be 0 or 1, got {negate!r}")
    occ = _field(doc, "occupied_thresh", where, minimum=0.0, maximum=1.0, unit="")
    free = _field(doc, "free_thresh", where, minimum=0.0, maximum=1.0, unit="")
    if free > occ:
        raise ArgumentError(f"{where}: free_thresh ({free}) must not exceed occupied_thresh ({occ})")
    out.update(mode=mode, negate=bool(negate), occupied_thresh=occ, free_thresh=free)
    return out


def _read_image(path: str, where: str) -> tuple[NDArray[Any], NDArray[Any] | None, float]:
    """Colour channels, alpha (or None) and full scale of a PGM / PNG / BMP image."""
    from PIL import UnidentifiedImageError

    from pointnav_core.floor.loaders import open_image

    if not os.path.isfile(path):
        raise FileNotFoundError(f"{where}: image {path!r} does not exist")
    try:
        with open_image(path, f"{where}: image {path!r}") as image:
            image.load()
            if image.mode in ("1", "P", "PA"):
                image = image.convert("RGBA" if "transparency" in image.info or image.mode == "PA" else "L")
            mode, pixels = image.mode, np.asarray(image)
    except (UnidentifiedImageError, OSError, SyntaxError) as exc:
        raise ArgumentError(f"{where}: image {path!r} is not a readable image: {exc}") from None
    if mode in ("L", "RGB"):
        return pixels, None, 255.0
    if mode in ("LA", "RGBA"):
        return pixels[..., :-1], pixels[..., -1], 255.0
    if mode in ("I", "I;16", "I;16B", "I;16L") and pixels.min() >= 0 and pixels.max() <= 65535:
        return pixels, None, 65535.0
    raise ArgumentError(f"{where}: image {path!r} has pixel mode {mode!r}; expected grey, RGB(A) or 16-bit grey")


def read_ros_map(yaml_path: str | os.PathLike[str]) -> RosMap:
    """Read a map_server ``map.yaml`` and its image as map_server does (see the module notes).

    Raises
    ------
    FileNotFoundError
        When the yaml or its image does not exist (the message names both).
    ValueError
        When a key is missing or out of range, or the image cannot be read; the message names
        the file and the key.
    """
    path = os.fspath(yaml_path)
    params = _parse_yaml(path)
    colour, alpha, full = _read_image(params["image"], f"{path!r}")
    data = occupancy(
        colour, alpha, mode=params["mode"], negate=params["negate"], full=full,
        occupied_thresh=params["occupied_thresh"], free_thresh=params["free_thresh"],
    )
    return RosMap(np.ascontiguousarray(data[::-1]), params["resolution"], params["origin"], params["image"])


def _turn(codes: NDArray[np.uint8], res: float, origin: tuple[float, float, float], where: str,
          ignore_yaw: bool) -> tuple[NDArray[np.uint8], tuple[float, float]]:
    """The grid and outer corner of cell (0, 0) in the world frame, for a quarter-turn yaw."""
    x0, y0, yaw = origin
    quarter = yaw / (math.pi / 2)
    k = round(quarter) % 4
    if ignore_yaw or k == 0 and abs(quarter - round(quarter)) <= _YAW_TOL:
        return codes, (x0, y0)
    if abs(quarter - round(quarter)) > _YAW_TOL:
        raise ArgumentError(
            f"{where}: origin yaw {yaw} rad is not a quarter turn; a floor grid is axis-aligned, "
            "so pass ignore_yaw=True to read the map in its own frame (as most ROS nodes do)"
        )
    h, w = codes.shape
    cos, sin = ((1, 0), (0, 1), (-1, 0), (0, -1))[k]
    corners = [(cos * x - sin * y, sin * x + cos * y) for x in (0.0, w * res) for y in (0.0, h * res)]
    # np.rot90 with k = -1 turns the grid's contents a quarter turn counter-clockwise when
    # rows grow with +y (cell (r, c) of the result is cell (H - 1 - c, r) of the map).
    turned = np.ascontiguousarray(np.rot90(codes, -k))
    return turned, (x0 + min(c[0] for c in corners), y0 + min(c[1] for c in corners))


def ros_map_floor(
    yaml_path: str | os.PathLike[str],
    *,
    unknown: str = "void",
    lethal_threshold: int = 100,
    ignore_yaw: bool = False,
    height: float = 0.0,
) -> TraversableMap:
    """One floor from a ROS map (what :meth:`Scene.from_ros_map` wraps).

    Parameters
    ----------
    yaml_path : str or os.PathLike
        The map's yaml file.
    unknown : {"void", "obstacle", "free"}
        What an unknown cell becomes (VOID: off the floor, nothing is sampled there).
    lethal_threshold : int
        Occupancy (1..100) from which a cell is an obstacle; nav2's costmap default is 100.
    ignore_yaw : bool
        Read a map whose origin yaw is not a quarter turn in its own frame.
    height : float
        Floor height (m).
    """
    if unknown not in UNKNOWN_AS:
        raise ArgumentError(f"unknown must be one of {list(UNKNOWN_AS)}, got {unknown!r}")
    lethal = validation.integer("lethal_threshold", lethal_threshold, minimum=1)
    if lethal > 100:
        raise ArgumentError(f"lethal_threshold must be an integer in 1..100, got {lethal_threshold!r}")
    ignore_yaw = validation.boolean("ignore_yaw", ignore_yaw)
    ros = read_ros_map(yaml_path)
    codes = np.where(ros.data < 0, UNKNOWN_AS[unknown], np.where(ros.data >= lethal, OBSTACLE, FREE))
    codes, corner = _turn(codes.astype(np.uint8), ros.resolution, ros.origin, repr(os.fspath(yaml_path)), ignore_yaw)
    return TraversableMap(codes, ros.resolution, corner, height)


def write_ros_map(tmap: TraversableMap, yaml_path: str | os.PathLike[str], image: str | None = None) -> str:
    """Write a floor as a trinary map_server map: ``yaml_path`` and a PGM image beside it.

    FREE cells are written 254, OBSTACLE 0 and VOID 205 (unknown), as map_saver does, with
    ``free_thresh: 0.196`` and ``occupied_thresh: 0.65``, so that map_server and
    :func:`read_ros_map` read the same cells back. Only the grid is written: a floor's
    polygons (``TraversableMap.geometry``) have no place in the format. Returns the image path.
    """
    import yaml
    from PIL import Image

    path = os.fspath(yaml_path)
    if not path.endswith((".yaml", ".yml")):
        raise ArgumentError(f"yaml_path must end with .yaml or .yml, got {path!r}")
    name = image or os.path.splitext(os.path.basename(path))[0] + ".pgm"
    pixels = np.zeros(tmap.shape, np.uint8)
    for code, value in _SAVED.items():
        pixels[tmap.codes == code] = value
    image_path = os.path.join(os.path.dirname(path), name)
    Image.fromarray(np.ascontiguousarray(pixels[::-1]), mode="L").save(image_path)
    doc = {
        "image": name, "mode": "trinary", "resolution": tmap.resolution,
        "origin": [tmap.origin[0], tmap.origin[1], 0.0], "negate": 0,
        "occupied_thresh": 0.65, "free_thresh": 0.196,
    }
    with open(path, "w", encoding="utf-8") as file:
        yaml.safe_dump(doc, file, sort_keys=False, default_flow_style=None)
    return image_path
