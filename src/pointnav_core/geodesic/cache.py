"""The geometry cache on disk: a floor's tangent graph, built once and reloaded by every process.

Habitat keeps a scene's navmesh in a file; this keeps what a floor's :class:`Planner
<pointnav_core.geodesic.Planner>` builds that does not depend on a goal (its nodes' sight
bounds and every tangent edge), so that eval workers, pool workers, SB3 subprocesses and Ray
workers share one build.

- **Where.** ``$POINTNAV_CACHE_DIR`` if set (empty, ``0`` or ``off``: no cache), else the
  platform's cache folder: ``$XDG_CACHE_HOME/pointnav-core`` (default ``~/.cache``) on
  Linux, ``~/Library/Caches/pointnav-core`` on macOS, ``%LOCALAPPDATA%\\pointnav-core\\Cache``
  on Windows.
- **Key.** A SHA-256 of the blocked cells, the resolution, the origin, the outside rule, the
  polygons (WKB), the robot radius, the library version and this file format: a changed map,
  radius or version misses.
- **Never trusted blindly.** A file is read without pickle, must carry its own key and the
  floor's node count; an unreadable, truncated or foreign file warns and is rebuilt.
- **Atomic.** A file is written under a unique temporary name in the same folder, then
  renamed over the entry: readers see a whole file or none, and two processes building the
  same entry leave one valid file.
- Builds faster than :data:`MIN_SECONDS` are not written: reading them back would not pay.
"""

from __future__ import annotations

import hashlib
import os
import sys
import tempfile
import warnings
import zipfile
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.errors import ArgumentError

if TYPE_CHECKING:
    from pointnav_core.floor.collision import FloorCollision

__all__ = ["ENV_VAR", "MIN_SECONDS", "cache_dir", "edge_arrays", "floor_key", "load", "save"]

ENV_VAR = "POINTNAV_CACHE_DIR"
#: Builds (s) shorter than this are not written to the cache.
MIN_SECONDS = 0.5
#: Bumped whenever what is stored, or how it is computed, changes.
FORMAT = 3


def cache_dir() -> Path | None:
    """The cache folder, or None when the cache is off (``POINTNAV_CACHE_DIR`` empty, 0 or off)."""
    value = os.environ.get(ENV_VAR)
    if value is not None:
        return None if value.strip().lower() in ("", "0", "off", "none") else Path(value)
    if sys.platform == "win32":
        return Path(os.environ.get("LOCALAPPDATA", Path.home() / "AppData" / "Local")) / "pointnav-core" / "Cache"
    if sys.platform == "darwin":
        return Path.home() / "Library" / "Caches" / "pointnav-core"
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "pointnav-core"


def floor_key(geo: FloorCollision, radius: float) -> str:
    """The cache key of a floor's blocked set for a robot ``radius`` (m): 64 hex digits."""
    import shapely

    from pointnav_core import __version__

    h = hashlib.sha256()
    h.update(f"pointnav-core geodesic {FORMAT} {__version__}\n".encode())
    h.update(f"{geo.shape} {geo.resolution!r} {geo.origin!r} {geo.outside_blocked} {float(radius)!r}\n".encode())
    h.update(np.packbits(np.asarray(geo.blocked, dtype=bool)).tobytes())
    for poly in geo.polygons:
        h.update(shapely.to_wkb(poly))
    return h.hexdigest()


def load(key: str, n_nodes: int) -> dict[str, NDArray] | None:
    """The arrays stored under ``key`` for a floor of ``n_nodes`` nodes, or None (a miss).

    A file that cannot be read whole, or whose key or node count differ, warns
    (``RuntimeWarning``) and counts as a miss; it is removed so that the rebuild replaces it.
    """
    folder = cache_dir()
    if folder is None:
        return None
    path = folder / f"{key}.npz"
    if not path.is_file():
        return None
    try:
        with open(path, "rb") as f, np.load(f, allow_pickle=False) as z:  # our handle: closed on any error
            data = {name: z[name] for name in z.files}
        if str(data["key"]) != key or len(data["sights"]) != n_nodes:
            raise ArgumentError("it belongs to another floor")
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as err:
        warnings.warn(f"geometry cache file {path} is unreadable ({err}); rebuilding it", RuntimeWarning, stacklevel=3)
        try:
            path.unlink()
        except OSError:
            pass
        return None
    return data


def save(key: str, arrays: dict[str, NDArray]) -> Path | None:
    """Write ``arrays`` under ``key`` atomically; the file, or None (cache off or not writable)."""
    folder = cache_dir()
    if folder is None:
        return None
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{key[:16]}-", suffix=".tmp")
    except OSError:
        return None  # a read-only or missing home: the build simply is not kept
    path = folder / f"{key}.npz"
    try:
        with os.fdopen(fd, "wb") as f:
            np.savez(f, key=np.array(key), **arrays)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except OSError:
        Path(tmp).unlink(missing_ok=True)
        return None
    return path


def edge_arrays(store: dict[tuple[int, int], tuple[list[Any], ...]]) -> dict[str, NDArray[Any]]:
    """A planner's edges, ``(node, side) -> (departures, targets, target sides, arrivals,
    lengths)``, as the flat arrays an entry keeps."""
    keys = sorted(store)
    lists = [store[k] for k in keys]
    return {
        "node": np.array([k[0] for k in keys], dtype=np.int64),
        "side": np.array([k[1] for k in keys], dtype=np.int8),
        "count": np.array([len(v[0]) for v in lists], dtype=np.int64),
        "dep": np.array([x for v in lists for x in v[0]], dtype=np.float64),
        "to": np.array([x for v in lists for x in v[1]], dtype=np.int64),
        "to_side": np.array([x for v in lists for x in v[2]], dtype=np.int8),
        "arr": np.array([x for v in lists for x in v[3]], dtype=np.float64),
        "length": np.array([x for v in lists for x in v[4]], dtype=np.float64),
    }
