"""Kernel-neutral tensor-product B-spline surfaces and their interpolation fit.

This module uses numpy only (scipy is optional and not needed) and never imports
a CAD kernel: FreeCAD's own Python and the OCP layer in :mod:`tabletcad.cad`
both build their surfaces from the same :class:`BSplineSurfaceData`.

Conventions (identical to OCCT's ``Geom_BSplineSurface`` and FreeCAD's
``Part.BSplineSurface.buildFromPolesMultsKnots``):

* ``poles`` has shape ``(nu, nv, 3)``; knots are the *distinct* knot values,
  ``*_mults`` their multiplicities.
* Non-periodic direction: ``sum(mults) == n_poles + degree + 1`` (clamped ends
  have multiplicity ``degree + 1``).
* Periodic direction: the first and last knot bound one period and carry the
  same multiplicity; ``sum(mults) - mults[-1] == n_poles``.  Pole 0 is the
  first B-spline of the flat knot sequence extended by ``degree`` knots on each
  side (measured against OCCT 7.8/8.0: a uniform periodic cubic with all
  multiplicities 1 has ``C(k0) = (P0 + 4 P1 + P2) / 6``).  When the first knot
  has multiplicity ``m > 1`` OCCT starts the period at its *last* copy: the
  flat period is ``k0, k1 x m1, ..., k_{n-1} x m_{n-1}, k_n x (m - 1)``
  (checked by random-pole evaluation against ``Geom_BSplineSurface``).

:func:`fit_surface` interpolates a parametric surface ``f(u, v) -> (..., 3)``
(``u`` in [0, 1] clamped, ``v`` periodic with period ``2 pi``) at the
surface's own parameter values, so the B-spline parametrisation matches the
patch's, and refines the grid until the deviation measured on a much denser
grid is within tolerance.  :func:`fit_patches` fits a chain of patches with a
common ``v`` grid so that neighbouring patches get bit-identical boundary rows.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from tabletcad.errors import GeometryError

__all__ = [
    "PatchFunction",
    "chain_breakpoints",
    "BSplineSurfaceData",
    "SurfaceFit",
    "fit_surface",
    "fit_patches",
    "basis_functions",
    "flat_knots",
    "segment_v",
    "periodic_knots",
    "normalise_breaks",
    "enclosed_volume",
]

SurfaceFunction = Callable[[np.ndarray, np.ndarray], np.ndarray]


# --------------------------------------------------------------------------- knots


def flat_knots(knots: np.ndarray, mults: np.ndarray, degree: int, periodic: bool) -> np.ndarray:
    """Full (flat) knot vector; a periodic one is extended by ``degree`` knots on each side.

    For a periodic direction the number of B-splines of the returned vector is
    ``n_poles + degree``; B-spline ``i`` uses pole ``i mod n_poles``.
    """
    knots = np.asarray(knots, dtype=float)
    mults = np.asarray(mults, dtype=int)
    if not periodic:
        return np.repeat(knots, mults)
    period = knots[-1] - knots[0]
    # one period, length n_poles.  OCCT's pole 1 is the B-spline that starts at the *last*
    # copy of the first knot (measured with OCCT 7.9/8.0): a first knot of multiplicity m
    # contributes one copy here and the period's end knot the other m - 1.
    m0 = int(mults[0])
    one = np.concatenate([knots[:1], np.repeat(knots[1:-1], mults[1:-1]), np.repeat(knots[-1:], m0 - 1)])
    n = one.size
    if n < degree + 1:
        raise GeometryError(f"periodic B-spline needs at least degree+1 = {degree + 1} poles, got {n}")
    head = one[n - degree:] - period
    tail = np.concatenate([one[: degree + 1] + period])
    return np.concatenate([head, one, tail])


def segment_v(data: BSplineSurfaceData, a: float, b: float) -> BSplineSurfaceData:
    """The part ``a <= v <= b`` of ``data`` as a surface clamped in ``v``, exactly.

    ``a`` and ``b`` must be knots of multiplicity >= ``v_degree`` (C0 knots; a
    periodic surface's first knot counts with its multiplicity) - there the
    curve already splits into independent pieces, so the piece keeps the
    poles of the B-splines active on ``(a, b)`` and the knots in between, with
    ``a`` and ``b`` clamped (multiplicity ``degree + 1``).  On a periodic
    surface the piece may run across the period's end (``b`` up to ``a +``
    one period).
    """
    p = int(data.v_degree)
    knots = np.asarray(data.v_knots, dtype=float)
    mults = np.asarray(data.v_mults, dtype=int)
    n = data.shape[1]
    if data.v_periodic:
        period = float(knots[-1] - knots[0])
        m0 = int(mults[0])
        one = np.concatenate([knots[:1], np.repeat(knots[1:-1], mults[1:-1]), np.repeat(knots[-1:], m0 - 1)])
        # B-spline k of t uses pole (k - n + p) mod n (flat_knots starts p knots before the period)
        t = np.concatenate([one - period, one, one + period, one[: p + 1] + 2.0 * period])
        shift = p - n
        if not (knots[0] <= a < knots[-1] and a < b <= a + period + 1e-12):
            raise GeometryError(f"segment_v: [{a}, {b}] is not within one period from [{knots[0]}, {knots[-1]})", data)
    else:
        t = np.repeat(knots, mults)
        shift = 0
        if not (knots[0] <= a < b <= knots[-1]):
            raise GeometryError(f"segment_v: [{a}, {b}] is not within [{knots[0]}, {knots[-1]}]", data)
    scale = max(1.0, float(np.max(np.abs(t))))
    for x in (a, b):
        if int(np.sum(np.abs(t - x) <= 1e-12 * scale)) < p and not (not data.v_periodic and x in (knots[0], knots[-1])):
            raise GeometryError(f"segment_v: v = {x} is not a knot of multiplicity >= {p}", data)
    n_basis = t.size - p - 1
    active = [k for k in range(n_basis) if t[k] < b - 1e-12 * scale and t[k + p + 1] > a + 1e-12 * scale]
    inner = t[(t > a + 1e-12 * scale) & (t < b - 1e-12 * scale)]
    vals, counts = np.unique(inner, return_counts=True)
    new_knots = np.concatenate([[a], vals, [b]])
    new_mults = np.concatenate([[p + 1], counts, [p + 1]]).astype(int)
    poles = np.asarray(data.poles)[:, [(k + shift) % n for k in active], :]
    return replace(data, poles=poles, v_knots=new_knots, v_mults=new_mults, v_periodic=False)


def _find_span(t: np.ndarray, degree: int, n_basis: int, x: np.ndarray) -> np.ndarray:
    """Index ``i`` with ``t[i] <= x < t[i+1]``, clipped to the valid spans ``[degree, n_basis-1]``."""
    span = np.searchsorted(t, x, side="right") - 1
    return np.clip(span, degree, n_basis - 1)


def _basis_on_span(t: np.ndarray, degree: int, x: np.ndarray, span: np.ndarray) -> np.ndarray:
    """Cox-de Boor: values of B-splines ``span-degree ... span`` at ``x`` (vectorised)."""
    N = np.zeros(x.shape + (degree + 1,))
    N[..., 0] = 1.0
    left = np.zeros(x.shape + (degree + 1,))
    right = np.zeros(x.shape + (degree + 1,))
    for j in range(1, degree + 1):
        left[..., j] = x - t[span + 1 - j]
        right[..., j] = t[span + j] - x
        saved = np.zeros(x.shape)
        for r in range(j):
            denom = right[..., r + 1] + left[..., j - r]
            safe = np.where(denom != 0.0, denom, 1.0)
            temp = np.where(denom != 0.0, N[..., r] / safe, 0.0)
            N[..., r] = saved + right[..., r + 1] * temp
            saved = left[..., j - r] * temp
        N[..., j] = saved
    return N


def basis_functions(t: np.ndarray, degree: int, n_basis: int, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Non-zero B-spline values at ``x``.

    Returns ``(span, N)`` with ``N`` of shape ``x.shape + (degree + 1,)``: the
    values of B-splines ``span - degree ... span`` at ``x``.
    """
    x = np.asarray(x, dtype=float)
    span = _find_span(t, degree, n_basis, x)
    return span, _basis_on_span(t, degree, x, span)


