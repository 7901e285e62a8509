"""A planner's tangent edges per ``(node, side)``, filled lazily from a disk cache's arrays.

The searches read a node's edges as Python lists (``(departures, targets, target sides,
arrivals, lengths)``, sorted by departure), where a numpy scalar would cost ten times more.
A floor loaded from the disk cache (:mod:`pointnav_core.geodesic.cache`) holds every edge as
flat arrays; turning all of them into lists at once took 2.3 s on a 1000 x 1000 map of
69,277 nodes, while a first path reads a few thousand nodes' edges. :class:`EdgeStore`
turns one ``(node, side)`` into lists the first time it is read, and everything that walks
the whole store (``keys``, ``values``, ``items``, iteration, ``len``) fills it first.
"""

from __future__ import annotations

from collections.abc import ItemsView, Iterator, KeysView, ValuesView
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["EdgeStore"]

Key = tuple[int, int]
Lists = tuple[list[float], list[int], list[int], list[float], list[float]]
_COLUMNS = ("dep", "to", "to_side", "arr", "length")


class EdgeStore(dict):  # type: ignore[type-arg]
    """``dict`` of ``(node, side) -> edge lists``, with the entries of :meth:`attach`'s
    arrays added on first read."""

    def __init__(self) -> None:
        super().__init__()
        self._flat: dict[str, NDArray[Any]] | None = None
        self._lo = np.zeros(0, dtype=np.int64)
        self._hi = np.zeros(0, dtype=np.int64)
        self._waiting = 0  # stored keys not read yet

    @classmethod
    def of(cls, entries: dict[Key, Lists]) -> EdgeStore:
        """A store holding ``entries`` (lists already made)."""
        store = cls()
        dict.update(store, entries)
        return store

    def __reduce__(self) -> tuple[Any, ...]:
        # Every entry as lists, without the arrays they came from.
        return (EdgeStore.of, (dict(self.items()),))

    def attach(self, stored: dict[str, NDArray[Any]]) -> None:
        """Hold the flat arrays of ``cache.edge_arrays`` (``node``, ``side``, ``count`` and
        the columns); their keys read as present from now on."""
        ends = np.cumsum(stored["count"])
        slot = 2 * stored["node"].astype(np.int64) + (stored["side"] < 0)
        size = int(slot.max()) + 1 if len(slot) else 0
        self._lo = np.full(size, -1, dtype=np.int64)
        self._hi = np.zeros(size, dtype=np.int64)
        self._lo[slot] = ends - stored["count"]
        self._hi[slot] = ends
        self._flat = {k: stored[k] for k in _COLUMNS}
        self._waiting = len(slot)

    def _slot(self, key: Key) -> int:
        """Where ``key``'s stored edges are indexed, or -1 where none wait."""
        if self._waiting == 0:
            return -1
        k = 2 * int(key[0]) + (key[1] < 0)
        return k if 0 <= k < len(self._lo) and self._lo[k] >= 0 else -1

    def _fill(self, key: Key) -> Lists | None:
        k = self._slot(key)
        if k < 0 or dict.__contains__(self, key):
            return None
        i, j = int(self._lo[k]), int(self._hi[k])
        value = tuple(self._flat[c][i:j].tolist() for c in _COLUMNS)  # type: ignore[index]
        dict.__setitem__(self, key, value)
        self._lo[k] = -1
        self._waiting -= 1
        return value  # type: ignore[return-value]

    def fill_all(self) -> None:
        """Turn every stored entry not read yet into lists."""
        if self._waiting:
            nodes, = np.nonzero(self._lo >= 0)
            for k in nodes.tolist():
                self._fill((k // 2, 1 if k % 2 == 0 else -1))

    def n_edges(self) -> int:
        """How many edges the store holds, read or not."""
        waiting = int((self._hi - self._lo)[self._lo >= 0].sum()) if self._waiting else 0
        return sum(len(v[0]) for v in dict.values(self)) + waiting

    def get(self, key: Key, default: Any = None) -> Any:
        value = dict.get(self, key)
        if value is None:
            value = self._fill(key)
        return default if value is None else value

    def __getitem__(self, key: Key) -> Lists:
        value = self.get(key)
        if value is None:
            raise KeyError(key)
        return value  # type: ignore[no-any-return]

    def __contains__(self, key: object) -> bool:
        return dict.__contains__(self, key) or (isinstance(key, tuple) and self._slot(key) >= 0)  # type: ignore[arg-type]

    def __iter__(self) -> Iterator[Key]:
        self.fill_all()
        return dict.__iter__(self)

    def __len__(self) -> int:
        return dict.__len__(self) + self._waiting

    def keys(self) -> KeysView[Key]:  # type: ignore[override]
        self.fill_all()
        return dict.keys(self)

    def values(self) -> ValuesView[Lists]:  # type: ignore[override]
        self.fill_all()
        return dict.values(self)

    def items(self) -> ItemsView[Key, Lists]:  # type: ignore[override]
        self.fill_all()
        return dict.items(self)

    def __eq__(self, other: object) -> bool:
        self.fill_all()
        if isinstance(other, EdgeStore):
            other.fill_all()
        return dict.__eq__(self, other)

    __hash__ = None  # type: ignore[assignment]

    def setdefault(self, key: Key, default: Any = None) -> Any:
        value = self.get(key)
        if value is None:
            dict.__setitem__(self, key, default)
            return default
        return value
