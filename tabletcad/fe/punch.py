"""Punch-tip stress and force rating by finite elements.

The punch tip is the tooling's own solid (:func:`tabletcad.tooling.toolset.make_tooling`):
the plan outline inset by the clearance, extruded to ``tip_length_mm`` beyond
the band edge, minus the tablet, so its face is the cup (scores as bars,
embossing as engravings).  The compaction force ``F`` is spread as a uniform
normal pressure over the face that touches the powder (every boundary facet
whose outward normal points towards the tablet, ``n·e < -0.3`` with ``e`` the
punch axis pointing away from the tablet: cup walls up to 72° steep; the
chordal triangles of the side wall tilt much less), scaled so that its axial resultant
is ``F``; the back face of the tip (the datum plane) carries the reaction as
a uniform pressure.  The tip is held by a 3-2-1 support that carries no load
(the two resultants balance; any lateral resultant of an asymmetric face is
reported as the reaction).  Linear elasticity, quadratic tetrahedra
(:mod:`tabletcad.fe.elasticity`).

Rating: the largest von Mises stress (vertex-averaged field) per newton
gives the allowed force ``F_allowed = σ_y / (S · σ_vM,max/F)`` for a steel's
yield stress ``σ_y`` and a safety factor ``S``.  For a flat-faced tip the
stress is the uniform ``F/A`` (checked in the tests); a cup raises the
largest stress and lowers the rating (also tested).

Buckling: the tip as a column of length ``L = tip_length_mm`` and the back
face's smallest second moment of area ``I`` (radius of gyration
``r = sqrt(I/A)``), effective-length factor ``K`` (default 2: fixed at the
barrel, free at the tip, conservative).  Euler ``F_cr = π² E I/(K L)²`` for a
slenderness ``KL/r`` above ``π sqrt(2E/σ_y)``, Johnson's parabola
``F_cr = A σ_y (1 - σ_y (KL/r)²/(4π² E))`` below it.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from importlib import resources
from typing import Any

import numpy as np

from tabletcad.errors import MISSING, DesignError, GeometryError, check_positive, check_range
from tabletcad.fe.elasticity import Material, PressureLoad, _skfem_mesh, boundary_facets, solve_elasticity, von_mises
from tabletcad.tolerance import MAX_YIELD_MPA, MIN_FORCE_N, MIN_YIELD_MPA
from tabletcad.fe.mesh import Refinement, check_mesh_size, mesh_solid

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

__all__ = ["ToolSteel", "tool_steels", "PunchResult", "punch_stress", "punch_tip_solid", "column_buckling", "fe_tip_rating", "tool_set_tip"]

#: Cosine below which a facet's outward normal counts as facing the tablet (loaded by the powder):
#: the cup and land (cup walls up to 72° steep); chordal triangles of the side wall tilt far less.
_FACING = -0.3


@dataclass(frozen=True)
class ToolSteel:
    """A tool steel with cited yield stress (MPa) and Young's modulus (MPa)."""

    name: str
    description: str
    yield_MPa: float
    E_MPa: float
    yield_source: str
    E_source: str


def tool_steels() -> dict[str, ToolSteel]:
    """The steels of ``tabletcad/data/tool_steels.toml`` by name."""
    text = resources.files("tabletcad").joinpath("data/tool_steels.toml").read_text(encoding="utf-8")
    data = tomllib.loads(text)
    return {k: ToolSteel(name=k, description=v["description"], yield_MPa=float(v["yield_MPa"]),
                         E_MPa=float(v["E_MPa"]), yield_source=v["yield_source"], E_source=v["E_source"])
            for k, v in data.get("steel", {}).items()}


def column_buckling(area: float, I_min: float, length: float, E: float, yield_stress: float,
                    K: float = 2.0) -> dict[str, Any]:
    """Critical axial force (N) of a column: Euler if slender, Johnson's parabola otherwise."""
    r = math.sqrt(I_min / area)
    lam = K * length / r
    lam_c = math.pi * math.sqrt(2.0 * E / yield_stress)
    if lam >= lam_c:
        f, how = math.pi**2 * E * I_min / (K * length) ** 2, "Euler"
    else:
        f, how = area * yield_stress * (1.0 - yield_stress * lam**2 / (4.0 * math.pi**2 * E)), "Johnson"
    return dict(critical_force_N=f, method=how, slenderness=lam, transition_slenderness=lam_c,
                radius_of_gyration_mm=r, I_min_mm4=I_min, area_mm2=area, length_mm=length,
                effective_length_factor=K)


