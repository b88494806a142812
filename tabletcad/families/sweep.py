"""Swept tablets: exact nominal (profile swept along outline offsets) and certified PDE patches.

Nominal
-------
A tablet of this package is fixed by a plan outline ``O(v)`` (closed, CCW,
lines and arcs; a circle for round tablets), a band (wall) height ``b`` and a
top-face profile ``z(d)``: a chain of lines and arcs in the ``(d, z)`` plane
from the band edge ``d = 0`` inward (:mod:`tabletcad.families.profile`).  The
face is the sweep ``S(d, v) = O(v) + d N(v) + z e_z`` (``N`` the unit inward
normal): at every height the outline offset inward by ``d`` — lines offset to
lines, arcs to concentric arcs.  The bottom face is the mirror image; the
tablet stands on ``z = 0``.  When the profile ends before the offsets close
(shaped outlines), the face is finished by a flat plateau.

Because the sweep's normal lies in the plane spanned by ``N(v)`` and ``e_z``,
the exact distance from a point ``p`` to the nominal surface is the planar
distance from ``(δ(p), z)`` to the profile chain, with ``δ`` the exact signed
distance from ``p``'s plan position to the outline — valid while ``δ`` stays
below the outline's reach (which the offset checks guarantee on the surface).
For a round tablet this is the exact distance to spheres, cones and tori.

PDE representation
------------------
Each profile element is split into pieces (:func:`profile.pieces_for`) whose
cubic Hermite interpolant is within ``refine × tol.nominal`` of it; each piece
becomes a :class:`~tabletcad.geometry.patch.PDEPatch` in Hermite form with data
``X(0) = S(d0, v)``, ``X(1) = S(d1, v)``, ``X_u = D_d N(v) + D_z e_z`` (the
piece's end derivatives).  Consecutive patches share their curves (C0) and
their tangent directions wherever the profile is smooth (G1 by construction).
With a small smoothing parameter ``a`` the cardinal functions are nearly the
cubic Hermite ones for every Fourier mode, so the patch follows the nominal
to well below a micrometre; :func:`certify` measures it.
"""

from __future__ import annotations

import contextlib
import contextvars
import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from tabletcad.geometry.curves import Curve
from tabletcad.errors import DesignError, GeometryError
from tabletcad.families.outline import PlanOutline
from tabletcad.families.profile import Piece, profile_line, distance_to_chain, joint_is_smooth, pieces_for
from tabletcad.geometry.patch import PDEPatch
from tabletcad.geometry.tablet import Tablet
from tabletcad.tolerance import DEFAULT, Tolerances
from tabletcad.geometry.vectors import cross_first, linspace
from tabletcad.geometry.quadrature import gauss_legendre

__all__ = [
    "SweepCurve",
    "SweepNominal",
    "NominalBuilt",
    "nominal_only",
    "Certificate",
    "build_sweep_tablet",
    "certify",
    "sweep_properties",
    "nominal_volume",
    "DEFAULT_A",
    "REFINE",
]


class NominalBuilt(Exception):
    """Raised by :func:`build_sweep_tablet` inside :func:`nominal_only` once the exact nominal is
    made; ``nominal`` is that :class:`SweepNominal`."""

    def __init__(self, nominal: "SweepNominal") -> None:
        super().__init__("nominal built")
        self.nominal = nominal


_STOP_AT_NOMINAL: contextvars.ContextVar[bool] = contextvars.ContextVar("tabletcad_stop_at_nominal", default=False)


@contextlib.contextmanager
def nominal_only() -> Iterator[None]:
    """Inside the block, a family build stops with :class:`NominalBuilt` as soon as its exact
    nominal exists: every dimension check has run, no PDE patch is made (about 100 times
    cheaper).  For searches over a family's dimensions (:mod:`tabletcad.families.inverse`).
    Keyed on a context variable: other threads and contexts build as usual."""
    token = _STOP_AT_NOMINAL.set(True)
    try:
        yield
    finally:
        _STOP_AT_NOMINAL.reset(token)


#: Smoothing parameter of the family patches (small: nearly cubic Hermite in u for every mode).
DEFAULT_A = 0.01
#: Pieces are split until their planar Hermite error is below ``REFINE × tol.nominal``
#: (so areas and volumes agree with the nominal to ~1e-6 relative, not only the 1 µm certificate).
REFINE = 0.01


