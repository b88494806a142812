"""Surfaces of revolution about the z axis with a B-spline profile (numpy only).

A PDE patch of revolution (:mod:`tabletcad.geometry.revolution`) is its profile
``(R(u), Z(u))`` turned a full circle about the z axis.  Its CAD face is exactly
that: a clamped cubic B-spline profile in the half-plane ``y = 0`` (``x = R``)
revolved about z, which OCCT (``Geom_SurfaceOfRevolution``) and STEP
(``SURFACE_OF_REVOLUTION``) represent exactly.  Only the profile is fitted, so
the fit is one-dimensional and its deviation at equal parameters *is* the
surface's deviation at equal ``(u, angle)``: the circles are exact.

:func:`fit_profile` interpolates the profile at its own parameters and refines
until the deviation measured on a denser grid is within the tolerance, like
:func:`tabletcad.brep.fit.fit_surface` in ``u``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from tabletcad.brep.knots import basis_derivatives, clamped_interp_knots, flat_knots
from tabletcad.errors import GeometryError
from tabletcad.geometry.quadrature import gauss_legendre
from tabletcad.geometry.tables import COLLOCATION

__all__ = ["RevolvedSurfaceData", "ProfileFit", "fit_profile", "fit_profiles", "revolved_mesh", "revolved_volume"]

ProfileFunction = Callable[[np.ndarray], np.ndarray]


def _frozen(a, dtype=float) -> np.ndarray:
    a = np.array(a, dtype=dtype, copy=True)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class RevolvedSurfaceData:
    """A clamped B-spline profile ``(R, Z)`` (mm) revolved a full turn about the z axis.

    ``poles`` has shape ``(n, 2)``: ``(R, Z)`` of each pole in the half-plane
    ``y = 0``; ``knots`` are the distinct knot values and ``mults`` their
    multiplicities (``sum(mults) == n + degree + 1``), as for
    :class:`~tabletcad.brep.surface.BSplineSurfaceData`.  The surface point at
    ``(u, θ)`` is ``(R(u) cos θ, R(u) sin θ, Z(u))``.
    """

    poles: np.ndarray
    knots: np.ndarray
    mults: np.ndarray
    degree: int = 3

    def __post_init__(self) -> None:
        object.__setattr__(self, "poles", _frozen(self.poles))
        object.__setattr__(self, "knots", _frozen(self.knots))
        object.__setattr__(self, "mults", _frozen(self.mults, int))
        object.__setattr__(self, "degree", int(self.degree))
        if self.poles.ndim != 2 or self.poles.shape[1] != 2:
            raise GeometryError(f"profile poles must have shape (n, 2), got {self.poles.shape}", self)
        if not np.all(np.isfinite(self.poles)):
            raise GeometryError("profile poles contain non-finite values", self)
        if self.degree < 1 or self.knots.ndim != 1 or self.knots.shape != self.mults.shape or self.knots.size < 2:
            raise GeometryError("profile knots/mults must be 1-D of equal length >= 2 and degree >= 1", self)
        if np.any(np.diff(self.knots) <= 0):
            raise GeometryError("profile knots must be strictly increasing", self)
        if int(self.mults.sum()) - self.degree - 1 != self.poles.shape[0]:
            raise GeometryError("profile knots/mults do not match the number of poles", self)

    @property
    def shape(self) -> tuple[int, int]:
        """``(n, 1)``: the profile's poles, revolved (one meridian; the circles are exact)."""
        return self.poles.shape[0], 1

    @property
    def u_range(self) -> tuple[float, float]:
        return float(self.knots[0]), float(self.knots[-1])

    def _basis(self, u: np.ndarray, order: int, shared: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Pole indices and values (``order`` 0) or first derivatives (1) of the non-zero B-splines at
        ``u``; with ``shared``, read-only and shared by every profile with the same knots and samples
        (:data:`~tabletcad.geometry.tables.COLLOCATION`)."""
        if shared:
            key = ("revolved basis", order, self.degree, self.knots.tobytes(), self.mults.tobytes(), u.shape,
                   u.tobytes())
            return COLLOCATION.get(key, lambda: self._basis(u, order))
        t = flat_knots(self.knots, self.mults, self.degree, False)
        span, N = basis_derivatives(t, self.degree, self.poles.shape[0], u, order)
        return span[..., None] - self.degree + np.arange(self.degree + 1), N

    def profile(self, u, du: int = 0, *, shared: bool = False) -> np.ndarray:
        """``(R, Z)`` (or its first ``u``-derivative) at ``u``; shape ``u.shape + (2,)``.

        ``shared``: the B-spline values are kept for the next profile with the same knots evaluated at
        the same ``u`` (:meth:`_basis`).  For samples that do not depend on the profile's shape - a fit's
        check grid, the Gauss nodes of the volume and area, the curvature samples of the mesh: the faces
        of a chain fitted with as many poles share their knots, so one table serves them all (on the
        compound cup 7 faces, ~60 µs a table)."""
        u = np.asarray(u, dtype=float)
        idx, N = self._basis(u, du, shared)
        # np.take: the same gather as poles[idx], ~6x faster (5 instead of 32 µs for 513 points)
        return np.einsum("...i,...ik->...k", N, np.take(self.poles, idx, axis=0))

    def evaluate_grid(self, u, theta) -> np.ndarray:
        """Points on the grid ``u × θ`` (θ the plan angle, rad): shape ``(len(u), len(θ), 3)``."""
        P = self.profile(np.asarray(u, dtype=float).reshape(-1))
        th = np.asarray(theta, dtype=float).reshape(-1)
        return np.stack([np.outer(P[:, 0], np.cos(th)), np.outer(P[:, 0], np.sin(th)),
                         np.repeat(P[:, 1:2], th.size, axis=1)], axis=-1)

    def as_dict(self) -> dict:
        """Plain-Python representation (lists), e.g. for JSON or FreeCAD's Python."""
        return {"poles": self.poles.tolist(), "knots": self.knots.tolist(), "mults": self.mults.tolist(),
                "degree": self.degree}


def revolved_volume(surfaces) -> float:
    """Signed volume (mm³) enclosed by a closed chain of revolved profiles (divergence theorem).

    For ``S(u, θ) = (R cos θ, R sin θ, Z)``, ``S · (S_u × S_θ) = Z R R' - R² Z'``, so each
    face contributes ``(2π/3) ∫ (Z R R' - R² Z') du``: a polynomial of degree ``3p - 1`` on every
    knot span, integrated exactly by Gauss-Legendre with ``ceil(3p/2)`` points per span.
    The sign follows the parametrisation ``(u, θ)``.
    """
    total = 0.0
    for s in surfaces:
        x, w = gauss_legendre(int(math.ceil(3 * s.degree / 2)) + 1)
        a, b = s.knots[:-1, None], s.knots[1:, None]
        u = (((b - a) * x + (a + b)) / 2).ravel()
        wu = (((b - a) / 2) * w).ravel()
        (R, Z), (dR, dZ) = s.profile(u, shared=True).T, s.profile(u, 1, shared=True).T
        total += (math.tau / 3.0) * float(np.sum(wu * (Z * R * dR - R * R * dZ)))
    return total


@dataclass(frozen=True)
class ProfileFit:
    """Result of :func:`fit_profile`: the revolved surface and its measured deviation (mm).

    ``max_deviation`` is the largest ``|C(u) - P(u)|`` (same ``u``) on a grid
    ``check_factor`` times denser than the interpolation points, midpoints included;
    it is also the surface's deviation at equal ``(u, angle)``.
    """

    surface: RevolvedSurfaceData
    max_deviation: float
    tol: float
    n: int
    iterations: int
    seconds: float
    u_samples: np.ndarray = field(repr=False)

    @property
    def ok(self) -> bool:
        return self.max_deviation <= self.tol

    @property
    def poles(self) -> tuple[int, int]:
        return self.surface.shape


def _collocation(u: np.ndarray, degree: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Knots, multiplicities and the square collocation matrix of the clamped interpolant at ``u``."""
    knots, mults = clamped_interp_knots(u, degree)
    proto_t = flat_knots(knots, mults, degree, False)
    span, N = basis_derivatives(proto_t, degree, u.size, u, 0)
    B = np.zeros((u.size, u.size))
    rows = np.repeat(np.arange(u.size), degree + 1)
    np.add.at(B, (rows, (span[:, None] - degree + np.arange(degree + 1)).ravel()), N.ravel())
    return knots, mults, B


def _interpolate(D: np.ndarray, u: np.ndarray, degree: int) -> RevolvedSurfaceData:
    # the matrix depends on the samples alone: the profiles of a chain, sampled alike, share it
    key = ("revolved collocation", degree, u.tobytes())
    knots, mults, B = COLLOCATION.get(key, lambda: _collocation(u, degree))
    P = np.empty_like(D)
    P[0], P[-1] = D[0], D[-1]  # a clamped interpolant passes through its end data exactly
    if u.size > 2:
        P[1:-1] = np.linalg.solve(B[1:-1, 1:-1], D[1:-1] - np.outer(B[1:-1, 0], D[0]) - np.outer(B[1:-1, -1], D[-1]))
    return RevolvedSurfaceData(P, knots, mults, degree)


def fit_profile(
    f: ProfileFunction,
    tol: float = 1e-4,
    *,
    n: int = 17,
    degree: int = 3,
    max_n: int = 2000,
    max_iterations: int = 12,
    check_factor: int = 8,
    pole_tol: float = 1e-9,
    start: np.ndarray | None = None,
    name: str = "profile",
) -> ProfileFit:
    """Interpolate a profile ``f(u) -> (m, 2)`` (``(R, Z)``, mm, ``u`` in [0, 1]) within ``tol``.

    The profile is sampled at ``n`` equally spaced ``u`` and interpolated by a clamped
    B-spline of ``degree``; ``n`` grows with the ``h^(p+1)`` rate until the deviation on
    the check grid is ``<= tol``.  An end whose radius is within ``pole_tol`` of the axis
    is put exactly on it (the face's pole); ``start`` replaces the first sample (so that a
    chain of profiles shares its end points bit for bit).  Raises :class:`GeometryError`
    naming ``name`` when ``max_n``/``max_iterations`` do not reach ``tol``.
    """
    if tol <= 0 or not math.isfinite(tol):
        raise ValueError(f"tol = {tol} is not allowed: must be > 0")
    t0 = time.perf_counter()
    n = max(int(n), degree + 1)
    best = None
    for it in range(1, max_iterations + 1):
        u = np.linspace(0.0, 1.0, n)
        D = np.array(f(u), dtype=float).reshape(n, 2)
        if start is not None:
            D[0] = start
        for k in (0, -1):
            if abs(D[k, 0]) <= pole_tol:
                D[k, 0] = 0.0
        if not np.all(np.isfinite(D)):
            raise GeometryError(f"profile of {name} has non-finite values", f)
        surf = _interpolate(D, u, degree)
        uc = np.linspace(0.0, 1.0, check_factor * (n - 1) + 1)
        miss = surf.profile(uc, shared=True) - np.asarray(f(uc), dtype=float)
        dev = float(np.max(np.linalg.norm(miss, axis=-1)))
        best = ProfileFit(surf, dev, float(tol), n, it, time.perf_counter() - t0, u)
        if dev <= tol:
            return best
        ratio = dev / (0.4 * tol)
        new_n = min(int(math.ceil((n - 1) * min(max(ratio ** (1.0 / (degree + 1)), 1.25), 3.0))) + 1, max_n)
        if new_n == n:
            break
        n = new_n
    assert best is not None
    raise GeometryError(
        f"B-spline fit of {name} misses tolerance: max deviation {best.max_deviation:.3g} mm > tol {tol:.3g} mm "
        f"with {best.n} profile poles", best)


def fit_profiles(profiles, tol: float = 1e-4, *, names=None, degree: int = 5) -> list[ProfileFit]:
    """:func:`fit_profile` of a chain of profiles (profile ``j`` ends where ``j+1`` starts), each
    starting at the previous fit's last pole, so that neighbours share their end points bit
    for bit; ``names`` name them in errors."""
    names = list(names) if names is not None else [f"profile {j}" for j in range(len(profiles))]
    fits, start = [], None
    for f, n in zip(profiles, names):
        fit = fit_profile(f, tol, degree=degree, start=start, name=n)
        fits.append(fit)
        start = fit.surface.poles[-1]
    return fits


def _curvature_samples(s: RevolvedSurfaceData, samples: int = 513) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``u`` on ``samples`` points of one profile, the length of each interval between them and its
    curvature (the turn of the tangent over the length), for :func:`_profile_nodes`."""
    lo, hi = s.u_range
    u = np.linspace(lo, hi, samples)
    P, D = s.profile(u, shared=True), s.profile(u, 1, shared=True)
    dP = np.diff(P, axis=0)
    seg = np.sqrt(dP[:, 0] * dP[:, 0] + dP[:, 1] * dP[:, 1])  # (norm's sum of squares, without its reduction)
    phi = np.unwrap(np.arctan2(D[:, 1], D[:, 0]))
    kappa = np.abs(np.diff(phi)) / np.maximum(seg, 1e-300)  # curvature of each sample interval
    return u, seg, kappa


def _profile_nodes(s: RevolvedSurfaceData, curvature, deflection: float, angle: float, density: float) -> np.ndarray:
    """Parameters ``u`` of the mesh nodes on one profile: both ends plus nodes equidistributed in
    ``max(sqrt(κ / (8 δ)), κ / angle)`` per unit length (``δ`` = half the deflection; κ the
    curvature, ``curvature`` the profile's :func:`_curvature_samples`), times ``density``."""
    lo, hi = s.u_range
    u, seg, kappa = curvature
    rate = np.maximum(np.sqrt(kappa / (8.0 * 0.5 * deflection)), kappa / angle) * density
    count = np.concatenate([[0.0], np.cumsum(rate * seg)])
    n = max(1, int(math.ceil(count[-1])))
    if n == 1:
        return np.array([lo, hi])
    nodes = np.interp(np.linspace(0.0, count[-1], n + 1), count, u)
    nodes[0], nodes[-1] = lo, hi  # the ends exactly (count may stand still at either end)
    return nodes


def revolved_mesh(surfaces, deflection: float, angle: float, *, max_rounds: int = 4):
    """A closed, welded triangle mesh of a chain of revolved faces (numpy only).

    Profile nodes follow each face's curvature (:func:`_profile_nodes`); every node off the
    axis becomes a ring of ``m`` vertices, ``m`` set by the widest ring's sagitta
    (``R (1 - cos(π/m)) <= deflection / 2``) and by ``2π/m <= angle``; a node on the axis
    is one vertex (a pole, closed by a fan).  Triangles are wound outward.

    The deflection is then *measured*: every band of cells between two rings is congruent
    under rotation, so one cell per band is compared with the surface at the same
    parameters ``(u, θ)`` (a bound on the distance to the surface) on 15 points of each
    triangle (corners, edge midpoints, centroid and points between them); until it is
    ``<= deflection`` the node densities are doubled (at most ``max_rounds`` times, else
    :class:`GeometryError`).

    Returns
    -------
    V : ndarray (n, 3), T : ndarray (t, 3) int, measured : float (mm)
    """
    density, measured = 1.0, math.inf
    curvature = [_curvature_samples(s) for s in surfaces]  # the same in every round
    for _ in range(max_rounds + 1):
        P, bands = [], []
        for f, s in enumerate(surfaces):
            u = _profile_nodes(s, curvature[f], deflection, angle, density)
            pts = s.profile(u)
            start = len(P) - 1 if P else None  # the previous face's last node is this face's first
            if start is None:
                P.append(pts[0])
                start = 0
            idx = [start] + list(range(len(P), len(P) + len(u) - 1))
            P.extend(pts[1:])
            bands.extend((f, u[t], u[t + 1], idx[t], idx[t + 1]) for t in range(len(u) - 1))
        P = np.array(P)
        if P[0, 0] > 0.0 and np.max(np.abs(P[-1] - P[0])) <= 1e-6 * (1.0 + np.max(np.abs(P))):
            last = len(P) - 1  # a ring: the chain returns to its start
            P = P[:-1]
            bands = [(f, ua, ub, ia, 0 if ib == last else ib) for f, ua, ub, ia, ib in bands]
        rmax = float(np.max(P[:, 0]))
        half = 0.5 * deflection
        m = max(8, int(math.ceil(math.tau / angle)),
                int(math.ceil(math.pi / math.acos(1.0 - half / rmax))) if rmax > half else 8)
        m = 4 * int(math.ceil(m * math.sqrt(density) / 4))
        V, T, measured = _mesh_rings(surfaces, P, bands, m)
        if measured <= deflection:
            return V, T, measured
        density *= 2.0
    raise GeometryError(f"revolved mesh misses the deflection {deflection:g} mm: measured {measured:.3g} mm")


def _mesh_rings(surfaces, P: np.ndarray, bands, m: int):
    th = np.arange(m) * (math.tau / m)
    pole = P[:, 0] <= 0.0
    first = np.zeros(len(P) + 1, dtype=np.int64)  # index of each node's first vertex
    first[1:] = np.cumsum(np.where(pole, 1, m))
    V = _ring_vertices(P, pole, first, th)
    T = _ring_triangles(bands, pole, first, m)
    a, b, c = (np.take(V, T[:, k], axis=0) for k in range(3))  # (take: the same rows as V[T[:, k]], 3x faster)
    if float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum()) < 0.0:  # wind outward (positive volume)
        T = T[:, ::-1]
    return V, np.ascontiguousarray(T), _mesh_deviation(surfaces, P, bands, th[1])


def _ring_vertices(P: np.ndarray, pole: np.ndarray, first: np.ndarray, th: np.ndarray) -> np.ndarray:
    """Vertices (mm): node ``k`` off the axis is the ring ``(R cos θ, R sin θ, Z)`` over ``th`` from
    ``first[k]`` on, a node on the axis the one vertex ``(0, 0, Z)`` at ``first[k]`` (all rings in
    one product each: a ring, and a band of triangles, at a time took 0.59 ms of the compound cup's
    mesh, 0.15 now)."""
    V = np.zeros((int(first[-1]), 3))
    V[first[:-1][pole], 2] = P[pole, 1]
    at = first[:-1][~pole, None] + np.arange(th.size)  # each ring's vertices
    V[at, 0] = np.outer(P[~pole, 0], np.cos(th))
    V[at, 1] = np.outer(P[~pole, 0], np.sin(th))
    V[at, 2] = P[~pole, 1, None]
    return V


def _ring_triangles(bands, pole: np.ndarray, first: np.ndarray, m: int) -> np.ndarray:
    """Triangles of the bands between consecutive rings, band by band: two per cell between two
    rings ``a`` and ``b`` (``(a_j, a_j+1, b_j)`` for every ``j``, then ``(a_j+1, b_j+1, b_j)``), one per
    cell of a fan to a pole, none between two poles."""
    ia = np.array([band[3] for band in bands], dtype=np.int64)
    ib = np.array([band[4] for band in bands], dtype=np.int64)
    pa, pb = pole[ia, None], pole[ib, None]
    a, b = first[ia, None], first[ib, None]
    j, j1 = np.arange(m), (np.arange(m) + 1) % m
    # the first m triangles of a band: a ring pair's first kind, or a fan's (a pole's vertex in place of a ring's)
    head = np.stack([np.where(pa, a, a + j), np.where(pa, b + j1, a + j1), np.where(pb, b, b + j)], axis=-1)
    tail = np.stack([a + j1, b + j1, b + j], axis=-1)  # a ring pair's second kind
    keep = np.stack([~(pa & pb)[:, 0], ~(pa | pb)[:, 0]], axis=1)  # (bands, head / tail)
    both = np.stack([head, tail], axis=1)  # (bands, 2, m, 3): band by band, head before tail
    return both[keep].reshape(-1, 3)


def _profiles_at(surfaces, fs: np.ndarray, u: np.ndarray) -> np.ndarray:
    """``(R, Z)`` of ``surfaces[fs[b]]`` at ``u[b]`` for every row ``b`` of ``u``: shape ``u.shape + (2,)``.
    The faces with the same knots (a chain fitted with as many poles) share one evaluation of their
    B-splines, each row then taking its own face's poles: the same values as a face at a time, in one
    basis evaluation instead of one per face (0.9 of 1.1 ms on the compound cup's 7 faces)."""
    C = np.empty(u.shape + (2,))
    groups: dict = {}
    for f in np.unique(fs):
        s = surfaces[f]
        groups.setdefault((s.degree, s.poles.shape[0], s.knots.tobytes(), s.mults.tobytes()), []).append(f)
    for faces in groups.values():
        rows = np.isin(fs, faces)
        idx, N = surfaces[faces[0]]._basis(u[rows], 0)
        poles = np.concatenate([surfaces[f].poles for f in faces])  # the group's poles, face after face
        which = np.searchsorted(faces, fs[rows])  # each row's face in the group (faces are sorted)
        at = which[:, None, None] * surfaces[faces[0]].poles.shape[0] + idx  # its own face's poles
        C[rows] = np.einsum("...i,...ik->...k", N, np.take(poles, at, axis=0))
    return C


# barycentric sample points of a triangle: corners, edge midpoints, centroid, and between them
_BARY = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [.5, .5, 0], [0, .5, .5], [.5, 0, .5], [1 / 3, 1 / 3, 1 / 3],
                  [.75, .25, 0], [.25, .75, 0], [0, .75, .25], [0, .25, .75], [.25, 0, .75], [.75, 0, .25],
                  [2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6]], dtype=float)


