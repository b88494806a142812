"""Python's cyclic garbage collector during a command line build: fewer full collections.

A full (oldest-generation) collection walks every object the process holds.  A tooling build imports
OCC, SciPy, trimesh and matplotlib (some 285,000 objects by its end), and the collector's default
thresholds ran four full collections during those imports in ``tabletcad build
samples/tooling/concave_round_bisect.toml``: 0.24-0.26 s of CPU that freed 20 objects.  The young
generations are collected as before (cyclic garbage of the build itself is freed as it was); only
the full collections become :data:`FULL_FACTOR` times rarer, and the thresholds are restored after.
The build's results do not depend on when garbage is freed.
"""

from __future__ import annotations

import contextlib
import gc
from collections.abc import Iterator

__all__ = ["FULL_FACTOR", "fewer_full_collections"]

#: how many times rarer full collections are within :func:`fewer_full_collections` (the third
#: threshold, the young collections between two full ones, multiplied by it: 10 -> 100 by default)
FULL_FACTOR = 10


@contextlib.contextmanager
def fewer_full_collections(factor: int = FULL_FACTOR) -> Iterator[tuple[int, ...]]:
    """Within the block, full collections ``factor`` times rarer; the thresholds restored after.

    Parameters
    ----------
    factor : int
        What the collector's third threshold is multiplied by (>= 1).

    Yields
    ------
    tuple of int
        The thresholds in force within the block (``gc.get_threshold()``).
    """
    if int(factor) < 1:
        raise ValueError(f"factor = {factor!r} must be >= 1")
    old = gc.get_threshold()
    gc.set_threshold(old[0], old[1], old[2] * int(factor))
    try:
        yield gc.get_threshold()
    finally:
        gc.set_threshold(*old)