@dataclass(frozen=True, eq=False)
class SweepCurve(Curve):
    """``alpha O(v) + beta N(v) + const`` lifted to 3-D (mm): an outline offset at a
    height (``alpha = 1``) or a sweep derivative (``alpha = 0``).

    Parameters
    ----------
    outline : PlanOutline
    alpha, beta : float
        Weights of the outline point and of its unit inward normal.
    const : tuple of 3 floats
        Added to the value (not to derivatives), mm.
    """

    outline: Any
    alpha: float
    beta: float
    const: tuple = (0.0, 0.0, 0.0)

    def evaluate(self, v, der: int = 0) -> np.ndarray:
        v = np.asarray(v, dtype=float).reshape(-1)
        out = np.zeros((v.size, 3))
        if self.alpha or self.beta:
            out[:, :2] = self.outline.offset(v, der, self.alpha, self.beta)
        if der == 0:
            out += np.asarray(self.const, dtype=float)
        elif der not in (1, 2):
            raise ValueError(f"der = {der} is not allowed: must be 0, 1 or 2")
        return out

    @classmethod
    def evaluate_several(cls, curves, v, der: int = 0) -> np.ndarray | None:
        """Several offsets of one outline in one call (:meth:`~tabletcad.families.outline.PlanOutline.offsets`:
        one frame, the same arithmetic as each curve's :meth:`evaluate`); None for different outlines."""
        ol = curves[0].outline
        if any(c.outline is not ol for c in curves):
            return None
        v = np.asarray(v, dtype=float).reshape(-1)
        if der not in (0, 1, 2):
            raise ValueError(f"der = {der} is not allowed: must be 0, 1 or 2")
        out = np.zeros((len(curves), v.size, 3))
        a = np.array([c.alpha for c in curves])
        b = np.array([c.beta for c in curves])
        live = (a != 0.0) | (b != 0.0)  # (a point's offset is its constant alone, as in evaluate)
        if np.any(live):
            out[live, :, :2] = ol.offsets(v, der, a[live], b[live])
        if der == 0:
            out += np.array([c.const for c in curves], dtype=float)[:, None, :]
        return out

    @classmethod
    def combination(cls, curves) -> tuple | None:
        """``(basis, weights, const)`` (:func:`~tabletcad.geometry.curves.combination_of`): each curve is
        ``alpha O + beta N + const`` of one outline's :class:`OutlineBasis` ``(O, N)``; None for
        different outlines."""
        ol = curves[0].outline
        if any(c.outline is not ol for c in curves):
            return None
        basis = ol.__dict__.get("_sweep_basis")
        if basis is None:
            basis = OutlineBasis(ol)
            ol.__dict__["_sweep_basis"] = basis
        weights = np.array([[c.alpha, c.beta] for c in curves], dtype=float)
        return basis, weights, np.array([c.const for c in curves], dtype=float)

    @property
    def is_point(self) -> bool:
        return self.alpha == 0.0 and self.beta == 0.0

    @property
    def flat(self) -> bool:
        """Always: an outline's offset moves in plan only, at the constant's height (its z derivatives are 0)."""
        return True

    def band_limit(self) -> int | None:
        """1 on a circular outline (an offset circle, or a constant), else None."""
        return 1 if getattr(self.outline, "is_circle", False) else None

    def breakpoints(self) -> np.ndarray:
        """``v`` of the outline's segment joins (where the offset is only piecewise smooth)."""
        if self.is_point:
            return np.zeros(0)
        return np.asarray(getattr(self.outline, "smooth_breaks", self.outline.breaks[:-1]), dtype=float)


@dataclass(frozen=True, eq=False)
class OutlineBasis:
    """An outline ``O(v)`` and its unit inward normal ``N(v)`` lifted to ``z = 0``: the two curves every
    :class:`SweepCurve` on the outline combines (one per outline, :meth:`SweepCurve.combination`)."""

    outline: Any

    def evaluate(self, v, der: int = 0) -> np.ndarray:
        """``(2, len(v), 3)``: ``d^der O / dv^der`` and ``d^der N / dv^der`` (mm), from one frame."""
        v = np.asarray(v, dtype=float).reshape(-1)
        out = np.zeros((2, v.size, 3))
        out[:, :, :2] = self.outline.offsets(v, der, _UNIT_A, _UNIT_B)
        return out


_UNIT_A, _UNIT_B = np.array([1.0, 0.0]), np.array([0.0, 1.0])


@dataclass(frozen=True)
class Certificate:
    """Measured deviation of the PDE surface from the nominal.

    Attributes
    ----------
    max_deviation_mm : float
        Largest exact distance (mm) from the sampled PDE surface to the nominal.
    per_patch_mm : tuple of float
        The same per patch.
    tolerance_mm : float
        The tolerance it was certified against (``tol.nominal``).
    samples : tuple of int
        ``(nu, nv)``: the grid sampled on every patch, the outline's joins included in ``v``
        (then polished around its peaks, :func:`certify`).
    passed : bool
    """

    max_deviation_mm: float
    per_patch_mm: tuple
    tolerance_mm: float
    samples: tuple
    passed: bool