def _mesh_deviation(surfaces, P: np.ndarray, bands, dth: float, n_seg: int = 64) -> float:
    """Largest distance (mm) from the triangles to the surface, measured on one cell per band
    (the cells of a band are congruent under rotation): 15 points of each of its two
    triangles, each point's distance to the band's stretch of profile in its own meridian
    plane, the profile taken as ``n_seg`` chords (whose own sagitta, ~``δ/n_seg²``, is
    negligible)."""
    fs = np.array([b[0] for b in bands])
    ua = np.array([b[1] for b in bands])
    ub = np.array([b[2] for b in bands])
    A, B = P[[b[3] for b in bands]], P[[b[4] for b in bands]]
    c, s = math.cos(dth), math.sin(dth)

    def corner(p, rot):
        return np.column_stack([p[:, 0] * (c if rot else 1.0), p[:, 0] * (s if rot else 0.0), p[:, 1]])

    A0, A1, B0, B1 = corner(A, False), corner(A, True), corner(B, False), corner(B, True)
    q = np.concatenate([np.einsum("pk,bkc->bpc", _BARY, np.stack([A0, A1, B0], axis=1)),
                        np.einsum("pk,bkc->bpc", _BARY, np.stack([A1, B1, B0], axis=1))], axis=1)
    qr, qz = np.hypot(q[..., 0], q[..., 1]), np.ascontiguousarray(q[..., 2])  # (R, Z) of each (bands, 30)
    t = np.linspace(0.0, 1.0, n_seg + 1)
    C = _profiles_at(surfaces, fs, ua[:, None] + (ub - ua)[:, None] * t)  # (bands, n_seg + 1, 2)
    # R and Z apart, each a contiguous (bands, 30 points, n_seg chords) table: the same sums of two
    # products as a sum over a trailing axis of 2, without numpy's slow reductions over it (this check had
    # taken 6.1 of the compound cup's 7.4 ms mesh; ~2.8 now); the root of the least square is the least
    # root (the root is correctly rounded)
    Cr, Cz = np.ascontiguousarray(C[..., 0]), np.ascontiguousarray(C[..., 1])
    dr, dz = np.diff(Cr, axis=1)[:, None], np.diff(Cz, axis=1)[:, None]  # chord steps (bands, 1, n_seg)
    wr = qr[:, :, None] - Cr[:, None, :-1]
    wz = qz[:, :, None] - Cz[:, None, :-1]
    lam = wr * dr
    lam += wz * dz
    lam /= np.maximum(dr * dr + dz * dz, 1e-300)
    np.clip(lam, 0.0, 1.0, out=lam)
    wr -= lam * dr
    wz -= lam * dz
    wr *= wr
    wz *= wz
    wr += wz
    return float(np.sqrt(wr.min(axis=2)).max())
