"""A small least-recently-used store of read-only arrays shared by every patch.

The patches of one tablet (and of consecutive builds in one process: an
optimisation, a sweep, a workbench recompute) are evaluated on the same sample
arrays: the checks' ``u`` lines, the quadrature nodes, the ``v`` grids.  The
tables those samples need — trigonometric rows in ``v``, cardinal functions in
``u`` — depend only on the samples and on a few numbers (modes, ``λ``, nodes),
not on the patch, so one table can serve them all.  Keys hold the samples'
bytes: equal samples hit, nothing is ever shared between different ones.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from typing import Callable, Hashable

import numpy as np

__all__ = ["SharedTables", "TRIG", "CARDINAL", "COLLOCATION"]


class SharedTables:
    """Least-recently-used cache of read-only arrays (or tuples of arrays).

    Parameters
    ----------
    entries : int
        How many results are kept.
    max_bytes : int
        Results larger than this (summed over a tuple) are computed but not kept.
    total_bytes : int, optional
        The most all kept results may hold together (default ``entries × max_bytes``);
        the least recently used go first.
    """

    def __init__(self, entries: int, max_bytes: int, total_bytes: int | None = None) -> None:
        self.entries = int(entries)
        self.max_bytes = int(max_bytes)
        self.total_bytes = int(total_bytes if total_bytes is not None else entries * max_bytes)
        self._store: OrderedDict = OrderedDict()
        self._bytes = 0
        self._lock = threading.Lock()

    def get(self, key: Hashable, make: Callable[[], object]):
        """The result stored under ``key``, made by ``make()`` (and marked read-only) on a miss."""
        with self._lock:
            hit = self._store.get(key)
            if hit is not None:
                self._store.move_to_end(key)
                return hit
        hit = make()
        size = _nbytes(hit)
        if size > self.max_bytes:
            return hit
        for a in (hit,) if isinstance(hit, np.ndarray) else hit:
            a.setflags(write=False)
        with self._lock:
            if key not in self._store:
                self._store[key] = hit
                self._bytes += size
            while len(self._store) > self.entries or self._bytes > self.total_bytes:
                self._bytes -= _nbytes(self._store.popitem(last=False)[1])
        return hit

    def clear(self) -> None:
        with self._lock:
            self._store.clear()
            self._bytes = 0

    def __len__(self) -> int:
        return len(self._store)


def _nbytes(result) -> int:
    return result.nbytes if isinstance(result, np.ndarray) else sum(a.nbytes for a in result)


#: Trigonometric rows in ``v`` (:func:`tabletcad.geometry.patch._trig_shared`): none above 8 MB (8192
#: samples of 48 modes are 6.3 MB; 512 modes on 2048 samples, 16.8 MB, are not kept), 64 MB in all, and
#: up to 1024 tables, so that the bytes bound them: one shaped family tablet's load and report reads
#: about a hundred (the rounded triangle 115, 11.8 MB; the capsule 98, 10.0 MB), each design of a family
#: the same ones.  With 32 kept the least recently used went before its next read and ~150 were made
#: again on every build; with 256, when four families are built in turn (a sweep or a workbench document
#: of several), 363 a round (``tests/test_core_tables.py``).
TRIG = SharedTables(1024, 8_000_000, 64_000_000)
#: Cardinal functions in ``u`` (:meth:`tabletcad.geometry.patch.PDEPatch._u_tables`, the profiles of
#: :mod:`tabletcad.geometry.revolution`): the patches of a family share ``a`` and the nodes, so the
#: checks' and quadratures' ``u`` lines serve them all.  None above 4 MB, 48 MB in all, up to 512 tables:
#: a shaped tablet reads 50-80 (the rounded triangle 71, 4.2 MB); 96 kept had held one family's, and four
#: families built in turn made 163 again a round.
CARDINAL = SharedTables(512, 4_000_000, 48_000_000)
#: B-spline collocation matrices (:meth:`tabletcad.brep.surface.BSplineSurfaceData.collocation`):
#: the faces of a chain share their knots, and the fit, its check, the volume and area and the mesh
#: evaluate them on the same samples; and the chain's periodic knots (:func:`tabletcad.brep.knots.periodic_knots`).
#: 64 tables, none above 2 MB, 32 MB in all.
COLLOCATION = SharedTables(64, 2_000_000, 32_000_000)