class SweepNominal:
    """Exact nominal of a swept tablet; calling it gives the signed distance (mm, < 0 inside).

    Attributes
    ----------
    outline : PlanOutline
    chain : list of elements (absolute ``(d, z)``, bottom centre → band → top centre)
    top, bottom : lists of elements of each face (from the band inward)
    band_z : (float, float)
        Heights (mm) of the band's bottom and top edges.
    thickness : float
        Overall thickness (mm).
    expected_sharp : list of bool
        Per seam of the PDE chain: whether the nominal has an edge there.
    certificate : Certificate or None
    patch_ids : tuple
        ``id`` of the patches the certificate was measured on.
    info : dict
        Family facts for the design report (cup depth, land, ...).
    """

    def __init__(self, outline: PlanOutline, top: list, bottom: list, band_z: tuple[float, float],
                 thickness: float, d_far: float, info: dict | None = None) -> None:
        self.outline = outline
        self.top = list(top)
        self.bottom = list(bottom)
        self.band_z = band_z
        self.thickness = thickness
        self.chain = list(bottom) + ([profile_line((0.0, band_z[0]), (0.0, band_z[1]), "band")] if band_z[1] > band_z[0] else []) + list(top)
        self.info = dict(info or {})
        self.expected_sharp: list[bool] = []
        self.certificate: Certificate | None = None
        self.patch_ids: tuple = ()
        self.top_patch_range: tuple[int, int] = (0, 0)
        #: the plane ``z`` (mm) in which the builder made the lower face's patches as mirror images
        #: of the upper face's (:meth:`~tabletcad.geometry.tablet.Tablet.mirror`), or None
        self.mirror_z: float | None = None
        #: the patches that statement is about (held, so that their identity is checked, not their ids)
        self.mirror_patches: tuple = ()
        # face heights as functions of d (the faces are graphs over d)
        self._dz_top = _graph(self.top, d_far)
        self._dz_bot = _graph(self.bottom[::-1], d_far, reverse=True)

    #: ``nu`` of the distance to this nominal (:meth:`~tabletcad.geometry.tablet.Tablet.nominal_nu`)
    deviation_nu = 65

    def v_samples(self, nv: int) -> np.ndarray:
        """``nv`` equally spaced ``v`` (rad) over a whole turn and each side of every join of the outline
        (where the offset is only piecewise smooth): the ``v`` samples of a distance to this nominal
        (:meth:`~tabletcad.geometry.tablet.Tablet.nominal_deviation`, :func:`certify`)."""
        return _v_samples(self.outline, nv)

    @property
    def axisymmetric(self) -> bool:
        """True when the nominal is a solid of revolution about the z axis: its outline is one
        full circle about the origin (then its distance to a point depends only on the
        point's radius and height)."""
        o = self.outline
        return bool(getattr(o, "is_circle", False)) and max(map(abs, o.segs[0].center)) <= 1e-12 * o.segs[0].radius

    @property
    def convex(self) -> bool | None:
        """Whether the nominal solid is convex, or None when its outline is not lines and arcs.

        Convex when the outline turns one way only (a G1 chain with no concave arc) and the faces,
        as heights over the inward distance ``d`` from the outline, rise and bend down on top and
        fall and bend up at the bottom: then ``{z_bottom(d) <= z <= z_top(d)}`` is convex, ``d``
        being concave inside a convex outline.  A cup rising from a land is not (a kink upward).
        """
        segs = getattr(self.outline, "segs", None)
        if segs is None:
            return None
        if any(s.kind == "arc" and s.sweep < 0.0 for s in segs):
            return False
        (dt, zt), (db, zb) = self._dz_top, self._dz_bot
        return _rising_concave(dt, zt) and _rising_concave(db, -zb)

    def planar(self, points: np.ndarray) -> np.ndarray:
        """``(δ, z)`` of 3-D points: signed inward plan distance to the outline and height."""
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        return np.column_stack([self.outline.signed_distance(p[:, :2]), p[:, 2]])

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Unsigned exact distance (mm) from 3-D points to the nominal surface."""
        return distance_to_chain(self.chain, self.planar(points))

    def __call__(self, points: np.ndarray) -> np.ndarray:
        q = self.planar(points)
        dist = distance_to_chain(self.chain, q)
        d, z = q[:, 0], q[:, 1]
        zt = np.interp(np.maximum(d, 0.0), *self._dz_top)
        zb = np.interp(np.maximum(d, 0.0), *self._dz_bot)
        inside = (d > 0.0) & (z > zb) & (z < zt)
        return np.where(inside, -dist, dist)


def _rising_concave(d: np.ndarray, z: np.ndarray) -> bool:
    """Whether the graph ``z(d)`` (``d`` increasing, dense samples) never falls and bends down only."""
    dd = np.diff(d)
    keep = dd > 1e-12 * max(1.0, float(np.max(np.abs(d))))
    slope = np.diff(z)[keep] / dd[keep]
    tol = 1e-7 * max(1.0, float(np.max(np.abs(slope))))
    return bool(np.all(slope >= -tol) and np.all(np.diff(slope) <= tol))


def _graph(elements, d_far: float, reverse: bool = False):
    """Dense (d, z) samples of a face for ``np.interp`` (d increasing)."""
    pts = []
    for e in elements:
        n = 2 if e.kind == "line" else 2049
        pts.append(e.point(linspace(0.0, 1.0, n)))
    p = np.vstack(pts)
    o = np.argsort(p[:, 0], kind="stable")
    d, z = p[o, 0], p[o, 1]
    if d[-1] < d_far:
        d = np.append(d, d_far)
        z = np.append(z, z[-1])
    return d, z


def _elements_smooth(prev, nxt) -> bool:
    return joint_is_smooth(prev, nxt, tol_deg=1e-7)


def _place(elements: Sequence, dz: float) -> list:
    return [e.translated(0.0, dz) for e in elements]


def build_sweep_tablet(
    outline: PlanOutline,
    face: Sequence,
    band: float,
    *,
    name: str,
    family: str,
    params: dict,
    reach: float,
    info: dict | None = None,
    a: float = DEFAULT_A,
    tol: Tolerances = DEFAULT,
    refine: float = REFINE,
    certify_surface: bool = True,
) -> Tablet:
    """Tablet from an outline, a top-face profile and a band height.

    Parameters
    ----------
    outline : PlanOutline
        Plan outline (mm).
    face : sequence of tabletcad.geometry.curves.Seg
        Top-face profile in ``(d, z)`` with ``z`` measured from the band's top
        edge (``z = 0`` at ``d = 0``), running inward and ending either at the
        outline's ``reach`` (the offsets close: a point for a circle, a segment
        for a stadium) or horizontally before it (a flat plateau closes the face).
    band : float
        Band (wall) height (mm, >= 0).
    reach : float
        Largest inward offset of the outline (mm): its inscribed radius.
    a : float
        Smoothing parameter of the patches.
    refine : float
        Pieces are split until their planar error is ``<= refine * tol.nominal``.
    certify_surface : bool
        Measure the deviation (:func:`certify`) and raise :class:`~tabletcad.errors.DesignError`
        if it exceeds ``tol.nominal`` (naming ``a`` where one is given, else the family).
    """
    face = list(face)
    if not face:
        raise DesignError("face profile", "empty", "a face needs at least one line or arc")
    d_end, z_end_rel = (float(x) for x in face[-1].point(1.0))
    h_face = max(float(np.max(e.point(linspace(0, 1, 65))[:, 1])) for e in face)
    T = band + 2.0 * h_face
    top = _place(face, h_face + band)
    zm = 0.5 * T
    bottom = [e.mirrored(zm) for e in reversed(top)]
    closes = d_end >= reach * (1.0 - 1e-12)
    if not closes:
        end_dir = face[-1].derivative(np.array(1.0))
        if abs(float(end_dir[1])) > 1e-9 * float(np.linalg.norm(end_dir)):
            raise DesignError("face profile", f"ends at d = {d_end:.4g} mm with a slope",
                              f"must end horizontally (a flat plateau) or reach the centre (d = {reach:.6g} mm)")
    d_far = max(reach, d_end) + 1.0
    nominal_top = list(top)
    nominal_bottom = list(bottom)
    if not closes:
        z_top_end = float(top[-1].point(1.0)[1])
        nominal_top.append(profile_line((d_end, z_top_end), (d_far, z_top_end), "plateau"))
        nominal_bottom.insert(0, profile_line((d_far, T - z_top_end), (d_end, T - z_top_end), "plateau"))
    nom = SweepNominal(outline, nominal_top, nominal_bottom, (h_face, h_face + band), T, d_far, info)
    if _STOP_AT_NOMINAL.get():
        raise NominalBuilt(nom)

    target = refine * tol.nominal
    # pieces along the chain: bottom (centre -> edge), band, top (edge -> centre)
    chain_pieces: list[Piece] = []
    joints_sharp: list[bool] = []
    elems: list = list(bottom) + ([profile_line((0.0, h_face), (0.0, h_face + band), "band")] if band > 0 else []) + list(top)
    for k, e in enumerate(elems):
        ps = pieces_for(e, target)
        if chain_pieces:
            joints_sharp.append(not _elements_smooth(elems[k - 1], e))
        chain_pieces.extend(ps)
        joints_sharp.extend([False] * (len(ps) - 1))
    n_bottom = sum(len(pieces_for(e, target)) for e in bottom)

    c = outline.centroid()
    patches: list[PDEPatch] = []
    expected: list[bool] = []
    # the plateau: one fan from the centre to the rim, or - when corners of the rim have
    # collapsed to points - a fan to an inner curve Q plus a ring from Q to the rim (see _plateau_ring)
    ring = _plateau_ring(outline, d_end, c) if not closes else None
    # the lower face's patches and the upper face's are mirror images in z = zm, in reverse order
    n_total = 2 * (0 if closes else (1 if ring is None else 2)) + len(chain_pieces)

    def mk(data, label):
        # The patch's own stray check measures Fourier content the truncated series leaves to
        # the remainder term; for offsets with collapsed corner arcs (G0 in v) that content is
        # large although harmless (with a small a the remainder only interpolates).  The
        # certificate below bounds the real deviation from the nominal instead; the fold depth
        # of the solid map (a surface crossing its spine) is still checked.
        patch = PDEPatch(tuple(data), a=a, form="hermite", tol=tol, name=f"{name}[{len(patches)}:{label}]", check=False)
        # the patches are cubic-like in u: a coarser u grid than the core default suffices; a
        # patch of revolution is measured on a few meridians at the default (the report's) u grid
        # (tol.fold alone, not a fraction of the patch's size: a family's patches do not fold at all, and
        # one that does has offsets that are not star-shaped)
        twin = n_total - 1 - len(patches)
        if twin < len(patches) and patch.mirrors(patches[twin], zm):  # the reflection folds alike
            depth = patches[twin].checked_fold_depth
        else:
            depth = patch.fold_depth(nu=65 if patch.revolution is None else 257, nv=128)
        object.__setattr__(patch, "_fold_depth", depth)  # the figure checked (the report's)
        if depth > tol.fold:
            raise DesignError(f"patch {patch.name} curves", f"a fold {depth:.3g} mm deep",
                              f"the surface must not cross its spine by more than {tol.fold:g} mm "
                              "(the outline's offsets are not star-shaped about its centroid)")
        return patch

    prev_curve = None
    if not closes:
        zb = T - float(top[-1].point(1.0)[1])
        pole = SweepCurve(outline, 0.0, 0.0, (float(c[0]), float(c[1]), zb))
        rim = SweepCurve(outline, 1.0, d_end, (0.0, 0.0, zb))
        if ring is None:
            du = SweepCurve(outline, 1.0, d_end, (-float(c[0]), -float(c[1]), 0.0))
            patches.append(mk((pole, rim, du, du), "plateau"))
        else:
            lam, beta_q = ring
            q = SweepCurve(outline, lam, beta_q, ((1 - lam) * float(c[0]), (1 - lam) * float(c[1]), zb))
            du_in = SweepCurve(outline, lam, beta_q, (-lam * float(c[0]), -lam * float(c[1]), 0.0))
            du_out = SweepCurve(outline, 1.0 - lam, d_end - beta_q, (-(1 - lam) * float(c[0]), -(1 - lam) * float(c[1]), 0.0))
            patches.append(mk((pole, q, du_in, du_in), "plateau"))
            expected.append(False)  # plane to plane
            patches.append(mk((q, rim, du_out, du_out), "plateau ring"))
        expected.append(False)  # plateau -> face: tangent (the face ends horizontally)
        prev_curve = rim
    for i, p in enumerate(chain_pieces):
        P0, P1, D0, D1 = p.hermite()
        X0 = prev_curve if prev_curve is not None else SweepCurve(outline, 1.0, float(P0[0]), (0.0, 0.0, float(P0[1])))
        X1 = SweepCurve(outline, 1.0, float(P1[0]), (0.0, 0.0, float(P1[1])))
        U0 = SweepCurve(outline, 0.0, float(D0[0]), (0.0, 0.0, float(D0[1])))
        U1 = SweepCurve(outline, 0.0, float(D1[0]), (0.0, 0.0, float(D1[1])))
        patches.append(mk((X0, X1, U0, U1), p.element.label))
        if i < len(chain_pieces) - 1:
            expected.append(joints_sharp[i])
        prev_curve = X1
    n_plateau = 0 if closes else (1 if ring is None else 2)
    top_start = n_plateau + n_bottom + (1 if band > 0 else 0)
    if not closes:
        zt = float(top[-1].point(1.0)[1])
        pole = SweepCurve(outline, 0.0, 0.0, (float(c[0]), float(c[1]), zt))
        expected.append(False)
        if ring is None:
            du = SweepCurve(outline, -1.0, -d_end, (float(c[0]), float(c[1]), 0.0))
            patches.append(mk((prev_curve, pole, du, du), "plateau"))
        else:
            lam, beta_q = ring
            q = SweepCurve(outline, lam, beta_q, ((1 - lam) * float(c[0]), (1 - lam) * float(c[1]), zt))
            du_in = SweepCurve(outline, -lam, -beta_q, (lam * float(c[0]), lam * float(c[1]), 0.0))
            du_out = SweepCurve(outline, -(1.0 - lam), -(d_end - beta_q), ((1 - lam) * float(c[0]), (1 - lam) * float(c[1]), 0.0))
            patches.append(mk((prev_curve, q, du_out, du_out), "plateau ring"))
            expected.append(False)
            patches.append(mk((q, pole, du_in, du_in), "plateau"))
    nom.expected_sharp = expected
    nom.mirror_z = zm  # the bottom's elements are the top's mirrored in z = zm, and so are their patches
    nom.mirror_patches = tuple(patches)  # (these patches: another tablet with this nominal is not vouched for)
    nom.top_patch_range = (top_start, len(patches))
    tablet = Tablet(tuple(patches), name=name, family=family, params=dict(params), nominal=nom,
                    nominal_name=f"{family} (profile swept along outline offsets)", tol=tol)
    if certify_surface:
        cert = certify(tablet)
        if not cert.passed and a != DEFAULT_A:  # a smoothing parameter the design chose: name it
            raise DesignError("a", a, f"must leave the PDE surface within {tol.nominal * 1e3:.3g} µm of the {family}'s "
                                      f"nominal (it deviates {cert.max_deviation_mm * 1e3:.3g} µm; leave a out for "
                                      f"the family's {DEFAULT_A:g})")
        if not cert.passed:  # dimensions the family's PDE cannot follow (a 999 mm rounded square with 1.8 mm
            # corners: 1.09 µm): refused as input, by the family the dimensions are given for
            raise DesignError("tablet", family, f"must leave the PDE surface within {tol.nominal * 1e3:.3g} µm of "
                                                f"the {family}'s nominal (Tolerances.nominal; these dimensions leave "
                                                f"it {cert.max_deviation_mm * 1e3:.3g} µm from it)")
    return tablet


def _rim_collapses(outline, d: float) -> bool:
    """Whether the offset of ``outline`` by ``d`` stands still over some ``v`` (convex arcs of
    radius ``d`` collapsed to points: the corners of a rounded polygon at ``cup_width = corner_radius``)."""
    segs = getattr(outline, "segs", ())
    if segs:
        return any(sg.kind == "arc" and sg.sweep > 0 and sg.radius <= d * (1 + 1e-9) for sg in segs)
    v = linspace(0.0, math.tau, 4096, endpoint=False)
    speed = np.linalg.norm(outline.point(v, 1) + d * outline.normal(v, 1), axis=1)
    return bool(np.min(speed) <= 1e-9 * outline.speed)


def _plateau_ring(outline, d_end: float, c: np.ndarray):
    """``(λ, β)`` of the inner curve ``Q = c + λ (O + β/λ N - c)`` that splits a plateau whose rim
    has collapsed corners, or None when the rim is a regular curve (one fan patch suffices).

    A fan from the centre to a rim that stands still over a corner's ``v`` interval maps that
    whole strip of ``(u, v)`` onto one line: a zero-area sliver inside the face that meshers
    fold into a pocket (non-manifold STL).  Instead the fan ends on ``Q``, the offset by
    ``d_end/2`` (whose corners are still arcs) shrunk towards the centre by ``λ``, and a ruled
    ring joins ``Q`` to the rim: over a corner it is a thin triangle from ``Q``'s small arc to
    the corner point, with positive area.  Both patches are planar, so they lie on the nominal.
    ``λ`` shrinks from 0.5 by factors of 0.7 until ``Q`` lies inside the rim: a narrow rim (a
    rounded triangle at nearly its largest corner radius) takes a small one (it had stopped at 0.1,
    refusing the default cup width from a corner radius of 3 mm on an 11 mm triangle).
    """
    if not _rim_collapses(outline, d_end):
        return None
    d_q = 0.5 * d_end
    v = linspace(0.0, math.tau, 2048, endpoint=False)
    O = outline.point(v)
    N = outline.normal(v)
    lam = 0.5
    while lam > 1e-9:  # (the cup widths allowed leave the rim >= Tolerances.min_length from c: lam >~ 1e-6)
        q = c + lam * (O + d_q * N - c)
        least = d_end + 0.1 * lam * d_q
        # every 16th point first: the distances are pointwise, so one of them at or below the least refuses
        # this lam as the whole curve's would (most lams tried are refused: the 2048 points measured once)
        if (float(np.min(outline.signed_distance(q[::16]))) > least
                and float(np.min(outline.signed_distance(q))) > least):
            return lam, lam * d_q
        lam *= 0.7
    raise GeometryError(f"{outline.name}: no inner curve of the plateau fits inside its rim at the cup width "
                        f"{d_end:.6g} mm (the centroid is not inside the rim)", outline)


def _v_samples(outline, nv: int) -> np.ndarray:
    v = linspace(0.0, math.tau, nv, endpoint=False)
    b = np.asarray(outline.breaks)[:-1]
    eps = 1e-9
    return np.unique(np.concatenate([v, b, np.mod(b - eps, math.tau), b + eps]))


def _axisymmetric_nv(tablet: Tablet, nv: int) -> int:
    """``v`` samples for a distance to the nominal: 4 when the surface and the nominal are both
    of revolution about the z axis (the distance is then the same on every meridian), else ``nv``."""
    return 4 if tablet.revolution is not None and getattr(tablet.nominal, "axisymmetric", False) else nv


def certify(tablet: Tablet, nu: int | None = None, nv: int = 256) -> Certificate:
    """Measure the largest distance from the PDE surface to the exact nominal.

    The distances are :meth:`~tabletcad.geometry.tablet.Tablet.nominal_peaks`' (the geometry
    report's nominal deviation is the same measurement, computed once): every patch sampled on
    ``(nu - 1) / 2 + 1`` equally spaced ``u`` values (ends included) times ``nv / 2`` values of
    ``v`` and each side of the outline's joins, and polished around the largest local maxima of
    those samples (:meth:`~tabletcad.geometry.tablet.Tablet.deviation_peaks`: each peak resolved
    32 times finer than ``nu × nv``; ``nu`` None: :attr:`SweepNominal.deviation_nu`); a surface and
    nominal of revolution on 129 samples of one meridian (``nu`` when given), every peak polished
    in ``u`` (:meth:`~tabletcad.geometry.tablet.Tablet.meridian_peaks`).
    The distance of each point to the nominal is exact (planar distance to the profile's lines and
    arcs at the point's exact plan offset).  The result is stored on the nominal
    (``tablet.nominal.certificate``).
    """
    nom = tablet.nominal
    if not isinstance(nom, SweepNominal):
        raise DesignError("tablet", tablet.name, "has no swept nominal to certify against")
    if _axisymmetric_nv(tablet, nv) == 4:  # of revolution: every meridian gives the same distances
        u, v = linspace(0.0, 1.0, 129 if nu is None else nu), np.zeros(1)
    else:  # a grid half as fine each way, polished around its peaks
        u, v, _ = tablet.nominal_grid(nu, nv)
    per = [float(x) for x in tablet.nominal_peaks(nu, nv)]
    cert = Certificate(max(per), tuple(per), tablet.tol.nominal, (len(u), len(v)), max(per) <= tablet.tol.nominal)
    nom.certificate = cert
    nom.patch_ids = tuple(id(p) for p in tablet.patches)
    return cert


def _rule_v(outline, n_per: int):
    """Quadrature in v: Gauss-Legendre on every interval between the outline's joins
    (the surface is only piecewise smooth in v there); trapezoidal for a circle."""
    b = np.asarray(outline.breaks)
    if len(b) == 2:
        m = 4 * n_per
        return np.arange(m) * (math.tau / m), np.full(m, math.tau / m)
    x, w = gauss_legendre(n_per)
    vs, ws = [], []
    for lo, hi in zip(b[:-1], b[1:]):
        vs.append(0.5 * (hi - lo) * (x + 1) + lo)
        ws.append(0.5 * (hi - lo) * w)
    return np.concatenate(vs), np.concatenate(ws)


def sweep_properties(tablet: Tablet, nu: int = 24, nv_per: int = 48) -> dict[str, float]:
    """Area, volume, plan area and cup volume of a swept tablet by quadrature (mm², mm³).

    Gauss-Legendre in ``u`` per patch and in ``v`` per outline segment (the
    sweep is only piecewise smooth in ``v``), so the figures converge to
    rounding; :meth:`Tablet.properties` uses a periodic rule in ``v``, which is
    spectrally accurate for circles but only first order across the joins of
    a lines-and-arcs outline.  A tablet of revolution on a round outline takes four
    meridians (its integrands do not depend on ``v``).

    Returns
    -------
    dict with ``surface_area_mm2``, ``volume_mm3`` (divergence theorem over the
    closed surface), ``plan_area_mm2`` (projection of the top face),
    ``cup_volume_mm3`` (one face, above the band's top edge) and
    ``cup_surface_area_mm2``.
    """
    nom = tablet.nominal
    xu, wu = gauss_legendre(nu)
    u = 0.5 * (xu + 1)
    wu = 0.5 * wu
    if tablet.revolution is not None and nom.axisymmetric:  # integrands the same on every meridian
        v, wv = np.arange(4) * (math.tau / 4), np.full(4, math.tau / 4)
    else:
        v, wv = _rule_v(nom.outline, nv_per)
    area = vol = 0.0
    top_area = plan = cup = 0.0
    z0 = nom.band_z[1]
    t0, t1 = nom.top_patch_range
    mirror = tablet.mirror()
    sums: dict[int, tuple[float, float, float, float]] = {}
    for i, p in enumerate(tablet.patches):
        j = i if mirror is None else mirror[1][i]
        if j < i:  # patch j reflected in z = zm with u reversed (the rule is symmetric in u): X' = M X + 2 zm e_z,
            # n' = M n, so the same area, X'·n' = X·n - 2 zm n_z, n'_z = -n_z and X'_z n'_z = X_z n_z - 2 zm n_z
            a, xn, nz, zn = sums[j]
            xn, nz, zn = xn - 2.0 * mirror[0] * nz, -nz, zn - 2.0 * mirror[0] * nz
        else:  # coordinates first (a level patch's z from its spine: PDEPatch.jet_grid); Σ_ij wu_i wv_j f_ij
            X, Xu, Xv = p.jet_grid(u, v)  # as two products, no weight grid
            n = cross_first(Xu, Xv)
            a = float(wu @ np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) @ wv)
            xn = float(wu @ (X[0] * n[0] + X[1] * n[1] + X[2] * n[2]) @ wv)
            nz, zn = float(wu @ n[2] @ wv), float(wu @ (X[2] * n[2]) @ wv)
            sums[i] = (a, xn, nz, zn)
        area += a
        vol += xn / 3.0
        if t0 <= i < t1:
            top_area += a
            plan += nz
            cup += zn - z0 * nz
    sgn = 1.0 if vol >= 0 else -1.0
    # a flat face's cup is 0: its integrand (X_z - z0) vanishes but for rounding, which would
    # show as a negative -3e-15 mm3
    cup = 0.0 if abs(cup) <= 1e-13 * abs(vol) else sgn * cup
    return dict(
        surface_area_mm2=area,
        volume_mm3=abs(vol),
        plan_area_mm2=abs(plan),
        cup_volume_mm3=cup,
        cup_surface_area_mm2=top_area,
    )


def nominal_volume(nominal: SweepNominal, n: int = 64) -> float:
    """Volume (mm³) of the exact nominal solid, independent of the PDE patches.

    The plan section at inward distance ``d`` is the outline's offset region, whose area
    is Steiner's ``A(d) = A₀ - P d + π d²`` (``A₀`` area, ``P`` perimeter; exact for clean
    offsets of a closed G1 outline, whose tangent turns once), so one face above the band
    holds ``∫ A(d) dz`` along its profile (lines and arcs: ``n``-point Gauss-Legendre per
    element of a smooth integrand, exact to rounding), and the solid is
    ``A₀ · band + 2 ∫ A dz``.
    """
    ol = nominal.outline
    A0, P = float(ol.area), float(ol.perimeter)
    x, w = gauss_legendre(n)
    t = 0.5 * (x + 1.0)
    cup = 0.0
    for e in nominal.top:
        d = e.point(t)[:, 0]
        dz = e.derivative(t)[:, 1]
        cup += 0.5 * float(np.sum(w * (A0 - P * d + math.pi * d * d) * dz))
    band = nominal.band_z[1] - nominal.band_z[0]
    return A0 * band + 2.0 * cup
