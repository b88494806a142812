"""Kernel-neutral tensor-product B-spline surfaces (numpy only; never imports a CAD kernel).

FreeCAD's own Python and the OCP layer in :mod:`tabletcad.cad` both build their
surfaces from the same :class:`BSplineSurfaceData`.

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
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tabletcad.brep.knots import basis_derivatives, flat_knots
from tabletcad.errors import GeometryError
from tabletcad.geometry.vectors import cross
from tabletcad.geometry.quadrature import gauss_legendre
from tabletcad.geometry.tables import COLLOCATION

__all__ = ["BSplineSurfaceData", "enclosed_volume", "volume_and_area", "segment_v", "segments_v"]


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
        span, N = basis_derivatives(t, deg, n_basis, x, order)
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

    def evaluate_grid(self, u: np.ndarray, v: np.ndarray, du: int = 0, dv: int = 0, *,
                      components: bool = False) -> np.ndarray:
        """Points (or first partial derivatives) on the tensor grid ``u x v`` (1-D arrays);
        returns ``(len(u), len(v), 3)``, or with ``components`` the same values as the products
        make them, ``(3, len(u), len(v))`` (a new array, no transposed copy)."""
        Bu = self.collocation("u", u, du)
        Bv = self.collocation("v", v, dv)
        # two matrix products per coordinate, (B_u P_c) B_v^T or B_u (P_c B_v^T), whichever costs less
        # (:func:`_v_first`; an einsum searching its path took as long)
        P = np.ascontiguousarray(self.poles.transpose(2, 0, 1))
        X = Bu @ (P @ Bv.T) if _v_first(len(Bu), len(Bv), *self.shape) else (Bu @ P) @ Bv.T  # (3, len(u), len(v))
        return X if components else np.ascontiguousarray(X.transpose(1, 2, 0))

    def grid_components(self, u: np.ndarray, v: np.ndarray, collocation=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Points, ``S_u`` and ``S_v`` on the tensor grid ``u x v``, components first: each
        ``(3, len(u), len(v))``, C-contiguous.  One collocation matrix per direction and order,
        and two matrix products per component (``B_u P_c B_v^T``).  ``collocation(which, x)``,
        if given, supplies ``(values, first derivatives)`` matrices (e.g. shared by surfaces
        with the same knots).

        The products run in the cheaper order (:func:`_v_first`): the direction with more
        samples than poles is contracted last, so the large sample grid is made by one product
        and not two (the volume's Gauss grid of a 17 x 64 pole patch, 108 x 288 points: 6.6
        instead of 19 million multiply-adds, 0.4 instead of 1.3 ms).  The sums are the same
        terms in another order: equal to rounding."""
        u, v = np.asarray(u, dtype=float).ravel(), np.asarray(v, dtype=float).ravel()
        if collocation is None:
            def collocation(which, x):
                return self.collocation(which, x), self.collocation(which, x, 1)
        Bu, Bu1 = collocation("u", u)
        Bv, Bv1 = collocation("v", v)
        nu, nv = self.shape
        P = np.ascontiguousarray(self.poles.transpose(2, 0, 1))  # (3, u poles, v poles)
        if _v_first(len(u), len(v), nu, nv, 2, 3):
            C, C1 = P @ Bv.T, P @ Bv1.T  # (3, u poles, len(v))
            return Bu @ C, Bu1 @ C, Bu @ C1
        BvT, Bv1T = Bv.T, Bv1.T
        A, A1 = Bu @ P, Bu1 @ P  # (3, len(u), v poles)
        return A @ BvT, A1 @ BvT, A @ Bv1T

    def collocation(self, which: str, x: np.ndarray, order: int = 0) -> np.ndarray:
        """Dense matrix ``B[a, i]`` = value (``order`` 0) or first derivative (``order`` 1) of the
        B-spline attached to pole ``i`` at ``x[a]``; read-only, shared by every surface with the
        same knots in that direction (:data:`~tabletcad.geometry.tables.COLLOCATION`)."""
        x = np.asarray(x, dtype=float).ravel()
        n = self.shape[0] if which == "u" else self.shape[1]

        def make() -> np.ndarray:
            idx, N = self._basis(which, x, order)
            B = np.zeros((x.size, n))
            rows = np.repeat(np.arange(x.size), idx.shape[1])
            np.add.at(B, (rows, idx.ravel()), N.ravel())
            return B

        if which == "u":
            knots, mults, deg, per = self.u_knots, self.u_mults, self.u_degree, self.u_periodic
        else:
            knots, mults, deg, per = self.v_knots, self.v_mults, self.v_degree, self.v_periodic
        key = ("collocation", order, n, deg, per, knots.tobytes(), mults.tobytes(), x.tobytes())
        return COLLOCATION.get(key, make)

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


