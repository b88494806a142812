"""Results of OCC computations keyed by what a shape *is*, not by which object holds it.

Two builds of the same tablet make new shapes (new ``TShape`` objects) with the same geometry to the
last bit; OCC's adaptive integrals of them are then the same to the last bit too (they read nothing
else).  :func:`content_key` names a shape by its exact content: its binary BRep (``BinTools``, doubles
as stored, and the shapes' status flags), hashed.  :class:`ContentMemo` keeps the newest results by such
keys.  The flags make a shape meshed or checked since it was last keyed a new key: a miss, never a
wrong hit.

Only results computed from the exact geometry are keyed so: an integral over a face without a surface
(a mesh-only face) reads its triangulation instead, and shapes with such a face are not memoised
(:func:`has_all_surfaces`).
"""

from __future__ import annotations

import hashlib
import io
from collections import OrderedDict
from typing import Any, Callable, Hashable

from OCP.BinTools import BinTools, BinTools_FormatVersion
from OCP.BRep import BRep_Tool
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS_Shape

from tabletcad.cad._occ import cast

__all__ = ["content_key", "has_all_surfaces", "ContentMemo"]


def content_key(shape: TopoDS_Shape) -> bytes:
    """A 20-byte digest of ``shape``'s binary BRep: its topology, orientations, locations, tolerances and
    geometry (curves, p-curves, surfaces, parameter ranges) as exact doubles, and the status flags of its
    shapes (meshing a face clears its "checked" flag: a new key); triangulations only of faces without a
    surface.  Equal keys: the same shape content (BLAKE2b, a collision is not a practical concern)."""
    buf = io.BytesIO()
    BinTools.Write_s(shape, buf, False, False, BinTools_FormatVersion.BinTools_FormatVersion_CURRENT)
    return hashlib.blake2b(buf.getvalue(), digest_size=20).digest()


def has_all_surfaces(shape: TopoDS_Shape) -> bool:
    """Whether every face of ``shape`` has a surface (OCC integrates a face without one on its
    triangulation: such shapes are not memoised)."""
    exp = TopExp_Explorer(shape, TopAbs_FACE)
    while exp.More():
        if BRep_Tool.Surface_s(cast(exp.Current(), "Face")) is None:
            return False
        exp.Next()
    return True


class ContentMemo:
    """The ``size`` most recently used results ``compute()`` by hashable key (e.g. a
    :func:`content_key` and the integration's parameters); ``hits`` and ``misses`` counted."""

    def __init__(self, size: int) -> None:
        self.size = int(size)
        self._entries: OrderedDict = OrderedDict()
        self.hits = 0
        self.misses = 0

    def get(self, key: Hashable, compute: Callable[[], Any]) -> Any:
        """The result for ``key``: the kept one, else ``compute()`` (kept, the oldest dropped past ``size``)."""
        if key in self._entries:
            self._entries.move_to_end(key)
            self.hits += 1
            return self._entries[key]
        value = compute()
        self.misses += 1
        self._entries[key] = value
        while len(self._entries) > self.size:
            self._entries.popitem(last=False)
        return value

    def clear(self) -> None:
        self._entries.clear()
