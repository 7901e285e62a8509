"""Top-down drawing of a floor, its robots and the task's markers (SPEC section 8).

The drawing itself is pure: numpy and Pillow, no environment or backend. A
:class:`TopDownRenderer` turns one :class:`~pointnav_core.floor.maps.TraversableMap` into an RGB
picture once, then draws frames on copies of it:

==========================  ===============================================================
what                        how it is drawn
==========================  ===============================================================
free / obstacle / void      light / dark / mid grey cells (:data:`FLOOR_COLORS`)
:class:`Marker`             a translucent disc, alpha-blended over what is below it
:class:`RobotGlyph`         an opaque disc in the robot's colour (:data:`ROBOT_PALETTE` by
                            index when it has none) with a heading tick from its centre to
                            the rim along ``yaw``, in a contrasting colour
                            (:func:`contrast_color`)
==========================  ===============================================================

The task's markers use :data:`START_COLOR` (red, radius ``goal_tolerance``),
:data:`GOAL_COLOR` (blue, radius ``goal_tolerance``) and :data:`WAYPOINT_COLOR` (green,
radius ``waypoint_width``). Markers are drawn first, in order, then robots, in order.

Picture geometry
----------------
The image shows the map's whole extent with +x to the right and +y up: image row 0 is the
map's top edge (largest y), column 0 its left edge (smallest x). One metre is
``pixels_per_meter`` pixels (each side rounded to a whole number of pixels, halves up;
:attr:`TopDownRenderer.scale` is the exact scale used). :meth:`TopDownRenderer.world_to_pixel`
gives continuous pixel coordinates ``(col, row)``: pixel ``[i, j]`` covers
``col in [j, j + 1)`` and ``row in [i, i + 1)``, so its centre is ``(j + 0.5, i + 0.5)``.
A floor pixel shows the cell under its centre (as ``TraversableMap.cell_class_at`` finds it).
A disc covers the pixels whose centres lie within its radius (never fewer than the pixel
under its centre); there is no anti-aliasing. A robot's heading tick starts just past the
pixel under its centre, so that pixel always shows the robot's own colour.

From an environment
-------------------
:func:`render_env` is what ``render()`` of the environments calls: it draws the floor of
the (first) task's floor, every robot on it and the visible markers of every task
(``task.markers``, :mod:`~pointnav_core.task.markers`), with a renderer cached on the
environment. :func:`record_episode` runs a policy for one episode and returns its frames.
Frames are saved with :func:`save_png` and :func:`save_gif`. These four live in
:mod:`pointnav_core.render.recording`.

Performance
-----------
Drawing a frame copies the cached floor picture and touches only the bounding box of each
disc, with vectorised numpy masks. A 20 m x 20 m house at the default 20 px/m (400 x 400 px)
with 8 robots and 12 markers takes about 0.5 ms; ``benchmarks/bench_render.py`` measures
it, next to a Pillow ``ImageDraw`` version of the same frame, which is several times slower.
It also times ``env.render()`` of a ``PointNavEnv`` on that house with ``visualize_goal`` and
``visualize_path`` on (one robot, 12 markers, read from the task each frame): about 0.6 ms.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from os import PathLike
from typing import Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.errors import ArgumentError, ArgumentTypeError
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID, TraversableMap
from pointnav_core.render.glyphs import (
    RGB,
    SCAN_HIT_COLOR,
    SCAN_RAY_COLOR,
    Marker,
    RobotGlyph,
    ScanGlyph,
    check_color,
    check_number,
)

__all__ = [
    "FLOOR_COLORS",
    "ROBOT_PALETTE",
    "TopDownRenderer",
    "DEFAULT_PIXELS_PER_METER",
    "contrast_color",
]

DEFAULT_PIXELS_PER_METER = 20.0
"""Scale of :func:`render_env` when neither it nor the environment names one: a 20 m house
is 400 px wide."""

FLOOR_COLORS: Mapping[str, RGB] = {
    "free": (240, 240, 240),
    "obstacle": (50, 50, 50),
    "void": (150, 150, 150),
}
"""Default cell colours by cell class name; override any of them with ``colors=``."""

ROBOT_PALETTE: tuple[RGB, ...] = (
    (255, 127, 14),  # orange
    (148, 103, 189),  # purple
    (23, 190, 207),  # cyan
    (227, 119, 194),  # pink
    (140, 86, 75),  # brown
    (188, 189, 34),  # olive
    (255, 200, 0),  # gold
    (0, 128, 128),  # teal
)
"""Robot colours by robot index (cycled): none of them is a marker colour or a floor grey."""

_FLOOR_CODES = {"free": FREE, "obstacle": OBSTACLE, "void": VOID}
# Refuse pictures beyond this many pixels (about 200 MB as RGB).
_MAX_PIXELS = 1 << 26
# A disc never covers fewer pixels than the one under its centre: sqrt(1/2) reaches the
# centre of the pixel that contains any point.
_MIN_RADIUS_PX = math.sqrt(0.5)

PathArg = Union[str, PathLike]


def contrast_color(color: ArrayLike) -> RGB:
    """Return black or white, whichever stands out more against ``color``.

    This is the colour of a robot's heading tick.

    Parameters
    ----------
    color : (int, int, int)
        An RGB colour, each channel in [0, 255].

    Returns
    -------
    (int, int, int)
        ``(0, 0, 0)`` when the colour's luma (ITU-R BT.601) is at least 128, else
        ``(255, 255, 255)``.

    Examples
    --------
    >>> contrast_color((255, 200, 0))
    (0, 0, 0)
    >>> contrast_color((0, 128, 128))
    (255, 255, 255)
    """
    r, g, b = check_color(color, "color")
    luma = 0.299 * r + 0.587 * g + 0.114 * b
    return (0, 0, 0) if luma >= 128.0 else (255, 255, 255)


class TopDownRenderer:
    """Draw frames of one floor seen from above, with robots and markers.

    The floor picture is built once, here; every :meth:`draw` copies it and draws on the
    copy, so frames are independent arrays.

    Parameters
    ----------
    tmap : TraversableMap
        The floor to draw.
    pixels_per_meter : float, default 20.0
        Picture scale, > 0: a 20 m house is 400 px wide. Each image side is rounded to a
        whole number of pixels (at least 1); :attr:`scale` holds the exact scale per axis.
    colors : mapping of str to (int, int, int), optional
        Cell colours overriding :data:`FLOOR_COLORS`, keyed by ``"free"``, ``"obstacle"``
        or ``"void"``.

    Attributes
    ----------
    tmap : TraversableMap
        The floor.
    floor_image : ndarray of uint8, shape (H, W, 3)
        The floor picture without robots or markers (read-only).
    scale : (float, float)
        Pixels per metre along x (columns) and y (rows).

    Raises
    ------
    TypeError
        When ``tmap`` is not a TraversableMap.
    ValueError
        When ``pixels_per_meter`` is not a finite number > 0, gives a picture beyond
        2**26 pixels, or ``colors`` has an unknown key or a bad colour.

    Examples
    --------
    >>> tmap = TraversableMap([[0, 1], [2, 0]], resolution=1.0, origin=(0.0, 0.0))
    >>> renderer = TopDownRenderer(tmap, pixels_per_meter=4)
    >>> renderer.shape
    (8, 8)
    >>> renderer.world_to_pixel([0.5, 1.5]).tolist()  # cell (1, 0): VOID, top left
    [2.0, 2.0]
    >>> renderer.floor_image[2, 2].tolist() == list(FLOOR_COLORS["void"])
    True
    >>> frame = renderer.draw([RobotGlyph(position_xy=(1.0, 1.0), yaw=0.0, radius=0.5)])
    >>> frame.shape, frame.dtype
    ((8, 8, 3), dtype('uint8'))
    >>> frame[3, 3].tolist() == list(ROBOT_PALETTE[0])
    True
    """

    def __init__(
        self,
        tmap: TraversableMap,
        pixels_per_meter: float = 20.0,
        colors: Mapping[str, ArrayLike] | None = None,
    ) -> None:
        if not isinstance(tmap, TraversableMap):
            raise ArgumentTypeError(f"tmap must be a TraversableMap, got {type(tmap).__name__}")
        ppm = check_number(pixels_per_meter, "pixels_per_meter", " (px/m)", low=0.0, strict=True)
        palette = dict(FLOOR_COLORS)
        for key, value in (colors or {}).items():
            if key not in _FLOOR_CODES:
                raise ArgumentError(f"colors has an unknown key {key!r}; valid keys: {sorted(_FLOOR_CODES)}")
            palette[key] = check_color(value, f"colors[{key!r}]")

        xmin, xmax, ymin, ymax = tmap.extent
        width_m, height_m = xmax - xmin, ymax - ymin
        width = max(1, math.floor(width_m * ppm + 0.5))
        height = max(1, math.floor(height_m * ppm + 0.5))
        if width * height > _MAX_PIXELS:
            raise ArgumentError(
                f"pixels_per_meter={ppm:g} gives a {width} x {height} px picture of this "
                f"{width_m:g} m x {height_m:g} m map, beyond {_MAX_PIXELS} pixels; use a smaller scale"
            )
        self.tmap = tmap
        self.pixels_per_meter = ppm
        self.colors: Mapping[str, RGB] = palette
        self.scale = (width / width_m, height / height_m)
        self._xmin, self._ymax = xmin, ymax

        lut = np.zeros((256, 3), dtype=np.uint8)
        for key, code in _FLOOR_CODES.items():
            lut[code] = palette[key]
        rows_n, cols_n = tmap.shape
        # The cell under each pixel centre, as ``cell_class_at`` finds it (a centre on a cell
        # border belongs to the cell above / to the right); image row 0 is the map's top.
        cols = np.floor((np.arange(width) + 0.5) * cols_n / width).astype(np.intp)
        rows = np.floor(rows_n - (np.arange(height) + 0.5) * rows_n / height).astype(np.intp)
        cols = np.clip(cols, 0, cols_n - 1)
        rows = np.clip(rows, 0, rows_n - 1)
        floor = lut[tmap.codes[rows[:, None], cols[None, :]]]
        floor.flags.writeable = False
        self.floor_image: NDArray[np.uint8] = floor

    @property
    def shape(self) -> tuple[int, int]:
        """Picture size ``(H, W)`` in pixels."""
        return self.floor_image.shape[:2]  # type: ignore[return-value]

    def world_to_pixel(self, xy: ArrayLike) -> NDArray[np.float64]:
        """Continuous pixel coordinates ``(col, row)`` of world points.

        Pixel ``[i, j]`` of a frame covers ``col in [j, j + 1)``, ``row in [i, i + 1)``; a
        point off the map gets coordinates outside ``[0, W) x [0, H)``.

        Parameters
        ----------
        xy : array_like, shape (..., 2)
            World points (x, y) in metres.

        Returns
        -------
        ndarray of float64, shape (..., 2)
            ``(col, row)`` in pixels: col grows with +x, row with -y.

        Examples
        --------
        >>> r = TopDownRenderer(TraversableMap([[0, 0]], 1.0, origin=(-1.0, 0.0)), 10)
        >>> r.world_to_pixel([0.0, 0.5]).tolist()
        [10.0, 5.0]
        >>> r.world_to_pixel([[-1.0, 1.0], [1.0, 0.0]]).tolist()
        [[0.0, 0.0], [20.0, 10.0]]
        """
        xy = np.asarray(xy, dtype=np.float64)
        if xy.shape[-1:] != (2,):
            raise ArgumentError(f"xy must have shape (..., 2) (x, y in metres), got {xy.shape}")
        out = np.empty_like(xy)
        out[..., 0] = (xy[..., 0] - self._xmin) * self.scale[0]
        out[..., 1] = (self._ymax - xy[..., 1]) * self.scale[1]
        return out

    def draw(
        self, robots: Sequence[RobotGlyph], markers: Sequence[Marker] = (), scans: Sequence[ScanGlyph] = ()
    ) -> NDArray[np.uint8]:
        """Draw one frame: the floor, then ``markers`` blended in order, then ``scans``, then ``robots``.

        Parameters
        ----------
        scans : sequence of ScanGlyph, default ()
            Range scans: rays in :data:`SCAN_RAY_COLOR`, hits in :data:`SCAN_HIT_COLOR`.
        robots : sequence of RobotGlyph
            Robots in index order (the index picks the palette colour of a robot without
            one). Later robots are drawn over earlier ones.
        markers : sequence of Marker, default ()
            Translucent discs, each blended over the floor and the markers before it.

        Returns
        -------
        ndarray of uint8, shape (H, W, 3)
            A new RGB array on every call; parts of discs off the picture are clipped.
        """
        image = self.floor_image.copy()
        sx, sy = self.scale
        for k, marker in enumerate(markers):
            if not isinstance(marker, Marker):
                raise ArgumentTypeError(f"markers[{k}] must be a Marker, got {type(marker).__name__}")
            if marker.alpha == 0.0:
                continue
            x, y = marker.position_xy
            disc = _disc(image.shape, (x - self._xmin) * sx, (self._ymax - y) * sy, marker.radius * sx)
            if disc is None:
                continue
            window, mask, _, _ = disc
            patch = image[window]
            below = patch[mask].astype(np.float32)
            color = np.asarray(marker.color, dtype=np.float32)
            patch[mask] = (below + marker.alpha * (color - below) + 0.5).astype(np.uint8)
        for k, scan in enumerate(scans):
            if not isinstance(scan, ScanGlyph):
                raise ArgumentTypeError(f"scans[{k}] must be a ScanGlyph, got {type(scan).__name__}")
            self._draw_scan(image, scan)
        for k, robot in enumerate(robots):
            if not isinstance(robot, RobotGlyph):
                raise ArgumentTypeError(f"robots[{k}] must be a RobotGlyph, got {type(robot).__name__}")
            x, y = robot.position_xy
            radius_px = robot.radius * sx
            disc = _disc(image.shape, (x - self._xmin) * sx, (self._ymax - y) * sy, radius_px)
            if disc is None:
                continue
            window, mask, dx, dy = disc
            color = robot.color if robot.color is not None else ROBOT_PALETTE[k % len(ROBOT_PALETTE)]
            patch = image[window]
            patch[mask] = color
            # The tick: a strip along the heading (image rows grow with -y), inside the disc.
            ux, uy = math.cos(robot.yaw), -math.sin(robot.yaw)
            # It starts past the pixel under the centre, which keeps the robot's colour.
            along = dx * ux + dy * uy
            across = np.abs(dx * uy - dy * ux)
            half_width = max(_MIN_RADIUS_PX, 0.12 * radius_px)
            patch[mask & (along > _MIN_RADIUS_PX) & (across <= half_width)] = contrast_color(color)
        return image

    def _draw_scan(self, image: NDArray[np.uint8], scan: ScanGlyph) -> None:
        """Rays as one-pixel lines (sampled every half pixel), hits as 3 x 3 dots."""
        if not len(scan.hit):
            return
        height, width = image.shape[:2]
        start = self.world_to_pixel(scan.origin_xy)
        ends = self.world_to_pixel(scan.ends_xy)
        longest = float(np.abs(ends - start).max(initial=0.0))
        t = np.linspace(0.0, 1.0, max(2, math.ceil(2.0 * longest) + 1))[None, :, None]
        points = np.floor(start + t * (ends[:, None, :] - start)).reshape(-1, 2).astype(np.intp)
        ok = (points[:, 0] >= 0) & (points[:, 0] < width) & (points[:, 1] >= 0) & (points[:, 1] < height)
        image[points[ok, 1], points[ok, 0]] = SCAN_RAY_COLOR
        dots = np.floor(ends[scan.hit]).astype(np.intp)
        for dc in (-1, 0, 1):
            for dr in (-1, 0, 1):
                cols, rows = dots[:, 0] + dc, dots[:, 1] + dr
                ok = (cols >= 0) & (cols < width) & (rows >= 0) & (rows < height)
                image[rows[ok], cols[ok]] = SCAN_HIT_COLOR

    def __repr__(self) -> str:
        h, w = self.shape
        return f"TopDownRenderer(tmap={self.tmap!r}, pixels_per_meter={self.pixels_per_meter:g}, shape=({h}, {w}))"


def _disc(
    shape: tuple[int, ...], cx: float, cy: float, radius: float
) -> tuple[tuple[slice, slice], NDArray[np.bool_], NDArray[np.float64], NDArray[np.float64]] | None:
    """Pixels of a disc (centre and radius in pixels) within its clipped bounding box.

    Returns the window, the mask over it and the pixel-centre offsets from the disc centre
    (a (1, w) row ``dx`` and an (h, 1) column ``dy``), or None when the disc is off the image.
    """
    radius = max(radius, _MIN_RADIUS_PX)
    height, width = shape[0], shape[1]
    c0 = max(math.floor(cx - radius), 0)
    c1 = min(math.ceil(cx + radius) + 1, width)
    r0 = max(math.floor(cy - radius), 0)
    r1 = min(math.ceil(cy + radius) + 1, height)
    if c0 >= c1 or r0 >= r1:
        return None
    dx = (np.arange(c0, c1, dtype=np.float64) + (0.5 - cx))[None, :]
    dy = (np.arange(r0, r1, dtype=np.float64) + (0.5 - cy))[:, None]
    mask = dx * dx + dy * dy <= radius * radius
    return (slice(r0, r1), slice(c0, c1)), mask, dx, dy