def _v_first(n_u: int, n_v: int, poles_u: int, poles_v: int, first: int = 1, second: int = 1) -> bool:
    """Whether a tensor grid of ``n_u x n_v`` samples of a ``poles_u x poles_v`` net costs fewer
    multiply-adds contracting ``v`` first (``P B_v^T``, ``poles_u poles_v n_v`` each, then ``B_u``
    times that, ``n_u poles_u n_v`` each) than ``u`` first, with ``first`` products of the first
    kind and ``second`` of the second (:meth:`BSplineSurfaceData.grid_components`: 2 and 3, the
    values and the derivatives; :meth:`~BSplineSurfaceData.evaluate_grid`: 1 and 1)."""
    v_first = first * poles_u * poles_v * n_v + second * n_u * poles_u * n_v
    u_first = first * n_u * poles_u * poles_v + second * n_u * poles_v * n_v
    return v_first < u_first


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
    return segments_v(data, [(a, b)])[0]


def segments_v(data: BSplineSurfaceData, spans) -> tuple[BSplineSurfaceData, ...]:
    """:func:`segment_v` of every ``(a, b)`` in ``spans``, the knot vector set up once."""
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
    else:
        t = np.repeat(knots, mults)
        shift = 0
    scale = max(1.0, float(np.max(np.abs(t))))
    eps = 1e-12 * scale
    n_basis = t.size - p - 1
    all_poles = np.asarray(data.poles)
    out = []
    for a, b in spans:
        a, b = float(a), float(b)
        if data.v_periodic:
            if not (knots[0] <= a < knots[-1] and a < b <= a + period + 1e-12):
                raise GeometryError(f"segment_v: [{a}, {b}] is not within one period from [{knots[0]}, {knots[-1]})",
                                    data)
        elif not (knots[0] <= a < b <= knots[-1]):
            raise GeometryError(f"segment_v: [{a}, {b}] is not within [{knots[0]}, {knots[-1]}]", data)
        for x in (a, b):
            if int(np.count_nonzero(np.abs(t - x) <= eps)) < p and not (not data.v_periodic
                                                                         and x in (knots[0], knots[-1])):
                raise GeometryError(f"segment_v: v = {x} is not a knot of multiplicity >= {p}", data)
        active = np.flatnonzero((t[:n_basis] < b - eps) & (t[p + 1:p + 1 + n_basis] > a + eps))
        inner = t[(t > a + eps) & (t < b - eps)]  # sorted: equal values are neighbours
        if inner.size:
            first = np.concatenate([[True], inner[1:] != inner[:-1]])
            vals = inner[first]
            counts = np.diff(np.concatenate([np.flatnonzero(first), [inner.size]]))
        else:
            vals, counts = inner, np.zeros(0, dtype=int)
        # exact parts of valid data are valid: made without the constructor's checks (a third of the time)
        piece = object.__new__(BSplineSurfaceData)
        for name, value in (("poles", all_poles[:, (active + shift) % n, :]),
                            ("v_knots", np.concatenate([[a], vals, [b]])),
                            ("v_mults", np.concatenate([[p + 1], counts, [p + 1]]).astype(int))):
            value.setflags(write=False)
            object.__setattr__(piece, name, value)
        for name in ("u_knots", "u_mults", "u_degree", "v_degree", "u_periodic"):
            object.__setattr__(piece, name, getattr(data, name))
        object.__setattr__(piece, "v_periodic", False)
        out.append(piece)
    return tuple(out)


