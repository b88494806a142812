"""Gauss-Legendre rules, computed once per order.

numpy's ``leggauss`` solves an eigenproblem on every call (0.5 ms for 24 points); every
quadrature of the core (areas, volumes, the swept tablets' properties, the B-spline checks)
asks for the same few orders again and again.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

__all__ = ["gauss_legendre"]


@lru_cache(maxsize=64)
def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of the ``n``-point Gauss-Legendre rule on [-1, 1] (read-only arrays)."""
    x, w = np.polynomial.legendre.leggauss(int(n))
    x.setflags(write=False)
    w.setflags(write=False)
    return x, w
