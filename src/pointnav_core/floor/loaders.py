"""Read floor grids from files: OmniGibson traversability images and MovingAI ``.map`` files.

Each reader is a pure function from a file to an array of cell codes (:data:`~pointnav_core.floor.maps.FREE`,
:data:`~pointnav_core.floor.maps.OBSTACLE`, :data:`~pointnav_core.floor.maps.VOID`) in the grid geometry
of :class:`~pointnav_core.floor.maps.TraversableMap`: row ``i`` grows with +y, column ``j`` with +x.
Scene constructors wrap the arrays into maps; nothing here keeps state.

A missing file raises :class:`FileNotFoundError`, as :func:`open` does; a file that exists but
is not what the reader expects raises :class:`ValueError` naming the parameter at fault.

On :func:`read_trav_png`'s geometry: OmniGibson itself resizes with bilinear interpolation and then
keeps only cells equal to 255, and looks cells up with ``round(xy / res + N / 2)``, which puts its
cell centres half a cell away from the pixel geometry. Here a cell covers exactly the square its
pixels cover, so world positions agree with the image to within one source pixel.
"""

from __future__ import annotations

import math
import os
import re
import warnings

import numpy as np
from numpy.typing import NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.floor.maps import FREE, OBSTACLE
from pointnav_core.utils import validation

__all__ = ["MOVINGAI_CELLS", "open_image", "read_movingai", "read_trav_png"]

_ROS_HINT = (
    "read a ROS map with Scene.from_ros_map(<its map.yaml>), any other grid with Scene.from_array"
)
_ROS_SHADES = np.array([205, 254], np.uint8)
# Tolerance used when snapping pixel edges that should be whole numbers (0.1 / 0.01 is not 10).
_EDGE_TOL = 1e-6

#: Meaning of each MovingAI terrain character. Out of bounds (``@``, ``O``), trees and water
#: all block motion; in a game map out of bounds is a wall, so none of them is VOID.
MOVINGAI_CELLS: dict[str, int] = {
    ".": FREE,  # passable terrain
    "G": FREE,  # passable terrain
    "S": FREE,  # swamp: passable
    "@": OBSTACLE,  # out of bounds
    "O": OBSTACLE,  # out of bounds
    "T": OBSTACLE,  # trees
    "W": OBSTACLE,  # water
}


def _check_resolution(value: float, name: str) -> float:
    return validation.real(name, value, minimum=0.0, strict=True, unit="metres per cell")