@dataclass(frozen=True, eq=False)
class PunchResult:
    """Result of :func:`punch_stress` (N, mm, MPa)."""

    which: str
    force_N: float
    max_von_mises_MPa: float
    max_von_mises_location_mm: tuple[float, float, float]
    loaded_area_mm2: float
    axial_area_mm2: float
    back_area_mm2: float
    uniform_stress_MPa: float
    nodes: int
    elements: int
    dofs: int
    reaction_N: float
    yield_MPa: float | None
    safety_factor: float
    buckling: dict[str, Any] | None
    tip: dict[str, Any]
    solution: Any = field(repr=False, default=None)

    @property
    def allowed_force_kN(self) -> float | None:
        """Force at which the largest von Mises stress reaches yield / safety factor, kN."""
        if self.yield_MPa is None:
            return None
        f = self.yield_MPa / self.safety_factor / (self.max_von_mises_MPa / self.force_N) / 1000.0
        if self.buckling is not None:
            f = min(f, self.buckling["critical_force_N"] / self.safety_factor / 1000.0)
        return f

    def to_dict(self) -> dict[str, Any]:
        return {
            "punch": self.which,
            "force_kN": self.force_N / 1000.0,
            "max_von_mises_MPa": self.max_von_mises_MPa,
            "max_von_mises_location_mm": list(self.max_von_mises_location_mm),
            "uniform_stress_MPa": self.uniform_stress_MPa,
            "stress_concentration": self.max_von_mises_MPa / self.uniform_stress_MPa,
            "back_face_area_mm2": self.back_area_mm2,
            "loaded_area_mm2": self.loaded_area_mm2,
            "yield_MPa": self.yield_MPa,
            "safety_factor": self.safety_factor,
            "allowed_force_kN": self.allowed_force_kN,
            "allowed_force_yield_kN": None if self.yield_MPa is None else
            self.yield_MPa / self.safety_factor / (self.max_von_mises_MPa / self.force_N) / 1000.0,
            "buckling": self.buckling,
            "nodes": self.nodes,
            "elements": self.elements,
            "dofs": self.dofs,
            "reaction_N": self.reaction_N,
            "cup_depth_mm": self.tip.get("cup_depth_mm"),
            "tip_length_mm": self.tip.get("tip_length_mm"),
        }


def punch_tip_solid(tablet: Any, spec: Any, which: str = "upper") -> tuple[Any, dict[str, Any]]:
    """The ``which`` punch tip's solid and its info dict, from a design's ``[tooling]`` specification
    (:attr:`tabletcad.pipeline.design.Design.tooling_spec`)."""
    if which not in ("upper", "lower"):
        raise DesignError("punch", which, "must be upper or lower")
    if spec is None:
        raise DesignError("[tooling]", MISSING, "a punch tip is made from the design's [tooling] table (clearance, tip "
                          "length, standard): add one")
    from tabletcad.tooling.stage import check_tooling
    from tabletcad.tooling.toolset import make_tooling

    check_tooling(tablet, spec)
    ts = make_tooling(tablet, spec, check=False, interference_check=False)
    return tool_set_tip(ts, which)


def tool_set_tip(ts: Any, which: str) -> tuple[Any, dict[str, Any]]:
    """The ``which`` tip's solid and info of a built tool set: the punch part itself when the tooling is
    punch tips; with complete punches (``[tooling] standard``) the tip alone, as the tips-only tooling
    makes it (prism minus the finished tablet, up to ``tip_length_mm``), so that its back face is the
    datum plane the analysis loads; the tip relief behind ``tip_straight_mm`` is not modelled."""
    if ts.spec.body is None:
        return ts.parts[f"{which}_punch"], ts.report[f"{which}_punch"]
    from tabletcad.tooling.punch import punch_tip

    length = ts.spec.tip_length_mm if which == "upper" else ts.spec.lower_tip
    tip, _ = punch_tip(ts.frame, ts.parts["tablet"], which, ts.spec.clearance_mm, length, check=False)
    return tip.shape, tip.info


