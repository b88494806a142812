"""Results computed from an OCC shape, kept while the cache holds the shape (meshes, volumes, areas).

A tooling build asks for the same facts of the same solid many times: the finished tablet is
meshed for every Boolean's manifold3d check, for the overlap check, for the gap check and for its
STL; its volume is integrated before and after every Boolean.  :class:`ShapeCache` keeps one
result per (shape, key): shapes are matched by ``IsEqual`` (same topology, location and
orientation), the newest ``size`` entries are kept, and each entry holds a reference to its shape
so that its topology cannot be freed and its address reused while the entry exists.  A cached
result is the same object as the first one, so results are returned read-only (numpy arrays are
frozen by :func:`frozen`).
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Any, Callable

import numpy as np

from tabletcad.cad.content import ContentMemo

__all__ = ["ShapeCache", "frozen"]


class ShapeCache:
    """The ``size`` most recently used results ``compute()`` of ``(shape, key)``.

    ``faces`` > 0: :attr:`faces` is a second cache of that size for results per face (the faces a
    build's solids share: a punch tip's face is the tablet's), and :attr:`content` one for results by
    shape content (:func:`~tabletcad.cad.content.content_key`: a face of a build made again), both
    cleared with this one."""

    def __init__(self, size: int = 48, faces: int = 0) -> None:
        self.size = int(size)
        self._entries: OrderedDict = OrderedDict()
        self.hits = 0
        self.misses = 0
        self.faces: ShapeCache | None = ShapeCache(faces) if faces > 0 else None
        self.content: ContentMemo | None = ContentMemo(faces) if faces > 0 else None

    def get(self, shape, key: Any, compute: Callable[[], Any]) -> Any:
        slot = (hash(shape), key)
        for i, (s, value) in enumerate(self._entries.get(slot, ())):
            if s.IsEqual(shape):
                self._entries.move_to_end(slot)
                self.hits += 1
                return value
        value = compute()
        self.misses += 1
        self._entries.setdefault(slot, []).append((shape, value))
        self._entries.move_to_end(slot)
        while len(self._entries) > self.size:
            self._entries.popitem(last=False)
        return value

    def clear(self) -> None:
        self._entries.clear()
        if self.faces is not None:
            self.faces.clear()
        if self.content is not None:
            self.content.clear()


def frozen(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """The arrays made read-only (a cached result must not be changed by one of its users)."""
    for a in arrays:
        a.setflags(write=False)
    return arrays