def read_trav_png(
    path: str | os.PathLike[str],
    resolution: float = 0.1,
    source_resolution: float = 0.01,
) -> tuple[NDArray[np.uint8], tuple[float, float]]:
    """Read an OmniGibson ``floor_trav_<n>.png`` image as a grid of cell codes.

    The image is 8-bit greyscale and square, ``source_resolution`` metres per pixel, centred
    on the world origin, with the image row index growing with +y (OmniGibson's
    ``world_to_map`` maps ``(x, y)`` to ``(row=y, col=x)``). A pixel of 255 is free floor;
    anything lower is blocked (:data:`~pointnav_core.floor.maps.OBSTACLE`).

    Resampling to ``resolution`` is conservative: a cell is FREE only when every source pixel
    it overlaps is 255. The resampled grid has ``ceil(size_m / resolution)`` cells a side and
    is centred on the world origin, so when the image size is not a whole number of cells the
    missing strip, split evenly between both edges, counts as blocked. A ``resolution`` finer
    than ``source_resolution`` repeats pixels (nearest neighbour).

    Parameters
    ----------
    path : str or os.PathLike
        The PNG file.
    resolution : float, default 0.1
        Metres per cell of the returned grid, > 0.
    source_resolution : float, default 0.01
        Metres per pixel of the image, > 0 (OmniGibson's maps are 0.01).

    Returns
    -------
    codes : ndarray of uint8, shape (N, N)
        FREE (0) or OBSTACLE (1) per cell; ``codes[row, col]`` with row growing with +y.
    origin : (float, float)
        World ``(x, y)`` in metres of the outer corner of cell ``(0, 0)``:
        ``(-N * resolution / 2, -N * resolution / 2)``.

    Raises
    ------
    FileNotFoundError
        When ``path`` does not exist.
    ValueError
        When the file is not a readable image, is not 8-bit greyscale (mode ``"L"``; RGB,
        palette or 16-bit images are refused, not converted), is not square, is a PGM or
        holds map_saver's free (254) and unknown (205) shades (a ROS map: use
        ``Scene.from_ros_map``), or a resolution is not a finite positive number.

    See Also
    --------
    pointnav_core.floor.maps.TraversableMap : wraps ``codes``, ``resolution`` and ``origin``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from PIL import Image
    >>> pixels = np.full((40, 40), 255, np.uint8)
    >>> pixels[30:, :10] = 0  # a blocked square at +y (high rows), -x (low columns)
    >>> tmp = tempfile.TemporaryDirectory()
    >>> png = pathlib.Path(tmp.name) / "floor_trav_0.png"
    >>> Image.fromarray(pixels, mode="L").save(png)
    >>> codes, origin = read_trav_png(png, resolution=0.1)
    >>> codes
    array([[0, 0, 0, 0],
           [0, 0, 0, 0],
           [0, 0, 0, 0],
           [1, 0, 0, 0]], dtype=uint8)
    >>> origin
    (-0.2, -0.2)
    >>> read_trav_png(png, resolution=0.15)[0].shape  # 0.4 m is not whole 0.15 m cells
    (3, 3)
    >>> tmp.cleanup()
    """
    resolution = _check_resolution(resolution, "resolution")
    source_resolution = _check_resolution(source_resolution, "source_resolution")
    factor = resolution / source_resolution  # source pixels per cell, along one axis
    codes = _resampled(_blocked_pixels(path), factor)
    half = codes.shape[0] * resolution / 2.0
    return codes, (-half, -half)


def _blocked_pixels(path: str | os.PathLike[str]) -> NDArray[np.bool_]:
    """The pixels below 255 of an 8-bit greyscale square image; raises as :func:`read_trav_png`."""
    where = f"path {os.fspath(path)!r}"
    from PIL import UnidentifiedImageError  # only this reader needs Pillow

    try:
        with open_image(path, where) as image:
            image.load()
            mode, (width, height) = image.mode, image.size
            if mode != "L":
                raise ArgumentError(
                    f"{where} must be an 8-bit greyscale image (mode 'L'), got mode {mode!r}; "
                    "convert it explicitly if its values mean traversability"
                )
            if image.format == "PPM":
                raise ArgumentError(f"{where} is a PGM image, as ROS map_server maps are: {_ROS_HINT}")
            if width != height:
                raise ArgumentError(
                    f"{where} must be a square image (OmniGibson's are), got {width}x{height} "
                    f"pixels: {_ROS_HINT}"
                )
            pixels = np.asarray(image)
    except FileNotFoundError:
        raise
    except (UnidentifiedImageError, OSError, SyntaxError) as exc:
        # Pillow reports undecodable or truncated files as any of these.
        raise ArgumentError(f"{where} is not a readable image: {exc}") from exc
    if np.isin(_ROS_SHADES, pixels).all():
        # map_saver's free (254) and unknown (205) would all read as blocked here.
        raise ArgumentError(f"{where} holds ROS map_saver's free (254) and unknown (205) shades: {_ROS_HINT}")
    return pixels < 255