def punch_stress(
    tip_shape: Any,
    tip: dict[str, Any],
    force_kN: float,
    which: str = "upper",
    *,
    yield_MPa: float | None = None,
    safety_factor: float = 1.5,
    E: float = 206000.0,
    nu: float = 0.29,
    mesh_size: float | None = None,
    effective_length_factor: float = 2.0,
    face_refinement: float = 0.5,
) -> PunchResult:
    """Von Mises stress of a punch tip under ``force_kN`` spread over its cup face, and its rating.

    Parameters
    ----------
    tip_shape, tip
        The tip solid and its info (:func:`punch_tip_solid`).
    force_kN : float
        Compaction force, kN.
    yield_MPa : float, optional
        Steel yield stress, MPa (no rating without it): 100-10000 MPa
        (:data:`~tabletcad.tolerance.MIN_YIELD_MPA`: below any punch steel, so a value in GPa is refused).
    safety_factor : float
        Divides the yield stress and the buckling force.
    E, nu
        Steel elasticity (MPa; E enters only the buckling check).
    mesh_size : float, optional
        Element size, mm; default ``min(tip width/8, tip_length/6)``.
    face_refinement : float
        Element size near the cup face as a fraction of ``mesh_size`` (1: none).
    effective_length_factor : float
        ``K`` of the buckling check.
    """
    # (1e308 overflowed the solve; 1e-200 kN left no stress to divide by)
    F = check_range("--force", force_kN, MIN_FORCE_N / 1000.0, 1e6, "kN") * 1000.0
    S = check_range("--safety-factor", safety_factor, 1.0, 100.0)
    if yield_MPa is not None:
        check_range("--yield-stress", yield_MPa, MIN_YIELD_MPA, MAX_YIELD_MPA, "MPa")  # a steel's, in MPa
    axis = np.array([0.0, 0.0, 1.0 if which == "upper" else -1.0])
    A_plan = float(tip["tip_plan_area_mm2"])
    width = 2.0 * math.sqrt(A_plan / math.pi)
    L = float(tip["tip_length_mm"])
    h = min(width / 8.0, L / 6.0) if mesh_size is None else check_range("--mesh-size", mesh_size, 0.0, L + width, "mm",
                                                                         lo_open=True)  # at most the tip's size
    check_mesh_size(A_plan * (L + 2.0 * width), h, "--mesh-size")
    edge = float(tip["tip_edge_z_mm"])
    cup = float(tip.get("cup_depth_mm") or 0.0)
    big = 1e3
    lo = [-big, -big, edge - 2.0 * cup - h] if which == "upper" else [-big, -big, edge - 2.0 * h]
    hi = [big, big, edge + 2.0 * h] if which == "upper" else [big, big, edge + 2.0 * cup + h]
    refine = [] if face_refinement >= 1.0 else [Refinement(tuple(lo), tuple(hi), h * face_refinement)]
    mesh = mesh_solid(tip_shape, h, refinements=refine)
    m = _skfem_mesh(mesh)
    bf = boundary_facets(m)
    cos = bf.normals @ axis
    datum = float(tip["working_length_datum"]["datum_plane_z_mm"])
    back = np.flatnonzero((cos > 0.999) & (np.abs(bf.centroids[:, 2] - datum) < 1e-6 * max(1.0, abs(datum)) + 1e-6))
    face = np.flatnonzero(cos < _FACING)
    if back.size == 0 or face.size == 0:
        raise GeometryError("punch: no back face or no loaded face found on the tip", tip_shape)
    push = float((-cos[face] * bf.areas[face]).sum())  # axial projection of the loaded face, mm²
    A_back = float(bf.areas[back].sum())
    loads = [PressureLoad(face, F / push), PressureLoad(back, F / A_back)]
    c = m.p.mean(axis=1)
    sol = solve_elasticity(mesh, Material(E=E, nu=nu), loads, support_centre=c, support_arm=0.25 * width,
                           facets=bf, skmesh=m)
    vm = von_mises(sol.nodal_stress())
    k = int(np.argmax(vm))
    # back-face section properties (exact for its triangles)
    tri = m.p[:, m.facets[:, bf.ids[back]]]  # (3, 3, k)
    xy = tri[:2]  # (2, 3, k)
    a = bf.areas[back]
    cen = (xy.mean(axis=1) * a).sum(axis=1) / a.sum()
    d = xy - cen[:, None, None]
    # second moments of a triangle: A/12 (Σ x_i² + (Σ x_i)²)
    J = np.empty((2, 2))
    for i in range(2):
        for j in range(2):
            J[i, j] = float((a / 12.0 * ((d[i] * d[j]).sum(axis=0) + d[i].sum(axis=0) * d[j].sum(axis=0))).sum())
    I_min = float(np.linalg.eigvalsh(J)[0])
    buck = None
    if yield_MPa is not None:
        buck = column_buckling(A_back, I_min, L, E, yield_MPa, effective_length_factor)
        buck["critical_force_kN"] = buck["critical_force_N"] / 1000.0
    return PunchResult(
        which=which, force_N=F, max_von_mises_MPa=float(vm[k]),
        max_von_mises_location_mm=tuple(float(v) for v in m.p[:, k]), loaded_area_mm2=float(bf.areas[face].sum()),
        axial_area_mm2=push, back_area_mm2=A_back, uniform_stress_MPa=F / A_back, nodes=sol.nodes,
        elements=sol.elements, dofs=sol.dofs, reaction_N=sol.reaction, yield_MPa=yield_MPa, safety_factor=S,
        buckling=buck, tip=tip, solution=sol)