def _basis_derivatives(t: np.ndarray, degree: int, n_basis: int, x: np.ndarray, order: int):
    """Values (order 0) or first derivatives (order 1) of the non-zero B-splines at ``x``."""
    x = np.asarray(x, dtype=float)
    span = _find_span(t, degree, n_basis, x)
    if order == 0:
        return span, _basis_on_span(t, degree, x, span)
    if order != 1:
        raise ValueError("only first derivatives are implemented")
    # N'_{i,p} = p/(t_{i+p}-t_i) N_{i,p-1} - p/(t_{i+p+1}-t_{i+1}) N_{i+1,p-1}
    lower = _basis_on_span(t, degree - 1, x, span)  # B-splines span-p+1 ... span of degree p-1
    dN = np.zeros(x.shape + (degree + 1,))
    for k in range(degree + 1):
        i = span - degree + k
        if k >= 1:
            d = t[i + degree] - t[i]
            dN[..., k] += np.where(d != 0, degree / np.where(d != 0, d, 1.0), 0.0) * lower[..., k - 1]
        if k <= degree - 1:
            d = t[i + degree + 1] - t[i + 1]
            dN[..., k] -= np.where(d != 0, degree / np.where(d != 0, d, 1.0), 0.0) * lower[..., k]
    return span, dN


# --------------------------------------------------------------------------- surface data