def _resampled(blocked: NDArray[np.bool_], factor: float) -> NDArray[np.uint8]:
    """Cell codes of the square pixel mask ``blocked`` at ``factor`` pixels a cell, centred.

    A cell is FREE only when no pixel it overlaps is blocked and it lies inside the image.
    """
    n_pixels = blocked.shape[0]
    n_cells = max(1, math.ceil(n_pixels / factor - _EDGE_TOL))
    # Pixel coordinate of the grid's outer edge: <= 0, half the padding when not divisible.
    offset = (n_pixels - n_cells * factor) / 2.0
    starts, stops = _pixel_spans(offset + factor * np.arange(n_cells), factor)
    # A cell is blocked when any pixel of its rows x cols block is; "any" is separable.
    any_rows = _any_in_spans(blocked, starts, stops, axis=0)
    any_cells = _any_in_spans(any_rows, starts, stops, axis=1)
    outside = (starts < 0) | (stops > n_pixels)  # a cell reaching past the image edge
    any_cells |= outside[:, None] | outside[None, :]
    return np.where(any_cells, OBSTACLE, FREE).astype(np.uint8)


def open_image(path: str | os.PathLike[str], where: str):  # -> PIL.Image.Image
    """Open (not decode) an image within the cell budget (:func:`validation.cell_budget`).

    Pillow's own bomb check is replaced by the library's budget, applied to the header's
    size before any pixel is decoded; an image beyond Pillow's hard limit is over it too.
    """
    from PIL import Image

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            image = Image.open(path)
    except Image.DecompressionBombError:
        raise ArgumentError(
            f"{where} (image) is over the cell budget of {validation.MAX_CELLS} "
            "(pointnav_core.utils.validation.MAX_CELLS)"
        ) from None
    try:
        validation.cell_budget(f"{where} (image)", image.size[1], image.size[0])
    except ValueError:
        image.close()
        raise
    return image