#: compaction force (kN) the FE rating loads the tips with when the design gives none; the analysis is
#: linear, so the rating (stress per newton) does not depend on it
REFERENCE_FORCE_KN = 10.0


def fe_tip_rating(ts: Any, rating: Any, force_kN: float | None = None) -> dict[str, Any]:
    """The FE tip-force rating of a built tool set, for ``tooling.tip_rating.fe`` and the drawing.

    ``ts``: a :class:`tabletcad.tooling.toolset.ToolSet` (its tips, :func:`tool_set_tip`, the same
    as :func:`punch_tip_solid` makes); ``rating``: the design's ``[tooling.fe_rating]``
    (:class:`tabletcad.tooling.spec.FeRatingSpec`); ``force_kN``: the design's compaction force, kN
    (default :data:`REFERENCE_FORCE_KN`).  Each tip is analysed by :func:`punch_stress` with the
    steel's yield stress and Young's modulus; ``allowed_force_kN`` is the smaller of the tips'.
    """
    if rating.steel is not None:
        steel = tool_steels()[rating.steel]
        y, E, src, e_src = steel.yield_MPa, steel.E_MPa, steel.yield_source, steel.E_source
        what = f"steel {steel.name}: {steel.description}"
    else:
        y, E, src = rating.yield_stress_MPa, 206000.0, rating.yield_stress_source
        e_src, what = "tabletcad fe punch's default (206000 MPa)", "user-given yield stress"
    force = REFERENCE_FORCE_KN if force_kN is None else force_kN
    tips = {}
    for which in rating.punches:
        try:
            res = punch_stress(*tool_set_tip(ts, which), force, which, yield_MPa=y,
                               safety_factor=rating.safety_factor, E=E, mesh_size=rating.mesh_size_mm)
        except DesignError as exc:  # named by the design's key, not the command's option
            if exc.parameter == "--mesh-size":
                raise exc.renamed("[tooling.fe_rating] mesh_size_mm") from None
            raise
        tips[which] = {k: v for k, v in res.to_dict().items() if k != "buckling"}
        tips[which]["buckling"] = res.buckling
    allowed = min(t["allowed_force_kN"] for t in tips.values())
    return dict(method="FE punch analysis (tabletcad.fe.punch.punch_stress, as tabletcad fe punch): the largest von "
                       "Mises stress per newton of the compaction force spread over the cup face; allowed force = "
                       "yield / safety factor / (stress per N), or the buckling force / safety factor if lower",
                allowed_force_kN=allowed, yield_MPa=y, yield_source=src, youngs_modulus_MPa=E, youngs_modulus_source=e_src,
                material=what, steel=rating.steel, safety_factor=rating.safety_factor, force_kN=force,
                force_source="the design's [report] compaction_force_kN" if force_kN is not None else
                f"reference load {REFERENCE_FORCE_KN:g} kN (linear analysis: the rating does not depend on it)",
                utilisation=None if force_kN is None else force_kN / allowed, tips=tips)