def enclosed_volume(surfaces: Sequence) -> float:
    """Signed volume enclosed by a closed chain of B-spline patches (divergence theorem).

    ``V = 1/3 sum_k  integral S . (S_u x S_v) du dv``; the integrand is a
    polynomial on every knot span, so Gauss-Legendre with ``ceil(3p/2)`` points
    per span and direction is exact up to round-off.  The sign follows the
    parametrisation (positive when ``S_u x S_v`` points outward).  Faces of revolution
    (:class:`~tabletcad.brep.revolved.RevolvedSurfaceData`) contribute
    :func:`~tabletcad.brep.revolved.revolved_volume`.
    """
    from tabletcad.brep.revolved import RevolvedSurfaceData, revolved_volume

    total = 0.0
    for s in surfaces:
        if isinstance(s, RevolvedSurfaceData):
            total += revolved_volume([s])
            continue
        rules = []
        for knots, deg in ((s.u_knots, s.u_degree), (s.v_knots, s.v_degree)):
            n = int(math.ceil(3 * deg / 2)) + 1
            x, w = gauss_legendre(n)
            a, b = knots[:-1, None], knots[1:, None]
            rules.append(((((b - a) * x + (a + b)) / 2).ravel(), (((b - a) / 2) * w).ravel()))
        (uq, uw), (vq, vw) = rules
        S = s.evaluate_grid(uq, vq)
        Su = s.evaluate_grid(uq, vq, du=1)
        Sv = s.evaluate_grid(uq, vq, dv=1)
        integrand = np.einsum("...k,...k->...", S, cross(Su, Sv))
        total += float(np.einsum("i,j,ij->", uw, vw, integrand)) / 3.0
    return total



def _span_rule(knots: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights, ``n`` per knot span."""
    x, w = gauss_legendre(n)
    a, b = knots[:-1, None], knots[1:, None]
    return (((b - a) * x + (a + b)) / 2).ravel(), (((b - a) / 2) * w).ravel()


def volume_and_area(surfaces: Sequence) -> tuple[float, float]:
    """Signed enclosed volume (mm³, as :func:`enclosed_volume`) and area (mm²) of a closed
    chain of B-spline patches or faces of revolution, from one Gauss-Legendre grid per face.

    Every knot span gets ``max(ceil(3p/2) + 1, p + 4)`` points per direction: the volume's
    integrand ``S · (S_u × S_v)`` is a polynomial there, integrated exactly; the area's
    ``|S_u × S_v|`` is the root of one, smooth on every span wherever the patch is regular (a
    pole row, where ``S_v = 0``, lies on a span's end).  OCCT's adaptive integration of the
    same faces converges to these values: 1e-9 relative apart at ``eps = 1e-9``, within 3e-13
    at ``eps = 1e-12`` on the bundled samples (``tests/test_cad_solid.py``), at a tenth to a
    twentieth of the cost.  A face of revolution
    ``(R cos θ, R sin θ, Z)`` contributes ``(2π/3) ∫ (Z R R' - R² Z') du`` and
    ``2π ∫ |R| |(R', Z')| du``.
    """
    from tabletcad.brep.revolved import RevolvedSurfaceData

    volume = area = 0.0
    for s in surfaces:
        if isinstance(s, RevolvedSurfaceData):
            u, wu = _span_rule(s.knots, max(int(math.ceil(3 * s.degree / 2)) + 1, s.degree + 4))
            # (the faces of a chain fitted with as many poles share these nodes: RevolvedSurfaceData.profile)
            (R, Z), (dR, dZ) = s.profile(u, shared=True).T, s.profile(u, 1, shared=True).T
            volume += (math.tau / 3.0) * float(np.sum(wu * (Z * R * dR - R * R * dZ)))
            area += math.tau * float(np.sum(wu * np.abs(R) * np.hypot(dR, dZ)))
            continue
        (uq, uw), (vq, vw) = (_span_rule(k, max(int(math.ceil(3 * d / 2)) + 1, d + 4))
                              for k, d in ((s.u_knots, s.u_degree), (s.v_knots, s.v_degree)))
        (x, y, z), (xu, yu, zu), (xv, yv, zv) = s.grid_components(uq, vq)
        # the normal S_u x S_v, the volume's and the area's integrands, each term as before and in the
        # same order, written in place: four grid-sized arrays a face instead of eighteen (0.7 of 8 ms)
        nx = yu * zv
        nx -= zu * yv
        ny = zu * xv
        ny -= xu * zv
        nz = xu * yv
        nz -= yu * xv
        f = x * nx
        f += y * ny
        f += z * nz
        volume += float(uw @ f @ vw) / 3.0
        np.multiply(nx, nx, out=f)
        f += ny * ny
        f += nz * nz
        area += float(uw @ np.sqrt(f, out=f) @ vw)
    return volume, area