def _pixel_spans(lo: NDArray[np.float64], factor: float) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Half-open ranges ``[start, stop)`` of the pixels each cell ``[lo, lo + factor)`` overlaps."""
    hi = lo + factor
    starts = np.floor(lo + _EDGE_TOL).astype(np.int64)
    stops = np.ceil(hi - _EDGE_TOL).astype(np.int64)
    return starts, np.maximum(stops, starts + 1)


def _any_in_spans(
    mask: NDArray[np.bool_], starts: NDArray[np.int64], stops: NDArray[np.int64], axis: int
) -> NDArray[np.bool_]:
    """Reduce ``mask`` along ``axis``: output ``k`` is ``mask[starts[k]:stops[k]].any()``."""
    n = mask.shape[axis]
    counts = np.cumsum(mask, axis=axis, dtype=np.int32)
    counts = np.concatenate([np.zeros_like(np.take(counts, [0], axis=axis)), counts], axis=axis)
    hi = np.take(counts, np.clip(stops, 0, n), axis=axis)
    lo = np.take(counts, np.clip(starts, 0, n), axis=axis)
    return hi > lo


_HEADER_LINE = re.compile(r"^(type|height|width)\s+(\S+)$")


def read_movingai(path: str | os.PathLike[str]) -> NDArray[np.uint8]:
    """Read a MovingAI grid benchmark ``.map`` file as a grid of cell codes.

    The format is a header ``type octile``, ``height H``, ``width W``, ``map``, then ``H`` rows
    of ``W`` characters: ``.``, ``G`` and ``S`` are free; ``@``, ``O``, ``T`` and ``W`` are
    :data:`~pointnav_core.floor.maps.OBSTACLE` (out of bounds in a game map is a wall, not a drop,
    so nothing is VOID). See :data:`MOVINGAI_CELLS`.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.map`` file (ASCII; ``\\n`` or ``\\r\\n`` line ends).

    Returns
    -------
    codes : ndarray of uint8, shape (H, W)
        ``codes[i, j]`` is character ``j`` of the file's ``i``-th map row. The grid has no
        resolution of its own: one character is one cell, whatever size the scene gives it.

    Raises
    ------
    FileNotFoundError
        When ``path`` does not exist.
    ValueError
        When the header is malformed, a row has the wrong length, the number of rows is not
        ``height``, or a character is not one of :data:`MOVINGAI_CELLS` (the message names the
        character, its row and column, and the valid set).

    Notes
    -----
    The file's first map row becomes row 0, and rows grow with +y in a
    :class:`~pointnav_core.floor.maps.TraversableMap`. Plotted with +y up, the map therefore appears
    mirrored top to bottom relative to the text file (or to MovingAI's pictures, which draw row
    0 at the top). A mirror image has the same distances, paths and connectivity, and keeping
    row order means that the benchmark's ``(x, y)`` = ``(column, row)`` coordinates index the
    array directly as ``codes[y, x]``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = pathlib.Path(tmp.name) / "tiny.map"
    >>> _ = path.write_text("type octile\\nheight 2\\nwidth 3\\nmap\\n..@\\nT.S\\n")
    >>> read_movingai(path)
    array([[0, 0, 1],
           [1, 0, 0]], dtype=uint8)
    >>> tmp.cleanup()
    """
    with open(path, "rb") as file:
        raw = file.read()
    try:
        text = raw.decode("ascii")
    except UnicodeDecodeError as exc:
        raise ArgumentError(
            f"path {os.fspath(path)!r} must be an ASCII MovingAI .map file; byte {exc.start} is "
            f"{raw[exc.start:exc.start + 1]!r}"
        ) from None
    return _parse_movingai(text, os.fspath(path))


def _parse_movingai(text: str, source: str) -> NDArray[np.uint8]:
    lines = text.splitlines()
    where = f"path {source!r}"
    header: dict[str, str] = {}
    for number, line in enumerate(lines, start=1):
        stripped = line.strip()
        if stripped == "map":
            body_start = number  # index of the first map row in ``lines``
            break
        match = _HEADER_LINE.match(stripped)
        if match is None or match.group(1) in header:
            raise ArgumentError(
                f"{where}: bad MovingAI header at line {number}; expected the lines "
                "'type octile', 'height <H>', 'width <W>' (once each), then 'map'"
            )
        header[match.group(1)] = match.group(2)
    else:
        raise ArgumentError(f"{where}: bad MovingAI header: no 'map' line before the end of the file")
    missing = [key for key in ("type", "height", "width") if key not in header]
    if missing:
        raise ArgumentError(f"{where}: bad MovingAI header: missing {', '.join(missing)} before 'map'")
    if header["type"] != "octile":
        raise ArgumentError(f"{where}: bad MovingAI header: type must be 'octile', got {header['type']!r}")
    size = {}
    for key in ("height", "width"):
        value = header[key]
        if not value.isdigit() or int(value) < 1:
            raise ArgumentError(f"{where}: bad MovingAI header: {key} must be an integer >= 1, got {value!r}")
        size[key] = int(value)
    height, width = size["height"], size["width"]
    validation.cell_budget(f"{where} (map)", height, width)

    rows = lines[body_start:]
    while rows and not rows[-1].strip():  # trailing blank lines are harmless
        rows.pop()
    if len(rows) != height:
        raise ArgumentError(f"{where}: the header says height {height} but the map has {len(rows)} rows")
    for i, row in enumerate(rows):
        if len(row) != width:
            raise ArgumentError(
                f"{where}: map row {i} has {len(row)} characters, expected width {width}"
            )
    chars = np.frombuffer("".join(rows).encode("ascii"), dtype=np.uint8).reshape(height, width)
    lookup = np.full(256, 255, dtype=np.uint8)
    for char, code in MOVINGAI_CELLS.items():
        lookup[ord(char)] = code
    codes = lookup[chars]
    bad = np.argwhere(codes == 255)
    if bad.size:
        i, j = (int(v) for v in bad[0])
        raise ArgumentError(
            f"{where}: unknown character {chr(chars[i, j])!r} at map row {i}, column {j}; "
            f"valid: {''.join(MOVINGAI_CELLS)!r} (free: '.GS', blocked: '@OTW')"
        )
    return codes
