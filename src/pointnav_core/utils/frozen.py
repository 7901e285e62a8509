"""Read-only containers that survive ``pickle``, ``copy.deepcopy`` and ``cloudpickle``.

``types.MappingProxyType`` is the usual read-only view of a dict, but it cannot be
pickled, so an env holding one cannot be sent to a worker process (SuperSuit's vector envs
and Ray copy envs that way). :class:`FrozenMapping` is the picklable equivalent;
:func:`thaw` is the other half of the same concern: arrays that come back read-only from
another process (pickle protocol 5 buffers, Ray's object store) are copied before an
object edits them in place.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any, TypeVar

import numpy as np

__all__ = ["FrozenMapping", "ThawOnUnpickle", "thaw"]

K = TypeVar("K")
V = TypeVar("V")


class FrozenMapping(Mapping[K, V]):
    """A read-only mapping (a copy of ``data``) that pickles and deep-copies.

    >>> import pickle
    >>> m = FrozenMapping({"a": 1})
    >>> pickle.loads(pickle.dumps(m)) == {"a": 1}, m["a"]
    (True, 1)
    """

    __slots__ = ("_data",)

    def __init__(self, data: Mapping[K, V] | None = None) -> None:
        self._data: dict[K, V] = dict(data or {})

    def __getitem__(self, key: K) -> V:
        return self._data[key]

    def __iter__(self) -> Iterator[K]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __repr__(self) -> str:
        return f"FrozenMapping({self._data!r})"

    def __reduce__(self) -> tuple[Any, ...]:
        return (FrozenMapping, (self._data,))


def thaw(value: Any) -> Any:
    """``value`` with every read-only numpy array in it (through dicts, lists and tuples)
    replaced by a writable copy; anything else is returned as it is."""
    if isinstance(value, np.ndarray):
        return value if value.flags.writeable else value.copy()
    if isinstance(value, dict):
        return {k: thaw(v) for k, v in value.items()}
    if isinstance(value, list):
        return [thaw(v) for v in value]
    if isinstance(value, tuple) and type(value) is tuple:
        return tuple(thaw(v) for v in value)
    return value


class ThawOnUnpickle:
    """Mixin for objects that fill numpy arrays in place as queries arrive (the planner's
    sight bounds, a goal field's root table): unpickled from read-only buffers, they get
    writable copies (:func:`thaw`)."""

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(thaw(state))
