"""Small vector helpers of the numerical core."""

from __future__ import annotations

import numpy as np

__all__ = ["clip", "cross", "cross_first", "einsum", "linspace", "norm3", "points_last"]


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of 3-vectors along the last axis, broadcast over the others.

    The same values as :func:`numpy.cross` (the same products and differences, in the
    same order), written as three component expressions: ``numpy.cross`` moves axes and
    makes temporaries, which costs about six times as much on a surface grid.
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    np.multiply(a1, b2, out=out[..., 0])
    out[..., 0] -= a2 * b1
    np.multiply(a2, b0, out=out[..., 1])
    out[..., 1] -= a0 * b2
    np.multiply(a0, b1, out=out[..., 2])
    out[..., 2] -= a1 * b0
    return out


def cross_first(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of vector fields stored coordinates first, ``(3, ...)``: each coordinate one
    contiguous block (the layout :meth:`~tabletcad.geometry.patch.PDEPatch.evaluate_grid` gives with
    ``components``), so every product runs over whole blocks."""
    return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def norm3(a: np.ndarray) -> np.ndarray:
    """Euclidean length of 3-vectors along the last axis: ``sqrt((x² + y²) + z²)``.

    The value :func:`numpy.linalg.norm` gives with ``axis=-1`` (the same squares, summed in the
    same order), at a fifth of its cost on a surface grid (its reduction over an axis of three
    is numpy's general one).
    """
    a = np.asarray(a, dtype=float)
    x, y, z = a[..., 0], a[..., 1], a[..., 2]
    return np.sqrt(x * x + y * y + z * z)


def length2(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``sqrt(x² + y²)`` elementwise (mm): ``np.hypot`` without its care for over- and underflow (a tablet's
    lengths in mm are far from both), several times cheaper, within two ulp of it (tested)."""
    return np.sqrt(x * x + y * y)


def points_last(a: np.ndarray) -> np.ndarray:
    """``a`` of shape ``(k, ...)`` (coordinates first, such as
    :meth:`~tabletcad.geometry.patch.PDEPatch.evaluate_grid`'s ``components`` layout) as a C-contiguous
    ``(..., k)`` array of points: ``np.ascontiguousarray(np.moveaxis(a, 0, -1))`` (a copy from 64 points on).

    Copied one coordinate at a time over whole blocks: numpy's copy of the transposed view runs one
    inner loop of ``k`` elements per point (3x slower on a 97 x 256 grid); below 64 points that copy,
    with less set-up, is kept.
    """
    a = np.asarray(a)
    if a.ndim < 2 or a[0].size < 64:
        return np.ascontiguousarray(np.moveaxis(a, 0, -1))
    out = np.empty(a.shape[1:] + a.shape[:1], dtype=a.dtype)
    for c in range(a.shape[0]):
        out[..., c] = a[c]
    return out


#: :func:`numpy.clip`'s ufunc itself (the same values): ``numpy.clip`` reaches it through a Python wrapper
#: that costs several times the ufunc on the short arrays of the polishes (numpy >= 2: ``numpy._core``).
#: A private name: a numpy without it gets ``numpy.clip`` itself.
clip = getattr(getattr(getattr(np, "_core", None) or getattr(np, "core", None), "umath", None), "clip", None) or np.clip

#: :func:`numpy.einsum` without its Python wrapper: with ``optimize`` False (its default) the wrapper only
#: passes the operands on to this C function, so the values are the same; the wrapper and its dispatcher
#: cost more than the sum itself on a patch's small residual combinations (numpy >= 2: ``numpy._core``).
#: A private name: a numpy without it gets ``numpy.einsum`` itself.
einsum = getattr(getattr(getattr(np, "_core", None) or getattr(np, "core", None), "multiarray", None),
                 "c_einsum", None) or np.einsum


def linspace(start: float, stop: float, num: int, endpoint: bool = True) -> np.ndarray:
    """``numpy.linspace(start, stop, num, endpoint=endpoint)`` of two scalars, by its own arithmetic
    (``arange(num) * step + start``, ``step = (stop - start) / div``, the last value ``stop`` with the
    end point; with a step that underflows to 0, ``arange(num) / div * (stop - start) + start``): the same
    values, without the general function's cost per call (some 8x on the polishes' 33 samples)."""
    div = num - 1 if endpoint else num
    if div <= 0:
        return np.linspace(start, stop, num, endpoint=endpoint)
    start, stop = float(start), float(stop)
    delta = stop - start
    step = delta / div
    y = np.arange(num, dtype=float)
    if step == 0:
        y /= div
        y *= delta
    else:
        y *= step
    y += start
    if endpoint:
        y[-1] = stop
    return y