def _frozen(a: np.ndarray, dtype=float) -> np.ndarray:
    a = np.array(a, dtype=dtype, copy=True)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class BSplineSurfaceData:
    """A non-rational tensor-product B-spline surface, independent of any CAD kernel.

    Arrays are stored as read-only copies.  ``u_periodic``/``v_periodic`` follow
    OCCT's convention (see the module docstring).
    """

    poles: np.ndarray
    u_knots: np.ndarray
    u_mults: np.ndarray
    v_knots: np.ndarray
    v_mults: np.ndarray
    u_degree: int = 3
    v_degree: int = 3
    u_periodic: bool = False
    v_periodic: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "poles", _frozen(self.poles))
        object.__setattr__(self, "u_knots", _frozen(self.u_knots))
        object.__setattr__(self, "v_knots", _frozen(self.v_knots))
        object.__setattr__(self, "u_mults", _frozen(self.u_mults, int))
        object.__setattr__(self, "v_mults", _frozen(self.v_mults, int))
        object.__setattr__(self, "u_degree", int(self.u_degree))
        object.__setattr__(self, "v_degree", int(self.v_degree))
        object.__setattr__(self, "u_periodic", bool(self.u_periodic))
        object.__setattr__(self, "v_periodic", bool(self.v_periodic))
        if self.poles.ndim != 3 or self.poles.shape[2] != 3:
            raise GeometryError(f"poles must have shape (nu, nv, 3), got {self.poles.shape}", self)
        if not np.all(np.isfinite(self.poles)):
            raise GeometryError("poles contain non-finite values", self)
        nu, nv, _ = self.poles.shape
        for name, knots, mults, deg, per, n in (
            ("u", self.u_knots, self.u_mults, self.u_degree, self.u_periodic, nu),
            ("v", self.v_knots, self.v_mults, self.v_degree, self.v_periodic, nv),
        ):
            if knots.ndim != 1 or knots.shape != mults.shape or knots.size < 2:
                raise GeometryError(f"{name}: knots and mults must be 1-D of equal length >= 2", self)
            if np.any(np.diff(knots) <= 0):
                raise GeometryError(f"{name}: knots must be strictly increasing", self)
            if deg < 1:
                raise GeometryError(f"{name}: degree must be >= 1", self)
            expected = int(mults[:-1].sum()) if per else int(mults.sum()) - deg - 1
            if expected != n:
                raise GeometryError(f"{name}: knots/mults imply {expected} poles, poles have {n}", self)

    # ---------------------------------------------------------------- helpers
    @property
    def shape(self) -> tuple[int, int]:
        """``(nu, nv)``: number of poles in each direction."""
        return self.poles.shape[0], self.poles.shape[1]

    @property
    def u_range(self) -> tuple[float, float]:
        return float(self.u_knots[0]), float(self.u_knots[-1])

    @property
    def v_range(self) -> tuple[float, float]:
        return float(self.v_knots[0]), float(self.v_knots[-1])

    def flat_u_knots(self) -> np.ndarray:
        return flat_knots(self.u_knots, self.u_mults, self.u_degree, self.u_periodic)

    def flat_v_knots(self) -> np.ndarray:
        return flat_knots(self.v_knots, self.v_mults, self.v_degree, self.v_periodic)

    def _dir(self, which: str):
        if which == "u":
            knots, mults, deg, per, n = self.u_knots, self.u_mults, self.u_degree, self.u_periodic, self.shape[0]
        else:
            knots, mults, deg, per, n = self.v_knots, self.v_mults, self.v_degree, self.v_periodic, self.shape[1]
        t = flat_knots(knots, mults, deg, per)
        n_basis = n + deg if per else n
        return t, deg, per, n, n_basis, float(knots[0]), float(knots[-1])

    def _basis(self, which: str, x: np.ndarray, order: int):
        t, deg, per, n, n_basis, lo, hi = self._dir(which)
        x = np.asarray(x, dtype=float)
        if per:
            x = lo + np.mod(x - lo, hi - lo)
        span, N = _basis_derivatives(t, deg, n_basis, x, order)
        idx = span[..., None] - deg + np.arange(deg + 1)
        if per:
            idx = idx % n
        return idx, N

    def evaluate(self, u, v, du: int = 0, dv: int = 0) -> np.ndarray:
        """Point (or first partial derivative with ``du=1``/``dv=1``) at ``(u, v)``; broadcasts, returns ``(..., 3)``."""
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        iu, Nu = self._basis("u", u, du)
        iv, Nv = self._basis("v", v, dv)
        P = self.poles[iu[..., :, None], iv[..., None, :]]  # (..., pu+1, pv+1, 3)
        return np.einsum("...i,...j,...ijk->...k", Nu, Nv, P)

    def evaluate_grid(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Points on the tensor grid ``u x v`` (1-D arrays); returns ``(len(u), len(v), 3)``."""
        Bu = self.collocation("u", u)
        Bv = self.collocation("v", v)
        return np.einsum("ai,ijk,bj->abk", Bu, self.poles, Bv, optimize=True)

    def collocation(self, which: str, x: np.ndarray) -> np.ndarray:
        """Dense matrix ``B[a, i]`` = value of the B-spline attached to pole ``i`` at ``x[a]``."""
        x = np.asarray(x, dtype=float).ravel()
        idx, N = self._basis(which, x, 0)
        n = self.shape[0] if which == "u" else self.shape[1]
        B = np.zeros((x.size, n))
        rows = np.repeat(np.arange(x.size), idx.shape[1])
        np.add.at(B, (rows, idx.ravel()), N.ravel())
        return B

    def degenerate_rows(self, tol: float = 0.0) -> tuple[bool, bool]:
        """Whether the pole rows at ``u`` min / max collapse to a single point (within ``tol``)."""
        first, last = self.poles[0], self.poles[-1]
        return (
            bool(np.max(np.abs(first - first[0])) <= tol),
            bool(np.max(np.abs(last - last[0])) <= tol),
        )

    def as_dict(self) -> dict:
        """Plain-Python representation (lists), e.g. for JSON or FreeCAD's Python."""
        return {
            "poles": self.poles.tolist(),
            "u_knots": self.u_knots.tolist(),
            "u_mults": self.u_mults.tolist(),
            "v_knots": self.v_knots.tolist(),
            "v_mults": self.v_mults.tolist(),
            "u_degree": self.u_degree,
            "v_degree": self.v_degree,
            "u_periodic": self.u_periodic,
            "v_periodic": self.v_periodic,
        }

    @classmethod
    def from_dict(cls, d: dict) -> "BSplineSurfaceData":
        return cls(**{k: d[k] for k in cls.__dataclass_fields__})


# --------------------------------------------------------------------------- fitting


@dataclass(frozen=True)
class SurfaceFit:
    """Result of :func:`fit_surface`: the B-spline plus the measured deviation.

    ``max_deviation`` is the largest distance |S(u, v) - f(u, v)| (same
    parameters) over a check grid ``check_factor`` times denser than the fit
    grid in each direction, which includes the points midway between samples.
    ``u_samples``/``v_samples`` are the interpolation parameters.
    """

    surface: BSplineSurfaceData
    max_deviation: float
    rms_deviation: float
    tol: float
    nu: int
    nv: int
    iterations: int
    check_points: int
    pole_u0: bool
    pole_u1: bool
    seconds: float
    u_samples: np.ndarray = field(repr=False)
    v_samples: np.ndarray = field(repr=False)
    v_breaks: tuple[float, ...] = ()

    @property
    def poles(self) -> tuple[int, int]:
        """Number of poles ``(u, v)`` of the surface (``nv`` counts v spans, not poles, when
        there are breakpoints of multiplicity > 1)."""
        return self.surface.shape

    @property
    def ok(self) -> bool:
        return self.max_deviation <= self.tol


def _clamped_interp_knots(x: np.ndarray, degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Not-a-knot style clamped knots (distinct knots + mults) for interpolation at ``x``."""
    n = x.size
    if n < degree + 1:
        raise GeometryError(f"need at least degree+1 = {degree + 1} samples in u, got {n}")
    if degree % 2 == 1:
        h = (degree + 1) // 2
        interior = x[h : n - h]
    else:
        h = degree // 2
        interior = 0.5 * (x[h : n - h - 1] + x[h + 1 : n - h])
    knots = np.concatenate([[x[0]], interior, [x[-1]]])
    mults = np.concatenate([[degree + 1], np.ones(interior.size, dtype=int), [degree + 1]])
    return knots, mults.astype(int)


def normalise_breaks(v_breaks, period: float = math.tau, merge_tol: float = 1e-9) -> np.ndarray:
    """Sorted distinct breakpoints in ``[0, period)``; values closer than ``merge_tol`` (also across
    the period) are merged, keeping the smaller one."""
    if v_breaks is None:
        return np.zeros(0)
    b = np.asarray(v_breaks, dtype=float).ravel()
    if b.size == 0:
        return np.zeros(0)
    if not np.all(np.isfinite(b)):
        raise GeometryError("v_breaks must be finite numbers", v_breaks)
    b = np.mod(b, period)
    b[b > period - merge_tol] = 0.0  # the same point as 0
    b = np.sort(b)
    b = b[np.concatenate([[True], np.diff(b) > merge_tol])]
    if b[0] <= merge_tol:
        b[0] = 0.0
    return b


def periodic_knots(
    nv: int,
    degree: int,
    v_breaks=None,
    break_mult: int | None = None,
    period: float = math.tau,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Periodic ``v`` knots (distinct values, multiplicities) and interpolation parameters.

    Without breakpoints: ``nv`` uniform spans with multiplicity 1 (``nv``
    poles); odd degree interpolates at the knots, even degree at the span
    midpoints (both are the Greville abscissae, a well-conditioned circulant
    collocation matrix).

    With breakpoints ``v_breaks`` (values in ``[0, period)``; sorted, merged
    and wrapped here): every breakpoint is a knot of multiplicity
    ``break_mult`` (default ``degree - 1``: the B-spline is C1 there; use
    ``degree`` for C0) and each piece between consecutive breakpoints is cut
    into ``max(1, round(nv * length / period))`` uniform spans, so the spline is
    a polynomial of full order on every span of each smooth piece.  ``0`` is
    always a knot (multiplicity 1 unless it is a breakpoint) so the parameter
    range stays ``[0, period]``.  The interpolation parameters are the
    Greville abscissae of the periodic B-splines, which satisfy the
    Schoenberg-Whitney condition (every B-spline contains its own point inside
    its support) for multiplicities ``<= degree``.
    """
    nv = int(nv)
    breaks = normalise_breaks(v_breaks, period)
    if breaks.size == 0:
        knots = np.linspace(0.0, period, nv + 1)
        mults = np.ones(nv + 1, dtype=int)
        h = period / nv
        shift = 0.0 if degree % 2 == 1 else 0.5 * h
        return knots, mults, knots[:-1] + shift
    mb = degree - 1 if break_mult is None else int(break_mult)
    if not 1 <= mb <= degree:
        raise ValueError(f"break_mult = {mb} is not allowed: must be in [1, degree = {degree}]")
    anchors = breaks if breaks[0] == 0.0 else np.concatenate([[0.0], breaks])
    anchor_mult = np.full(anchors.size, mb, dtype=int)
    if breaks[0] != 0.0:
        anchor_mult[0] = 1
    ends = np.concatenate([anchors[1:], [period]])
    lengths = ends - anchors
    knots_l, mults_l = [], []
    for a, e, L, m in zip(anchors, ends, lengths, anchor_mult):
        n = max(1, round(nv * L / period))
        knots_l.append(a + (e - a) * np.arange(n) / n)
        mults_l.append(np.concatenate([[m], np.ones(n - 1, dtype=int)]))
    knots = np.concatenate(knots_l + [[period]])
    mults = np.concatenate(mults_l + [[anchor_mult[0]]]).astype(int)
    if np.any(np.diff(knots) <= 0):
        raise GeometryError("periodic knots are not strictly increasing (breakpoints too close)", knots)
    n_poles = int(mults[:-1].sum())
    if n_poles < degree + 1:  # too few poles for a periodic B-spline: refine uniformly
        return periodic_knots(nv + degree + 1, degree, v_breaks, break_mult, period)
    t = flat_knots(knots, mults, degree, True)
    # Greville abscissa of B-spline i: mean of its interior knots t[i+1 .. i+degree]
    csum = np.concatenate([[0.0], np.cumsum(t)])
    grev = (csum[degree + 1 : degree + 1 + n_poles] - csum[1 : 1 + n_poles]) / degree
    samples = np.sort(np.mod(grev, period))
    samples[np.abs(samples - period) < 1e-14 * period] = 0.0
    samples = np.sort(samples)
    if np.any(np.diff(samples) <= 0):
        raise GeometryError("Greville abscissae are not distinct (degenerate knot vector)", knots)
    return knots, mults, samples


def _eval_f(f: SurfaceFunction, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``f`` on the tensor grid ``u x v``; uses ``f.evaluate_grid(u, v)`` when ``f`` has one
    (e.g. a PDE patch: matrix products instead of point-wise series, ~25x faster)."""
    grid = getattr(f, "evaluate_grid", None)
    shape = (np.size(u), np.size(v))
    if grid is not None:
        X = np.asarray(grid(np.asarray(u, dtype=float), np.asarray(v, dtype=float)), dtype=float)
    else:
        U, V = np.meshgrid(u, v, indexing="ij")
        X = np.asarray(f(U, V), dtype=float)
    X = np.broadcast_to(X, shape + (3,))
    if not np.all(np.isfinite(X)):
        raise GeometryError("surface function returned non-finite values", f)
    return np.array(X)


def _solve_poles(
    D: np.ndarray, u: np.ndarray, v: np.ndarray, u_degree: int, v_degree: int, v_knots, v_mults, u_periodic: bool
):
    """Poles interpolating grid data ``D[i, j] = f(u[i], v[j])`` (tensor-product collocation)."""
    nu, nv = D.shape[:2]
    if u_periodic:
        raise NotImplementedError("periodic u is not supported")
    u_knots, u_mults = _clamped_interp_knots(u, u_degree)
    proto = BSplineSurfaceData(
        poles=np.zeros((nu, nv, 3)),
        u_knots=u_knots,
        u_mults=u_mults,
        v_knots=v_knots,
        v_mults=v_mults,
        u_degree=u_degree,
        v_degree=v_degree,
        u_periodic=False,
        v_periodic=True,
    )
    Bu = proto.collocation("u", u)
    Bv = proto.collocation("v", v)
    # along u: the end rows of a clamped interpolant equal the data exactly, so
    # solve only for the interior rows (keeps boundary rows bit-identical to the data).
    X = np.empty_like(D)
    X[0] = D[0]
    X[-1] = D[-1]
    if nu > 2:
        rhs = D[1:-1].reshape(nu - 2, -1) - np.outer(Bu[1:-1, 0], D[0].ravel()) - np.outer(Bu[1:-1, -1], D[-1].ravel())
        X[1:-1] = np.linalg.solve(Bu[1:-1, 1:-1], rhs).reshape(nu - 2, nv, 3)
    # along v (periodic): Bv P_i = X_i for every row i
    rhs = X.transpose(1, 0, 2).reshape(nv, -1)
    P = np.linalg.solve(Bv, rhs).reshape(nv, nu, 3).transpose(1, 0, 2)
    return u_knots, u_mults, np.ascontiguousarray(P)


def _pole_point(row: np.ndarray, pole_tol: float) -> np.ndarray | None:
    centre = row.mean(axis=0)
    if np.max(np.linalg.norm(row - centre, axis=-1)) <= pole_tol:
        return centre
    return None


def _build(
    f: SurfaceFunction,
    nu: int,
    nv: int,
    u_degree: int,
    v_degree: int,
    pole_tol: float,
    u_range: tuple[float, float],
    boundary_rows: tuple[np.ndarray | None, np.ndarray | None] = (None, None),
    v_breaks=None,
    break_mult: int | None = None,
):
    u = np.linspace(u_range[0], u_range[1], nu)
    v_knots, v_mults, v = periodic_knots(nv, v_degree, v_breaks, break_mult)
    D = _eval_f(f, u, v)
    poles_flags = []
    for k, r in ((0, 0), (-1, 1)):
        if boundary_rows[r] is not None:
            D[k] = boundary_rows[r]
        p = _pole_point(D[k], pole_tol)
        if p is not None:
            D[k] = p  # a collapsed boundary becomes exactly one point
        poles_flags.append(p is not None)
    u_knots, u_mults, P = _solve_poles(D, u, v, u_degree, v_degree, v_knots, v_mults, False)
    # interpolating constant data along v gives the constant back up to round-off: make it exact
    for k, flag in ((0, poles_flags[0]), (-1, poles_flags[1])):
        if flag:
            P[k] = D[k][0]
    data = BSplineSurfaceData(P, u_knots, u_mults, v_knots, v_mults, u_degree, v_degree, False, True)
    return data, u, v, poles_flags, D


def _deviation(f: SurfaceFunction, data: BSplineSurfaceData, u: np.ndarray, v: np.ndarray, factor: int):
    """Errors on a grid ``factor`` x denser (includes midpoints between samples)."""
    nu = u.size
    uc = np.linspace(u[0], u[-1], factor * (nu - 1) + 1)
    # ``factor`` points per gap between consecutive (periodic) samples; column ``factor * j`` is sample j
    vs = np.concatenate([v, [v[0] + math.tau]])
    vc = (vs[:-1, None] + (np.arange(factor) / factor)[None, :] * np.diff(vs)[:, None]).ravel()
    F = _eval_f(f, uc, vc)
    S = data.evaluate_grid(uc, vc)
    E = np.linalg.norm(S - F, axis=-1)
    # split: points on sample v-lines (pure u-interpolation error) and on sample u-lines
    err_u = float(E[:, ::factor].max())
    err_v = float(E[::factor, :].max())
    return float(E.max()), float(np.sqrt(np.mean(E**2))), err_u, err_v, E.size


def fit_surface(
    f: SurfaceFunction,
    u_degree: int = 3,
    v_degree: int = 3,
    nu: int = 17,
    nv: int = 32,
    periodic_v: bool = True,
    tol: float = 1e-4,
    *,
    max_nu: int = 400,
    max_nv: int = 512,
    max_iterations: int = 12,
    check_factor: int = 4,
    pole_tol: float = 1e-9,
    u_range: tuple[float, float] = (0.0, 1.0),
    fixed_nv: bool = False,
    boundary_rows: tuple[np.ndarray | None, np.ndarray | None] = (None, None),
    v_breaks: Sequence[float] | None = None,
    v_break_mult: int | None = None,
    name: str = "surface",
    raise_on_failure: bool = True,
) -> SurfaceFit:
    """Interpolate ``f`` by a B-spline (clamped in ``u``, periodic in ``v``) within ``tol``.

    ``f(u, v)`` must broadcast its arguments and return ``(..., 3)``.  The
    surface is sampled on a uniform ``nu x nv`` grid of its own parameters,
    poles are obtained by solving the 1-D collocation systems along ``u`` then
    along ``v``, and the grid is refined (per direction, from the measured
    error and the ``h^(p+1)`` convergence rate) until the maximum deviation on a
    ``check_factor``-times denser grid is ``<= tol`` (same unit as ``f``, mm).
    A boundary row whose points agree within ``pole_tol`` is a pole: its
    poles are set to exactly one point.  ``fixed_nv`` keeps ``nv`` unchanged
    (used by :func:`fit_patches` to share boundary rows); ``boundary_rows``
    overrides the sampled data of the ``u`` min / max rows.

    ``v_breaks``: values of ``v`` where ``f`` is not smooth in ``v`` (e.g. the
    junctions of an outline's arcs and lines, where the surface is only C1).
    They become knots of multiplicity ``v_break_mult`` (default
    ``v_degree - 1``, C1; ``v_degree`` gives C0) with uniform spans between
    them and Greville interpolation points (see :func:`periodic_knots`), so
    every smooth piece converges at the full order ``h^(v_degree+1)``.  ``nv``
    then counts knot spans rather than poles.

    Raises :class:`GeometryError` naming ``name`` and the deviation if the
    tolerance cannot be met within ``max_nu``/``max_nv``/``max_iterations``
    (unless ``raise_on_failure`` is false).
    """
    if not periodic_v:
        raise NotImplementedError("fit_surface only supports periodic v (a closed patch)")
    if tol <= 0 or not math.isfinite(tol):
        raise ValueError(f"tol = {tol} is not allowed: must be > 0")
    t0 = time.perf_counter()
    nu = max(int(nu), u_degree + 1)
    nv = max(int(nv), v_degree + 1)
    breaks = normalise_breaks(v_breaks)
    best = None
    for it in range(1, max_iterations + 1):
        data, u, v, flags, _ = _build(
            f, nu, nv, u_degree, v_degree, pole_tol, u_range, boundary_rows, breaks, v_break_mult
        )
        dmax, drms, err_u, err_v, npts = _deviation(f, data, u, v, check_factor)
        best = SurfaceFit(
            data, dmax, drms, tol, nu, nv, it, npts, flags[0], flags[1], time.perf_counter() - t0, u, v,
            tuple(float(b) for b in breaks),
        )
        if dmax <= tol:
            return best
        # refine: error ~ h^(p+1); aim at 0.4 tol (error on sample v-lines is pure
        # u-interpolation error and vice versa)
        target = 0.4 * tol
        ref_u, ref_v = err_u > target, err_v > target and not fixed_nv
        if not (ref_u or ref_v):
            ref_u, ref_v = True, not fixed_nv
        new_nu, new_nv = nu, nv
        if ref_u:
            ratio = (err_u if err_u > target else dmax) / target
            new_nu = int(math.ceil((nu - 1) * min(max(ratio ** (1.0 / (u_degree + 1)), 1.25), 3.0))) + 1
        if ref_v:
            ratio = (err_v if err_v > target else dmax) / target
            new_nv = int(math.ceil(nv * min(max(ratio ** (1.0 / (v_degree + 1)), 1.25), 3.0)))
        new_nu, new_nv = min(new_nu, max_nu), min(new_nv, max_nv)
        if (new_nu, new_nv) == (nu, nv):
            break
        nu, nv = new_nu, new_nv
    assert best is not None
    if raise_on_failure:
        raise GeometryError(
            f"B-spline fit of {name} misses tolerance: max deviation {best.max_deviation:.3g} mm > "
            f"tol {tol:.3g} mm with {best.surface.shape[0]} x {best.surface.shape[1]} poles",
            best,
        )
    return best


def fit_patches(
    functions: Sequence[SurfaceFunction],
    tol: float = 1e-4,
    *,
    names: Sequence[str] | None = None,
    u_degree: int = 3,
    v_degree: int = 3,
    nu: int = 17,
    nv: int = 32,
    share_tol: float = 1e-9,
    v_breaks: Sequence[float] | None = None,
    v_break_mult: int | None = None,
    **kwargs,
) -> list[SurfaceFit]:
    """Fit a chain of patches (patch ``j``'s ``u=1`` curve is patch ``j+1``'s ``u=0`` curve).

    All patches get the same periodic ``v`` knots, and a shared boundary row is
    sampled once and reused, so neighbours have bit-identical boundary poles
    (and sew without gaps).  A closed chain (a ring: last ``u=1`` equals first
    ``u=0``) is detected and shared too.  Raises :class:`GeometryError` naming
    the patch if a fit misses ``tol`` or if neighbouring boundaries disagree by
    more than ``share_tol``.

    ``v_breaks`` (see :func:`fit_surface`) must be the union of the breakpoints
    of the whole chain: every patch gets the same breakpoint knots, which keeps
    the v knot vectors, hence the shared boundary rows, identical.
    """
    functions = list(functions)
    n = len(functions)
    names = list(names) if names is not None else [f"patch {j}" for j in range(n)]
    # pass 1: independent fits to find the v resolution each patch needs
    kwargs.update(v_breaks=v_breaks, v_break_mult=v_break_mult)
    first = [
        fit_surface(fj, u_degree, v_degree, nu, nv, True, tol, name=names[j], **kwargs)
        for j, fj in enumerate(functions)
    ]
    nv_common = max(fit.nv for fit in first)
    _, _, v = periodic_knots(nv_common, v_degree, v_breaks, v_break_mult)
    zeros = np.zeros(1)
    rows_end = [_eval_f(fj, np.array([1.0]), v)[0] for fj in functions]
    rows_start = [_eval_f(fj, zeros, v)[0] for fj in functions]
    shared: list[list[np.ndarray | None]] = [[None, None] for _ in range(n)]
    pairs = [(j, j + 1) for j in range(n - 1)]
    if n > 1 and np.max(np.linalg.norm(rows_end[-1] - rows_start[0], axis=-1)) <= share_tol:
        pairs.append((n - 1, 0))
    for a, b in pairs:
        gap = float(np.max(np.linalg.norm(rows_end[a] - rows_start[b], axis=-1)))
        if gap > share_tol:
            raise GeometryError(
                f"{names[a]} (u=1) and {names[b]} (u=0) do not share their boundary curve: gap {gap:.3g} mm",
                (functions[a], functions[b]),
            )
        shared[a][1] = rows_end[a]
        shared[b][0] = rows_end[a]
    fits = []
    for j, fj in enumerate(functions):
        if first[j].nv == nv_common and all(r is None for r in shared[j]):
            fits.append(first[j])
            continue
        fits.append(
            fit_surface(
                fj,
                u_degree,
                v_degree,
                first[j].nu,
                nv_common,
                True,
                tol,
                fixed_nv=True,
                boundary_rows=(shared[j][0], shared[j][1]),
                name=names[j],
                **kwargs,
            )
        )
    # The shared rows were solved from identical data with the identical periodic
    # matrix; copy them so that they are bit-identical whatever LAPACK does.
    for a, b in pairs:
        pa, pb = fits[a].surface.poles, fits[b].surface.poles
        diff = float(np.max(np.abs(pa[-1] - pb[0])))
        if diff > max(share_tol, 1e-12):
            raise GeometryError(f"{names[a]} and {names[b]}: shared boundary poles differ by {diff:.3g}", fits)
        poles = np.array(pb)
        poles[0] = pa[-1]
        fits[b] = replace(fits[b], surface=replace(fits[b].surface, poles=poles))
    return fits


def enclosed_volume(surfaces: Sequence[BSplineSurfaceData]) -> float:
    """Signed volume enclosed by a closed chain of B-spline patches (divergence theorem).

    ``V = 1/3 sum_k  integral S . (S_u x S_v) du dv``; the integrand is a
    polynomial on every knot span, so Gauss-Legendre with ``ceil(3p/2)`` points
    per span and direction is exact up to round-off.  The sign follows the
    parametrisation (positive when ``S_u x S_v`` points outward).
    """
    total = 0.0
    for s in surfaces:
        rules = []
        for knots, deg in ((s.u_knots, s.u_degree), (s.v_knots, s.v_degree)):
            n = int(math.ceil(3 * deg / 2)) + 1
            x, w = np.polynomial.legendre.leggauss(n)
            a, b = knots[:-1, None], knots[1:, None]
            rules.append(((((b - a) * x + (a + b)) / 2).ravel(), (((b - a) / 2) * w).ravel()))
        (uq, uw), (vq, vw) = rules
        U, V = np.meshgrid(uq, vq, indexing="ij")
        S = s.evaluate(U, V)
        Su = s.evaluate(U, V, du=1)
        Sv = s.evaluate(U, V, dv=1)
        integrand = np.einsum("...k,...k->...", S, np.cross(Su, Sv))
        total += float(np.einsum("i,j,ij->", uw, vw, integrand)) / 3.0
    return total


class PatchFunction:
    """``f(u, v) = patch.evaluate(u, v)``; keeps the patch's ``evaluate_grid`` (tensor grids by
    matrix products), which :func:`tabletcad.bspline.fit_surface` uses when present."""

    def __init__(self, patch) -> None:
        self.patch = patch
        if hasattr(patch, "evaluate_grid"):
            self.evaluate_grid = lambda u, v: np.asarray(patch.evaluate_grid(u, v))

    def __call__(self, u, v) -> np.ndarray:
        return np.asarray(self.patch.evaluate(u, v))


def chain_breakpoints(patches) -> np.ndarray:
    """Union (sorted, in [0, 2 pi), values within 1e-9 merged) of the ``breakpoints()`` of the
    patches that have them."""
    pts = [np.asarray(p.breakpoints(), dtype=float).ravel() for p in patches if hasattr(p, "breakpoints")]
    pts = [b for b in pts if b.size]
    if not pts:
        return np.zeros(0)
    return normalise_breaks(np.concatenate(pts))


