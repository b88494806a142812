"""The tablet drawing toolmakers exchange: plan, front and side elevations with dimensions.

Views are projections of the B-rep by OCC's hidden-line removal
(``HLRBRep_Algo`` / ``HLRBRep_HLRToShape``): visible sharp edges and
silhouettes drawn solid, hidden sharp edges and silhouettes dashed (a die's bore in elevation) unless a
visible line covers them.  Third-angle layout: the
front elevation (looking along +y), the plan above it (looking down -z) and
the side elevation (looking along -x) to its right.  Dimensions state the
design's numbers: diameter (or length and width), band, cup depth, overall
thickness, a round's spherical cup radius (section A-A) and land (detail B), each
with its ± tolerance (compound, shaped and edge radii are in the notes; the design's
``[tooling.drawing] tolerances``, else its ``tolerance_mm``, else 0.076 mm stated
on the sheet as this program's default).  The title block carries name,
drawing number, revision, material, date and author from ``[tooling.drawing]``
and the scale the views were drawn at.  Written as ``drawing.svg`` and
``drawing.pdf`` (matplotlib, text kept as text) and ``drawing.dxf`` (ezdxf,
DIMENSION entities with the same texts).  With complete punches a second sheet,
``tooling.svg``/``.pdf``/``.dxf``, shows the upper punch, lower punch and die
in elevation with overall length, tip length, barrel and head diameters, die
diameter and height, each with its ± tolerance (neck, relief and bore in the notes).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepLib import BRepLib
from OCP.GCPnts import GCPnts_TangentialDeflection
from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
from OCP.HLRAlgo import HLRAlgo_Projector
from OCP.HLRBRep import HLRBRep_Algo, HLRBRep_HLRToShape

from tabletcad.cad._occ import explore
from tabletcad.io import atomic_path
from tabletcad.io.figures import save_figure
from tabletcad.io.timestamp import content_uuid, stamp_time
from tabletcad.tooling.rating import overload_texts, rating_text
from tabletcad.tooling.shape_cache import ShapeCache, frozen
from tabletcad.tolerance import DEFAULT as DEFAULT_TOLERANCES

__all__ = ["project_view", "drawing_model", "write_drawing", "Drawing", "Dim"]

VIEWS = {  # name: (view direction towards the viewer, horizontal axis of the sheet)
    "plan": ((0.0, 0.0, 1.0), (1.0, 0.0, 0.0)),
    "front": ((0.0, -1.0, 0.0), (1.0, 0.0, 0.0)),
    "side": ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
}


def _polylines(compound, deflection: float = 0.002) -> list[np.ndarray]:
    out = []
    if compound is None or compound.IsNull():
        return out
    BRepLib.BuildCurves3d_s(compound)
    for e in explore(compound, "Edge"):
        try:
            c = BRepAdaptor_Curve(e)
            d = GCPnts_TangentialDeflection(c, 0.05, deflection)
            pts = np.array([[d.Value(i).X(), d.Value(i).Y()] for i in range(1, d.NbPoints() + 1)])
        except Exception:  # pragma: no cover - degenerate edge from the projection
            continue
        if len(pts) >= 2:
            out.append(pts)
    return out


#: the projections and sections of the shapes drawn last (a sheet drawn again - another title block or
#: paper, the same parts - does not run the hidden-line removal again); entries hold their shapes
VIEW_CACHE = ShapeCache(size=24)


def _cached_view(shape, key, compute) -> dict:
    """``compute()``'s view of ``shape``, once per (shape, ``key``) while :data:`VIEW_CACHE` holds it: new
    lists of the same read-only polylines each time (a caller may add to a list, not change a polyline)."""
    view = VIEW_CACHE.get(shape, key, lambda: {k: frozen(*v) for k, v in compute().items()})
    return {k: list(v) for k, v in view.items()}


def project_view(shape, view: str) -> dict:
    """``{"visible": [polylines], "hidden": [polylines]}`` (2-D, mm) of ``shape`` seen in ``view``."""
    return _cached_view(shape, ("view", view), lambda: _project_view(shape, view))


def _project_view(shape, view: str) -> dict:
    d, x = VIEWS[view]
    # tangent (G1) edges - between the patches of a smooth cup, at the outline's line/arc
    # junctions where a chain is cut (tabletcad.brep.slit) - are not drawn, as on a toolmaker's
    # drawing: OCCT stores an edge's continuity only when asked, else every edge counts as sharp
    BRepLib.EncodeRegularity_s(shape, math.radians(DEFAULT_TOLERANCES.seam_angle_deg))
    algo = HLRBRep_Algo()
    algo.Add(shape)
    algo.Projector(HLRAlgo_Projector(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(*d), gp_Dir(*x))))
    algo.Update()
    algo.Hide()
    h = HLRBRep_HLRToShape(algo)
    vis = _polylines(h.VCompound()) + _polylines(h.OutLineVCompound())
    # hidden sharp edges and hidden outlines: a die's bore in elevation is its cylinder's (or its ends' arcs')
    # outline, not an edge (a trial's die showed the bore's seam alone, dashed, on one side)
    hid = _polylines(h.HCompound()) + _polylines(h.OutLineHCompound())
    return {"visible": vis, "hidden": [p for p in hid if not _on_lines(p, vis)]}


def _on_lines(p: np.ndarray, lines: list[np.ndarray], tol: float = 1e-4) -> bool:
    """Whether every point of the polyline ``p`` (and every point between them) lies within ``tol`` mm of
    ``lines``' segments: a hidden line a visible one covers, which a drawing does not show twice."""
    if not lines:
        return False
    t = np.linspace(0.0, 1.0, 5)[:, None]
    q = (p[:-1, None, :] * (1.0 - t) + p[1:, None, :] * t).reshape(-1, 2)
    lo, hi = q.min(axis=0) - tol, q.max(axis=0) + tol
    a = np.concatenate([v[:-1] for v in lines])
    b = np.concatenate([v[1:] for v in lines])
    near = np.all((np.minimum(a, b) <= hi) & (np.maximum(a, b) >= lo), axis=1)  # segments by the polyline
    a, b = a[near], b[near]
    if not len(a):
        return False
    ab = b - a
    u = np.clip(np.einsum("qsk,sk->qs", q[:, None, :] - a[None], ab) / np.maximum(np.einsum("sk,sk->s", ab, ab), 1e-300),
                0.0, 1.0)
    d = np.linalg.norm(q[:, None, :] - (a[None] + u[..., None] * ab[None]), axis=2)
    return bool(np.all(d.min(axis=1) <= tol))


def section_view(shape, direction_deg: float) -> dict:
    """The tablet cut by the plane through its axis across ``direction_deg`` (a score's direction):
    ``{"visible": [polylines (across, z)], "hidden": []}``, seen from the side the score runs to."""
    return _cached_view(shape, ("section", float(direction_deg)), lambda: _section_view(shape, direction_deg))


def _section_view(shape, direction_deg: float) -> dict:
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon

    from tabletcad.tooling.booleans import raw_boolean

    th = math.radians(direction_deg)
    n = (-math.sin(th), math.cos(th))
    R = 1e3
    poly = BRepBuilderAPI_MakePolygon()
    for u, z in ((-R, -R), (R, -R), (R, R), (-R, R)):
        poly.Add(gp_Pnt(u * n[0], u * n[1], z))
    poly.Close()
    cut = raw_boolean("common", shape, BRepBuilderAPI_MakeFace(poly.Wire(), True).Face())
    out = []
    for e in explore(cut, "Edge"):
        c = BRepAdaptor_Curve(e)
        d = GCPnts_TangentialDeflection(c, 0.05, 0.002)
        pts = [d.Value(i) for i in range(1, d.NbPoints() + 1)]
        if len(pts) >= 2:
            out.append(np.array([[p.X() * n[0] + p.Y() * n[1], p.Z()] for p in pts]))
    return {"visible": out, "hidden": []}


def section_band_edge(sec: dict, band_z: tuple[float, float]) -> float:
    """The across coordinate (mm) where the section :func:`section_view` meets the band on its positive
    side: the farthest point of its polylines between the band's heights.  Detail B looks there (a rounded
    triangle's section through the axis ends 4.667 mm out on that side, where half its 10.34 mm length had
    put the detail on a bare band line)."""
    b0, b1 = min(band_z), max(band_z)
    pts = np.vstack([p for p in sec["visible"] if len(p)]) if sec["visible"] else np.zeros((1, 2))
    on_band = pts[(pts[:, 1] >= b0 - 1e-6) & (pts[:, 1] <= b1 + 1e-6)]
    return float((on_band if len(on_band) else pts)[:, 0].max())


def detail_view(view: dict, centre: tuple[float, float], half: float, k: float) -> dict:
    """The part of ``view`` within ``half`` mm of ``centre``, enlarged ``k`` times about it."""
    c = np.asarray(centre, float)
    out = []
    step = half / 40.0
    for p in view["visible"]:
        # densify so that long straight edges through the window keep their inside part
        seg = [np.linspace(a, b, max(2, int(np.ceil(np.linalg.norm(b - a) / step)) + 1))[:-1] for a, b in zip(p[:-1], p[1:])]
        p = np.vstack(seg + [p[-1:]])
        inside = np.all(np.abs(p - c) <= half, axis=1)
        run: list = []
        for q, ok in zip(p, inside):
            if ok:
                run.append(q)
            elif run:
                out.append(np.array(run))
                run = []
        if len(run) >= 2:
            out.append(np.array(run))
    return {"visible": [(p - c) * k for p in out if len(p) >= 2], "hidden": []}


@dataclass
class Dim:
    """A linear dimension between two sheet points, drawn ``offset`` mm aside, with its text.

    ``radius``: a radius dimension instead; ``p1`` is the arc's centre, ``p2`` a point on the arc,
    and the leader runs from ``p2`` outwards (away from the centre) ``offset`` mm to the text.
    ``scale``: the view's enlargement (a detail at 10:1 is 10): a DXF reader measures the
    dimension as its sheet length over it.
    """

    p1: tuple[float, float]
    p2: tuple[float, float]
    offset: float
    text: str
    vertical: bool = False
    radius: bool = False
    scale: float = 1.0


@dataclass
class Drawing:
    views: dict
    origins: dict
    dims: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    title: str = ""
    title_block: list = field(default_factory=list)
    scale: float | None = None
    paper: str = "A4"
    #: ``(wire, (x, y))``: plan wires (z = 0, mm) the DXF carries as exact LINE, ARC, CIRCLE, ELLIPSE and
    #: SPLINE entities on its OUTLINE layer, placed at a view's origin (the tablet's nominal outline in the plan)
    exact: list = field(default_factory=list)

    def __post_init__(self) -> None:
        # a tablet's name or an emboss text in a font of its own may hold characters the sheet's font
        # (DejaVu Sans) has no glyph for: written as \uXXXX, not drawn as empty boxes
        self.title = drawable(self.title)
        self.notes = [drawable(n) for n in self.notes]
        self.title_block = [drawable(t) for t in self.title_block]

    def texts(self) -> list[str]:
        return [d.text for d in self.dims] + list(self.notes)


def drawable(text: str) -> str:
    """``text`` with every character the drawings' font cannot draw written as ``\\uXXXX``."""
    from tabletcad.tooling.spec import drawing_font, missing_glyphs

    for c in missing_glyphs(text, drawing_font()):
        text = text.replace(c, f"\\u{ord(c):04x}" if ord(c) <= 0xFFFF else f"\\U{ord(c):08x}")
    return text


def _fmt(x: float) -> str:
    return f"{x:.2f}" if abs(x) >= 0.1 else f"{x:.3f}"


def _outline_notes(ts) -> list[str]:
    """A shaped tablet's outline radii (its design's ``end_radius``, ``corner_radius``) and, for a cup swept
    over the outline's offsets, how far in the cup runs and whether a flat plateau finishes the face (a
    toolmaker's trial: an oval's sheet gave only the cup radius, and its 10 x 2.5 mm plateau went unsaid)."""
    notes = []
    params = getattr(ts.tablet, "params", None) or {}
    general = ts.spec.drawing.tolerance_mm
    for k in ("end_radius", "corner_radius"):
        v = params.get(k)
        if isinstance(v, (int, float)) and v > 0:
            notes.append(f"outline {k.replace('_', ' ')} R{_fmt(v)} ±{_fmt(general)} mm")
    info = ts.frame.info
    cw = info.get("cup_width_mm")
    outline = getattr(getattr(ts.tablet, "nominal", None), "outline", None)
    if isinstance(cw, (int, float)) and cw > 0 and info.get("cup_depth_mm", 0.0) > 0 and outline is not None:
        reach = outline.inscribed_radius()
        inside = ("a flat plateau inside (the outline offset inwards by it)" if cw < reach - 1e-6
                  else "closing at the centre")
        notes.append(f"cup swept over the outline's offsets: it runs {_fmt(cw)} mm in from the outline (land "
                     f"included), {inside}")
    return notes


def drawing_model(ts) -> Drawing:
    """Views and dimensions of a :class:`~tabletcad.tooling.toolset.ToolSet`'s tablet."""
    fr = ts.frame
    shape = ts.parts["tablet"]
    views = {k: project_view(shape, k) for k in VIEWS}
    L, W = fr.length, fr.width
    # the finished tablet's thickness: raised figures stand above the cups (a 1.5 mm one had been drawn as 4.6)
    z_lo, z_hi = ts.report["tablet"].get("z_range_mm", (fr.z_min, fr.z_max))
    T = z_hi - z_lo
    gap = 6.0 + 0.3 * max(L, W)
    origins = {"front": (0.0, 0.0), "plan": (0.0, T / 2 + gap + W / 2), "side": (L / 2 + gap + W / 2, 0.0)}
    # views are centred on the tablet's axis: front/side z runs from z_min to z_max
    zc = 0.5 * (fr.z_min + fr.z_max)
    origins = {k: (ox, oy - (zc if k != "plan" else 0.0)) for k, (ox, oy) in origins.items()}
    fx, fy = origins["front"]
    px, py = origins["plan"]
    sx, sy = origins["side"]
    x0, x1 = -L / 2, L / 2
    dims: list[Dim] = []
    if fr.round_radius is not None:
        dims.append(Dim((px + x0, py), (px + x1, py), W / 2 + 2.0, f"Ø{_fmt(2 * fr.round_radius)}"))
    else:
        dims.append(Dim((px + x0, py), (px + x1, py), W / 2 + 2.0, f"L {_fmt(L)}"))
        dims.append(Dim((sx - W / 2, sy + fr.z_min), (sx + W / 2, sy + fr.z_min), -2.0, f"W {_fmt(W)}"))
    b0, b1 = fr.band_z
    dims.append(Dim((fx + x1, fy + b0), (fx + x1, fy + b1), 2.0, f"band {_fmt(fr.band)}", vertical=True))
    if fr.cup_depth_top > 1e-6:  # a flat face has no cup to dimension
        dims.append(Dim((fx + x1, fy + b1), (fx + x1, fy + fr.z_max), 2.0 + 4.0, f"cup {_fmt(fr.cup_depth_top)}",
                        vertical=True))
    dims.append(Dim((fx + x0, fy + z_lo), (fx + x0, fy + z_hi), -3.0, f"T {_fmt(T)}", vertical=True))
    notes = [f"{ts.tablet.name} ({ts.tablet.family})", f"overall thickness {_fmt(T)} mm", f"band {_fmt(fr.band)} mm",
             f"cup depth {_fmt(fr.cup_depth_top)} mm (bottom {_fmt(fr.cup_depth_bottom)} mm)"]
    if fr.round_radius is not None:
        notes.insert(1, f"diameter Ø{_fmt(2 * fr.round_radius)} mm")
    else:
        notes.insert(1, f"length {_fmt(L)} mm x width {_fmt(W)} mm")
    tol = ts.spec.drawing.tolerance_text
    radii = {k: v for k, v in fr.info.items() if k.endswith("radius_mm") and isinstance(v, (int, float)) and v > 0}
    for k, v in radii.items():
        notes.append(f"{k[:-3].replace('_', ' ')} R{_fmt(v)} {tol('cup_radius')} mm")
    notes += _outline_notes(ts)
    if not radii and fr.round_radius is not None and fr.cup_depth_top > 1e-6 and not fr.info:
        R, d = fr.round_radius, fr.cup_depth_top  # a thesis shape: its PDE cup is not a sphere
        notes.append(f"sphere through the cup's rim and apex R{_fmt((R * R + d * d) / (2 * d))} mm (reference: "
                     "the cup is the PDE surface of the STEP file)")
    if fr.land:
        notes.append(f"land {_fmt(fr.land)} {tol('land')} mm")
    elif fr.land is not None:
        notes.append("no land")
    if fr.info.get("bevel_width_mm"):
        ang = dict(ts.spec.drawing.tolerances).get("bevel_angle")
        ang_text = (f"{ang[0]:+g}/{ang[1]:+g} deg" if isinstance(ang, tuple) else f"±{ang:g} deg" if ang is not None
                    else "±1 deg (ISO 2768-m, legs up to 10 mm)")
        notes.append(f"bevel {_fmt(fr.info['bevel_width_mm'])} {tol('bevel_width')} mm wide at "
                     f"{fr.info['bevel_angle_deg']:g} deg " + ang_text)
    for s in ts.report.get("scores", []):
        notes.append(_score_note(s, ts.spec.scores[s["index"]]))
    for e in ts.spec.emboss:  # what the engraver needs: the figure, its size, font, draft, place and turn
        what = (f"'{e.text}' {_fmt(e.height_mm)} mm high in {e.font}" if e.text is not None
                else "the SVG figure" if e.svg is not None else "the outline")
        notes.append(f"{e.mode} {what}, {_fmt(e.depth_mm)} mm deep ({'along the face normal' if e.projection == 'normal' else 'axially'}) "
                     f"on the {e.face} face, stroke angle {e.draft_deg:g} deg, centred at "
                     f"({_fmt(e.position_mm[0])}, {_fmt(e.position_mm[1])}) mm, turned {e.rotation_deg:g} deg")
    r = ts.report.get("tip_rating") or {}
    notes += rating_notes(r) + fit_notes(ts.spec)
    for k, b in ((r.get("buckling") or {}).get("tips") or {}).items():
        if b["buckling_load_kN"] is not None:
            notes.append(f"{k} tip Euler buckling load {rating_text(b['buckling_load_kN'], 3)} kN (K = 2, free length "
                         f"{_fmt(b['free_length_mm'])} mm)")
    notes.append("all dimensions in mm; third-angle projection; generated from the B-rep (OCC HLR)")
    # section across the (first) score, or across x, and a detail of the land and band edge
    scores = ts.spec.scores
    th = scores[0].direction_deg if scores else 90.0
    sec = section_view(shape, th)
    k = 10.0
    half = max(0.6, 1.2 * (fr.land or 0.0) + 0.2 * fr.cup_depth_top + 0.3)
    half_w = section_band_edge(sec, fr.band_z)  # where the section meets the band on its +across side
    det = detail_view(sec, (half_w, fr.band_z[1]), half, k)
    ox = L / 2 + gap + W / 2
    sx_, sy_ = ox, py - zc
    views["section A-A"] = sec
    origins["section A-A"] = (sx_, sy_)
    views[f"detail B {k:g}:1"] = det
    origins[f"detail B {k:g}:1"] = (sx_ + max(L, W) / 2 + gap / 2 + k * half, py)
    if scores:
        sc = ts.report["scores"][0]
        dims.append(Dim((sx_, sy_ + fr.z_max - sc["depth_mm"]), (sx_, sy_ + fr.z_max), 2.0 + half_w,
                        f"score {_fmt(sc['depth_mm'])}", vertical=True))
    cup_r = _single_cup_radius(fr, radii)
    # the section shows the cup only where no score runs along it: not across a quadrisect or crossing bisects
    along = any((sc.kind == "quadrisect" or abs(((sc.direction_deg - th) + 90.0) % 180.0 - 90.0) > 1e-9)
                and "top" in sc.face_list for sc in scores)  # (the radius is drawn on the top cup)
    if cup_r is not None and not along:  # on the section's left half, away from a score at the centre
        x = -0.6 * _cup_edge_radius(fr)
        zc = fr.z_max - cup_r  # the cup's sphere is centred on the axis
        dims.append(Dim((sx_, sy_ + zc), (sx_ + x, sy_ + zc + math.sqrt(cup_r * cup_r - x * x)), 3.0,
                        f"R{_fmt(cup_r)}", radius=True))
    if fr.land and fr.edge_land("top") > 0:  # the land in detail B: from the cup's edge to the outline
        dx, dy = origins[f"detail B {k:g}:1"]
        dims.append(Dim((dx - k * fr.land, dy), (dx, dy), 0.25 * k * half, f"land {_fmt(fr.land)}", scale=k))
    notes.append(f"section A-A through the axis across {th:g} deg{' (the score)' if scores else ''}; "
                 f"detail B: band edge and land, {k:g}:1")
    # (not a section of a free-form band)
    exact = fr.outline_kind in ("circle", "ellipse", "lines and arcs", "spline")
    if exact:
        notes.append("drawing.dxf: layer OUTLINE holds the nominal outline in the plan as exact "
                     + {"circle": "a circle", "ellipse": "an ellipse",
                        "spline": "a closed cubic B-spline (SPLINE)"}.get(fr.outline_kind, "lines and arcs"))
    return Drawing(views, origins, _toleranced(dims, ts), notes, title=_title(ts), title_block=title_block(ts),
                   exact=[(fr.outline, origins["plan"])] if exact else [])


def _single_cup_radius(fr, radii: dict) -> float | None:
    """The cup radius to dimension (mm): a round family's spherical cup (one radius, from the family's
    nominal geometry), else None (compound cups, shaped tablets and edge radii stay in the notes, as does
    the sphere through a thesis shape's PDE cup, which is not a sphere)."""
    if fr.round_radius is None or fr.cup_depth_top <= 1e-6 or set(radii) != {"cup_radius_mm"} \
            or "cup_radius_mm" not in fr.info:
        return None
    r = float(radii["cup_radius_mm"])
    return r if r >= _cup_edge_radius(fr) else None  # the sphere reaches the cup's edge (a hemisphere too)


def _cup_edge_radius(fr) -> float:
    """Distance from the axis to the cup's edge (mm): the outline's radius less the land and a bevel."""
    return fr.round_radius - (fr.land or 0.0) - float(fr.info.get("bevel_width_mm", 0.0))


def rating_notes(r: dict) -> list[str]:
    """The tip-force rating lines of the drawing from ``tooling.tip_rating``: the FE punch analysis's
    (``fe``, when it was computed) first, then the projected-area pressure rule's.  Ratings are rounded down
    (:func:`~tabletcad.tooling.rating.rating_text`), and an overload is stated with as many digits as it takes
    for the force to read above the rating and the utilisation above 1 (14.967 kN had read "15 kN", and a
    15 kN force "1 x the rated 15 kN")."""
    notes = []
    fe = r.get("fe") or {}
    if fe.get("allowed_force_kN") is not None:
        tips = ", ".join(f"{k} {rating_text(t['allowed_force_kN'])} kN" for k, t in fe["tips"].items())
        notes.append(f"tip force rating {rating_text(fe['allowed_force_kN'])} kN (FE punch analysis: {tips}; allowed "
                     f"stress {fe['yield_MPa']:g} MPa yield / safety factor {fe['safety_factor']:g}, from {fe['yield_source']})")
    if r.get("rated_force_kN") is not None:
        lead = "pressure-rule rating" if notes else "tip force rating"
        rated = r["rated_force_kN"]
        force, shown, u = (overload_texts(r["compaction_force_kN"], rated) if r.get("overloaded")
                           else (None, rating_text(rated), None))
        notes.append(f"{lead} {shown} kN = {r['allowed_pressure_MPa']:g} MPa x "
                     f"{r['tip_projected_area_mm2']:.4g} mm2 tip area (allowed pressure: {r['allowed_pressure_source']})")
        if r.get("overloaded"):
            notes.append(f"OVERLOADED: compaction force {force} kN is {u} x the rated {shown} kN")
    return notes


def fit_notes(spec) -> list[str]:
    """The fit's warnings (:func:`~tabletcad.tooling.spec.fit_warnings`: a clearance of 0 or wider than 0.1 mm a
    side, bore and tip tolerances that can close it) as the drawings' notes, as stderr has them."""
    from tabletcad.tooling.spec import fit_warnings

    return [f"WARNING: {m}" for m in fit_warnings(spec)]


def _fit_range(spec) -> str:
    """``; 0.020 to 0.040 a side at the tolerances' limits``: the clearance (mm) the bore's and the tips'
    tolerances allow (:meth:`~tabletcad.tooling.spec.DrawingSpec.fit_clearance`)."""
    from tabletcad.tooling.spec import micrometre_text

    least, most = spec.drawing.fit_clearance()
    return f"; {micrometre_text(least)} to {micrometre_text(most)} a side at the tolerances' limits"


_DIM_KEYS = {"Ø": "diameter", "L": "length", "W": "width", "band": "band", "cup": "cup_depth", "T": "thickness",
             "score": "score_depth", "R": "cup_radius", "land": "land"}


def _score_note(s: dict, spec) -> str:
    """A score's defining geometry in words: kind, profile (V angle, U width, pressure-sensitive slot),
    depth, width at the face, direction, face, and whether it is cut through or short."""
    profile = {"v": f"V {spec.angle_deg:g} deg", "u": f"U {_fmt(spec.width_mm)} mm wide",
               "pressure_sensitive": f"pressure-sensitive, slot {_fmt(spec.slot_width_mm)} mm, flanks "
                                     f"{spec.angle_deg:g} deg"}[s["profile"]]
    extent = (f"short, {_fmt(s['length_mm'])} mm long (decorative)" if s["length_mm"] is not None
              else "cut through the band" if s["cut_through"] else "across the face")
    return (f"{s['kind']} score {profile}, {_fmt(s['depth_mm'])} mm deep, {_fmt(s['width_at_face_centre_mm'])} mm "
            f"wide at the face, at {s['direction_deg']:g} deg on the {s['face']} face, {extent}")


def _toleranced(dims: list, ts) -> list:
    """``dims`` with ``±tolerance`` appended to each text (the drawing spec's value for its key)."""
    from dataclasses import replace

    import re
    import warnings

    dspec = ts.spec.drawing
    out, negative = [], []
    for d in dims:
        head = d.text.split()[0]
        key = _DIM_KEYS.get(head, _DIM_KEYS.get(head[:1], None))
        out.append(replace(d, text=f"{d.text} {dspec.tolerance_text(key)}") if key else d)
        size = re.search(r"\d+(?:\.\d+)?", d.text)
        if key and size and dspec.tolerance(key) >= float(size.group()) > 0.0:
            negative.append(f"{d.text} {dspec.tolerance_text(key)} ([tooling.drawing] tolerances.{key})")
    if negative:  # (a toolmaker's trial: "land 0.050 ±0.076" was drawn in silence)
        warnings.warn("the drawing's tolerances reach below zero: " + "; ".join(dict.fromkeys(negative)) +
                      ": give each a tolerance smaller than its size", stacklevel=3)
    return out


def _plan_size(fr, inset: float) -> str:
    """The plan size of the outline offset inward by ``inset`` mm: ``Ø`` of a round, else length x width
    (a convex outline's extents shrink by twice the offset), to the micrometre a bore and its tips are
    ground to (a thesis tablet's bore, 2.5 µm a side over the outline, read "Ø10.00" at two decimals)."""
    if fr.round_radius is not None:
        return f"Ø{2.0 * (fr.round_radius - inset):.3f}"
    return f"{fr.length - 2.0 * inset:.3f} x {fr.width - 2.0 * inset:.3f}"


def _bore_growth(fr) -> str:
    """The bore's growth over the outline in words (empty when there is none)."""
    return "" if fr.bore_offset < 1e-4 else f" + {fr.bore_offset * 1000:.3g} µm a side for the band's bulge"


def _title(ts) -> str:
    d = ts.spec.drawing
    return d.name or ts.tablet.name


def title_block(ts, sheet: str = "tablet") -> list[str]:
    """Title block lines: drawing number, revision, material, date, author and the tolerance note."""
    d = ts.spec.drawing
    number = d.number or "—"
    rows = [f"drawing no. {number}{'' if sheet == 'tablet' or not d.number else '-T'}   rev. {d.revision or '—'}   sheet: {sheet}",
            f"material: {d.material or '—'}", f"date: {d.date or '—'}   author: {d.author or '—'}",
            f"general tolerance ±{_fmt(d.tolerance_mm)} mm" + ("" if d.tolerance_given else
                                                             " (tabletcad default, not a standard's value)")]
    return rows


def _sheet_lines(dr: Drawing):
    for name, v in dr.views.items():
        ox, oy = dr.origins[name]
        for kind in ("visible", "hidden"):
            for p in v[kind]:
                yield kind, p + np.array([ox, oy])


def _dim_geometry(d: Dim):
    """``(a, b, extension lines)``: the dimension line from ``a`` to ``b`` (a radius: the leader, from
    the arc outwards) and the lines joining it to the measured points."""
    (x1, y1), (x2, y2) = d.p1, d.p2
    if d.radius:
        r = math.hypot(x2 - x1, y2 - y1)
        return (x2, y2), (x2 + d.offset * (x2 - x1) / r, y2 + d.offset * (y2 - y1) / r), []
    if d.vertical:
        x = max(x1, x2) + d.offset if d.offset > 0 else min(x1, x2) + d.offset
        return (x, y1), (x, y2), [((x1, y1), (x, y1)), ((x2, y2), (x, y2))]
    y = max(y1, y2) + d.offset if d.offset > 0 else min(y1, y2) + d.offset
    return (x1, y), (x2, y), [((x1, y1), (x1, y)), ((x2, y2), (x2, y))]


def _note_layout(notes: list[str], width_pt: float, height_pt: float, em: float = 0.62) -> tuple[float, int, list[str]]:
    """``(font size, columns, wrapped lines)`` that fit the notes into a ``width_pt`` x
    ``height_pt`` box (glyphs ``em`` wide on average: DejaVu Sans below 0.62 em; lines 1.35 em apart)."""
    import textwrap

    for fs in (7.0, 6.0, 5.0, 4.5):
        rows = max(1, int(height_pt // (1.4 * fs)))
        for ncols in (1, 2, 3, 4):
            chars = max(20, int((width_pt / ncols - 12.0) // (em * fs)))
            lines = [w for n in notes for w in (textwrap.wrap(n, chars) or [""])]
            if len(lines) <= rows * ncols:
                return fs, ncols, lines
    return fs, ncols, lines[: rows * ncols - 1] + [f"... ({len(lines) - rows * ncols + 1} more lines in report.json)"]


#: ISO 216 landscape sheets, inches (297 x 210, 420 x 297, 594 x 420 mm)
PAPER = {"A4": (11.69, 8.27), "A3": (16.54, 11.69), "A2": (23.39, 16.54)}


#: the title block's height, a fraction of the sheet's
_BLOCK = 0.2


def sheet_figure(dr: Drawing, paper: str = "A4"):
    """The landscape matplotlib figure of ``dr`` on ``paper``: the views above a title block that
    holds the notes (in two columns when long), both placed in sheet coordinates so that nothing
    runs past the sheet's edge whatever the tablet's size."""
    fig = _views_figure(dr, paper)
    _add_title_block(fig, dr, paper)
    return fig


def _smallest_views_figure(dr: Drawing):
    """:func:`_views_figure` on the smallest sheet that shows the views at 1:1 or larger (else the largest)."""
    for paper in PAPER:
        fig = _views_figure(dr, paper)
        if dr.scale >= 1.0 or paper == "A2":
            return fig


def _views_figure(dr: Drawing, paper: str):
    """The figure of ``dr``'s views and dimensions on ``paper`` (no title block yet); sets ``dr.paper``
    and ``dr.scale`` (paper mm per model mm, the views' limits fixed as a draw fixes them).  The
    dimension texts are placed once the scale is known (:func:`_place_dimension_texts`)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    w_in, h_in = PAPER[paper]
    fig = Figure(figsize=(w_in, h_in))
    FigureCanvasAgg(fig)  # its own canvas: the global backend is left alone
    dr.paper = paper
    ax = fig.add_axes((0.04, _BLOCK + 0.04, 0.92, 0.92 - _BLOCK - 0.04))
    # one collection per line style (a Line2D per edge cost 1-2 s to add and draw on a lettered tablet)
    lines = {"visible": [], "hidden": []}
    for kind, p in _sheet_lines(dr):
        lines[kind].append(p)
    # hidden lines under the visible ones (where a hidden line crosses a visible one, the visible is drawn)
    ax.add_collection(LineCollection(lines["hidden"], colors="0.4", linewidths=0.4, linestyles=[(0, (3, 2))]))
    ax.add_collection(LineCollection(lines["visible"], colors="k", linewidths=0.7))
    ext = [np.array(e, float) for d in dr.dims for e in _dim_geometry(d)[2]]
    ext_lines = ax.add_collection(LineCollection(ext, colors="0.3", linewidths=0.3, gid="dimension lines"))
    for d in dr.dims:
        a, b, _ = _dim_geometry(d)
        ax.annotate("", xy=a, xytext=b, arrowprops=dict(arrowstyle="-|>" if d.radius else "<|-|>", lw=0.4,
                                                        color="0.2", shrinkA=0, shrinkB=0,
                                                        mutation_scale=_ARROW_PT), gid="dimension line")
    labels = []
    for name, (ox, oy) in dr.origins.items():
        pts = np.concatenate([q for q in dr.views[name]["visible"]] or [np.zeros((1, 2))]) + np.array([ox, oy])
        ys = [pts[:, 1].min()]
        lo, hi = pts.min(axis=0) - 1e-6, pts.max(axis=0) + 1e-6
        for d in dr.dims:  # and under the dimension lines of this view (measured between its points)
            a, b, _ = _dim_geometry(d)
            if not d.vertical and all(np.all((lo <= q) & (q <= hi)) for q in (np.asarray(d.p1), np.asarray(d.p2))):
                ys.append(a[1] - 0.5)
        y = float(min(ys)) - 0.04 * float(np.ptp(pts[:, 1])) - 1.5  # under the view
        labels.append(ax.text(ox, y, name.upper(), fontsize=8, ha="center", va="top", gid="view label"))
        ax.update_datalim([(ox, y - 1.5)])  # keep the label inside the views' area
    ax.autoscale_view()
    ax.set_aspect("equal", adjustable="datalim")
    ax.margins(0.06)
    ax.axis("off")
    # fix the limits as drawing would (equal aspect: the data limits grow to the axes' shape), without
    # rendering the views: the scale is paper mm per model mm
    ax.apply_aspect()
    ax.set_autoscale_on(False)  # (the texts and leaders added below do not move the views)
    x0, x1 = ax.get_xlim()
    dr.scale = ax.get_window_extent().width / fig.dpi * 25.4 / (x1 - x0)
    leaders = _place_dimension_texts(ax, dr, lines["visible"] + lines["hidden"], ext, labels)
    ext_lines.set_segments(ext + leaders)  # and the leaders to texts set beyond an arrow
    return fig


#: the dimension arrows' size (points): heads 0.4 of it long and 0.2 of it to either side of the line
_ARROW_PT = 10.0
#: the gap (points) between a dimension's text and its line, and the room kept around every text
_TEXT_GAP_PT, _TEXT_ROOM_PT = 3.0, 1.0


def _place_dimension_texts(ax, dr: Drawing, view_lines: list, ext: list, labels: list) -> list[np.ndarray]:
    """Add every dimension's text to ``ax`` (limits fixed) where it meets no line of the views, no dimension
    line or arrow, no extension line and no other text, and return the leaders the placement needs.

    ISO 129 style: a linear dimension's text runs along its line, centred above it (right of a vertical
    one), else below (left of) it; a text longer than its line less its arrows goes beyond an arrow on the line's
    continuation (the leader returned), past either end, on either side.  A radius's text sits beyond its
    leader's end.  The first candidate that meets nothing is taken (else the one that meets the fewest
    lines and texts).  Earlier dimensions' texts and leaders are in the way of later ones.

    ``view_lines``: the views' polylines (sheet mm); ``ext``: the extension lines; ``labels``: the views'
    label texts.
    """
    renderer = ax.figure.canvas.get_renderer()
    to_data = ax.transData.inverted()
    mm_pt = 25.4 / 72.0 / dr.scale  # sheet (model) mm per point of paper
    gap, head_length = _TEXT_GAP_PT * mm_pt, 0.4 * _ARROW_PT * mm_pt
    lines = dict(views=_segments(view_lines), ext=_segments(ext),
                 arrows=_segments([np.array(_dim_geometry(d)[:2], float) for d in dr.dims]))
    boxes = [_data_box(t, renderer, to_data) for t in labels]
    leaders: list[np.ndarray] = []
    for d in dr.dims:
        t = ax.text(0.0, 0.0, d.text, fontsize=7, rotation=90 if d.vertical and not d.radius else 0, ha="center",
                    va="center", gid="dimension text")
        x0, y0, x1, y1 = _data_box(t, renderer, to_data)
        size = (x1 - x0, y1 - y0)
        best = None
        for centre, leader in _text_candidates(d, size, gap, head_length):
            box = (centre[0] - size[0] / 2, centre[1] - size[1] / 2, centre[0] + size[0] / 2, centre[1] + size[1] / 2)
            hits = _text_hits(box, leader, lines, boxes, leaders, mm_pt, (ax.get_xlim(), ax.get_ylim()))
            if best is None or hits < best[0]:
                best = (hits, centre, box, leader)
            if hits == 0:
                break
        _, centre, box, leader = best
        t.set_position(centre)
        boxes.append(box)
        if leader is not None:
            leaders.append(leader)
    return leaders


def _text_hits(box, leader, lines: dict, boxes: list, leaders: list, mm_pt: float, limits) -> int:
    """How many things a text at ``box`` (sheet mm) with its ``leader`` (or None) meets: the views' lines,
    extension lines, dimension lines with their arrows (``lines``: segments), the texts (``boxes``) and the
    leaders placed so far; 1000 more off the views' area ``limits`` (onto the title block or off the sheet)."""
    grown = _grow(box, _TEXT_ROOM_PT * mm_pt)
    head_width = 0.2 * _ARROW_PT * mm_pt  # to either side of the line: 2/3 of the gap
    hits = sum(int(np.count_nonzero(_meets_box(segs, grown))) for segs in (lines["views"], lines["ext"],
                                                                           _segments(leaders)))
    hits += int(np.count_nonzero(_meets_box(lines["arrows"], _grow(box, head_width))))
    hits += sum(_boxes_meet(grown, b) for b in boxes)
    if leader is not None:  # the leader must pass every text placed so far
        hits += sum(bool(_meets_box(_segments([leader]), _grow(b, _TEXT_ROOM_PT * mm_pt)).any()) for b in boxes)
    (x0, x1), (y0, y1) = limits
    return hits + (0 if x0 <= box[0] and box[2] <= x1 and y0 <= box[1] and box[3] <= y1 else 1000)


def _text_candidates(d: Dim, size: tuple[float, float], gap: float, head: float):
    """``(centre, leader or None)`` of the places for ``d``'s text of ``size`` (sheet mm, x and y), best first
    (see :func:`_place_dimension_texts`); ``gap`` from the line, ``head`` the arrows' length (sheet mm): a
    text centred on its line runs between the arrows."""
    a, b, _ = _dim_geometry(d)
    if d.radius:  # beyond the leader's end, on the side it points to
        sx = 1.0 if b[0] >= a[0] else -1.0
        sy = 1.0 if b[1] >= a[1] else -1.0
        yield (b[0] + sx * (gap + size[0] / 2), b[1] + sy * (gap + size[1] / 2)), None
        return
    k = 1 if d.vertical else 0  # the axis the dimension line runs along
    lo, hi = sorted((a[k], b[k]))
    at = a[1 - k]  # the line's place across
    along, across = size[k], size[1 - k]

    def place(s: float, side: float):
        c = [0.0, 0.0]
        c[k], c[1 - k] = s, at + side * (gap + across / 2)
        return tuple(c)

    def leader(s0: float, s1: float):
        p = np.zeros((2, 2))
        p[:, k], p[:, 1 - k] = (s0, s1), at
        return p

    if along + 2.0 * head <= hi - lo:  # the text fits between the arrows: centred, above (right) or below (left)
        for side in (1.0, -1.0):
            yield place(0.5 * (lo + hi), side), None
    for side in (1.0, -1.0):  # beyond an arrow, on the line's continuation
        yield place(hi + gap + along / 2, side), leader(hi, hi + gap + along)
        yield place(lo - gap - along / 2, side), leader(lo, lo - gap - along)


def _data_box(t, renderer, to_data) -> tuple[float, float, float, float]:
    """The box ``(x0, y0, x1, y1)`` (sheet mm) text ``t`` covers."""
    bb = t.get_window_extent(renderer)
    (x0, y0), (x1, y1) = to_data.transform([(bb.x0, bb.y0), (bb.x1, bb.y1)])
    return min(x0, x1), min(y0, y1), max(x0, x1), max(y0, y1)


def _grow(box, by: float) -> tuple[float, float, float, float]:
    return box[0] - by, box[1] - by, box[2] + by, box[3] + by


def _boxes_meet(a, b) -> bool:
    return a[0] <= b[2] and b[0] <= a[2] and a[1] <= b[3] and b[1] <= a[3]


def _segments(polylines: list) -> np.ndarray:
    """The segments ``(n, 2, 2)`` of ``polylines``."""
    segs = [np.stack([p[:-1], p[1:]], axis=1) for p in map(np.asarray, polylines) if len(p) >= 2]
    return np.concatenate(segs) if segs else np.zeros((0, 2, 2))


def _meets_box(segs: np.ndarray, box) -> np.ndarray:
    """Which of the segments ``segs`` ``(n, 2, 2)`` meet the box ``(x0, y0, x1, y1)`` (touching counts):
    Liang-Barsky clipping of each against the box."""
    segs = np.asarray(segs, float).reshape(-1, 2, 2)
    p, d = segs[:, 0], segs[:, 1] - segs[:, 0]
    t0, t1 = np.zeros(len(segs)), np.ones(len(segs))
    ok = np.ones(len(segs), bool)
    for k, lo, hi in ((0, box[0], box[2]), (1, box[1], box[3])):
        for q, r in ((-d[:, k], p[:, k] - lo), (d[:, k], hi - p[:, k])):
            par = q == 0.0
            ok &= ~(par & (r < 0.0))
            with np.errstate(divide="ignore", invalid="ignore"):
                u = np.where(par, 0.0, r / np.where(par, 1.0, q))
            t0 = np.where(~par & (q < 0.0), np.maximum(t0, u), t0)
            t1 = np.where(~par & (q > 0.0), np.minimum(t1, u), t1)
    return ok & (t0 <= t1)



def _add_title_block(fig, dr: Drawing, paper: str) -> None:
    """The title block under the views of ``fig`` (from :func:`_views_figure`): frame, title, the title
    block's lines with the scale and paper, the notes in as many columns as they need."""
    import matplotlib.patches

    w_in, h_in = PAPER[paper]
    block, scale = _BLOCK, dr.scale
    fig.add_artist(matplotlib.patches.Rectangle((0.04, 0.03), 0.92, block - 0.01, transform=fig.transFigure,
                                                fill=False, lw=0.6, ec="0.2"))
    title = fig.text(0.05, 0.03 + block - 0.025, dr.title, fontsize=10, ha="left", va="top", weight="bold")
    tb = list(dr.title_block) + [f"scale {_scale_text(scale)}   sheet {paper}   mm   third-angle projection"]
    right = fig.text(0.95, 0.03 + block - 0.02, "\n".join(tb), fontsize=6.5, ha="right", va="top",
                     family="DejaVu Sans", linespacing=1.35)
    renderer = fig.canvas.get_renderer()  # long texts (up to spec.TITLE_MAX_CHARS) in smaller type, down to 4 pt:
    while right.get_window_extent(renderer).width > 0.45 * fig.bbox.width and right.get_fontsize() > 4.0:
        right.set_fontsize(right.get_fontsize() - 0.25)  # the block within the right 45 % of the sheet
    room = right.get_window_extent(renderer).x0 - 0.01 * fig.bbox.width  # the title ends left of the block
    while title.get_window_extent(renderer).x1 > room and title.get_fontsize() > 4.0:
        title.set_fontsize(title.get_fontsize() - 0.5)
    text = dr.title
    while title.get_window_extent(renderer).x1 > room and len(text) > 1:  # a tablet name of up to 200 characters
        text = text[:-1]  # (the drawing's own name is at most 60): cut, with an ellipsis
        title.set_text(text.rstrip() + "…")
    for em in (0.62, 1.0):  # DejaVu Sans averages below 0.62 em; a name of wide letters (W) needs up to 1 em
        fs, ncols, lines = _note_layout(list(dr.notes), 0.9 * w_in * 72.0,
                                        (block - 0.07 - 0.012 * len(tb)) * h_in * 72.0, em=em)
        rows = -(-len(lines) // ncols)
        cols = [fig.text(0.05 + 0.9 * c / ncols, 0.03 + block - 0.055 - 0.012 * len(tb),
                         "\n".join(lines[c * rows:(c + 1) * rows]), fontsize=fs, ha="left", va="top",
                         family="DejaVu Sans", linespacing=1.35) for c in range(ncols)]
        if em == 1.0 or all(t.get_window_extent(renderer).width < (0.9 / ncols - 0.01) * fig.bbox.width for t in cols):
            break
        for t in cols:  # a column ran into the next: again, wrapped for wider letters
            t.remove()


def _scale_text(scale: float) -> str:
    return f"{scale:.3g}:1" if scale >= 1 else f"1:{1 / scale:.3g}"


def _write_matplotlib(dr: Drawing, svg: Path, pdf: Path) -> None:
    import matplotlib

    # TrueType (Type 42) fonts in the PDF: its text is text a reader can search and copy, and
    # PDF/A and print workflows accept it (Type 3 fonts are glyph drawings)
    # (save_figure: the SVG's element ids hashed with a fixed salt, both files dated by stamp_time())
    with matplotlib.rc_context({"svg.fonttype": "none", "pdf.fonttype": 42}):
        fig = _smallest_views_figure(dr)
        _add_title_block(fig, dr, dr.paper)  # (on the sheet kept only)
        save_figure(fig, svg, fmt="svg")
        save_figure(fig, pdf, fmt="pdf")


def _exact_entities(wire, origin: tuple[float, float]) -> list[tuple[str, dict]]:
    """``(kind, attributes)`` of DXF entities for the edges of a plan wire moved by ``origin``: a line's
    LINE, a circle's CIRCLE (whole) or ARC (counter-clockwise from ``start_angle`` to ``end_angle``, degrees),
    an ellipse's ELLIPSE, a B-spline's SPLINE (:func:`_spline_entity`: its own degree, knots and poles),
    anything else a polyline through points 0.002 mm from it."""
    from OCP.GeomAbs import GeomAbs_CurveType

    ox, oy = origin
    out = []
    for e in explore(wire, "Edge"):
        c = BRepAdaptor_Curve(e)
        t0, t1 = c.FirstParameter(), c.LastParameter()
        kind = c.GetType()
        a, b = c.Value(t0), c.Value(t1)
        if kind == GeomAbs_CurveType.GeomAbs_Line:
            out.append(("LINE", dict(start=(a.X() + ox, a.Y() + oy), end=(b.X() + ox, b.Y() + oy))))
        elif kind == GeomAbs_CurveType.GeomAbs_Circle:
            circ = c.Circle()
            ctr, r = circ.Location(), circ.Radius()
            centre = (ctr.X() + ox, ctr.Y() + oy)
            if abs(t1 - t0 - 2.0 * math.pi) < 1e-12:
                out.append(("CIRCLE", dict(center=centre, radius=r)))
                continue
            ang = [math.degrees(math.atan2(p.Y() - ctr.Y(), p.X() - ctr.X())) for p in (a, b)]
            if circ.Axis().Direction().Z() < 0.0:  # the parameter runs clockwise seen from +z
                ang.reverse()
            out.append(("ARC", dict(center=centre, radius=r, start_angle=ang[0], end_angle=ang[1])))
        elif kind == GeomAbs_CurveType.GeomAbs_Ellipse and abs(t1 - t0 - 2.0 * math.pi) < 1e-12:
            el = c.Ellipse()
            ctr, major = el.Location(), el.XAxis().Direction()
            R = el.MajorRadius()
            out.append(("ELLIPSE", dict(center=(ctr.X() + ox, ctr.Y() + oy), major_axis=(R * major.X(), R * major.Y()),
                                        ratio=el.MinorRadius() / R)))
        elif kind == GeomAbs_CurveType.GeomAbs_BSplineCurve:
            out.append(("SPLINE", _spline_entity(c.BSpline(), t0, t1, origin)))
        else:
            d = GCPnts_TangentialDeflection(c, 0.05, 0.002)
            out.append(("POLYLINE", dict(points=[(d.Value(i).X() + ox, d.Value(i).Y() + oy)
                                                 for i in range(1, d.NbPoints() + 1)])))
    return out


def _spline_entity(curve, t0: float, t1: float, origin: tuple[float, float]) -> dict:
    """A DXF SPLINE's data of the OCC B-spline ``curve`` (``Geom_BSplineCurve``, plan, mm) between its
    parameters ``t0`` and ``t1``, moved by ``origin``: ``degree``, ``control_points`` (x, y), ``knots``
    (count = control points + degree + 1, the curve's own parameter), ``weights`` (empty unless rational)
    and ``closed``.

    A periodic curve over its whole period is written as AutoCAD and ezdxf write a closed spline (flags
    CLOSED and PERIODIC): its poles followed by its first ``degree`` poles again, its knots the periodic
    extension of its flat knots, the curve the standard B-spline over ``[knots[degree],
    knots[-degree-1]]`` = its first knot and a period on (the whole closed curve, whichever its start).  Any other B-spline (or part of one) is written clamped:
    OCC's own non-periodic form of the part, its ends at its first and last control points.
    """
    p = curve.Degree()
    whole = curve.IsPeriodic() and abs(t1 - t0 - curve.Period()) < 1e-12 * max(1.0, curve.Period())
    if whole:
        knots = _periodic_flat_knots(curve)
        poles = list(range(1, curve.NbPoles() + 1))
        poles += poles[:p]
    else:
        curve = curve.Copy()
        if curve.IsPeriodic() or t0 > curve.FirstParameter() or t1 < curve.LastParameter():
            curve.Segment(t0, t1)  # (on a periodic curve, across its period's end too)
        if curve.IsPeriodic():
            curve.SetNotPeriodic()
        seq = curve.KnotSequence()
        knots = [seq.Value(i) for i in range(seq.Lower(), seq.Upper() + 1)]
        poles = list(range(1, curve.NbPoles() + 1))
    ox, oy = origin
    pts = [curve.Pole(i) for i in poles]
    return dict(degree=p, control_points=[(q.X() + ox, q.Y() + oy) for q in pts], knots=knots,
                weights=[curve.Weight(i) for i in poles] if curve.IsRational() else [], closed=whole)


def _periodic_flat_knots(curve) -> list[float]:
    """The ``NbPoles + 2 Degree + 1`` flat knots of the periodic ``curve`` (``Geom_BSplineCurve``) as an
    unperiodic B-spline over its poles followed by its first ``Degree`` poles: the periodic extension
    of its knots (each repeated by its multiplicity) from ``Degree`` before the last copy of its first knot.

    (OCC's first pole is the coefficient of the basis function starting there: on a periodic curve's first
    span the poles 1 to ``Degree + 1`` act, as for ``tabletcad.tooling.outline._periodic_bspline_edge``.)
    """
    p, n, L = curve.Degree(), curve.NbPoles(), curve.Period()
    one = [curve.Knot(i) for i in range(1, curve.NbKnots()) for _ in range(curve.Multiplicity(i))]  # n of them
    start = curve.Multiplicity(1) - 1 - p
    return [one[j % n] + L * (j // n) for j in range(start, start + n + 2 * p + 1)]


def _write_dxf(dr: Drawing, path: Path) -> None:
    import ezdxf

    doc = ezdxf.new("R2010", setup=True, units=4)  # 4 = millimetres
    # ezdxf's EZDXF style measures in centimetres of metre drawing units (DIMLFAC 100): here 1 unit is 1 mm,
    # so a reader that recomputes a measurement gets the model's millimetres (a detail's over its scale)
    doc.dimstyles.get("EZDXF").dxf.dimlfac = 1.0
    doc.header["$DIMLFAC"] = 1.0  # and the drawing's own default, which a dimension added in a CAD program takes
    doc.layers.add("VISIBLE", color=7)
    doc.layers.add("HIDDEN", color=8, linetype="DASHED")
    doc.layers.add("DIMENSIONS", color=1)
    doc.layers.add("NOTES", color=3)
    doc.layers.add("OUTLINE", color=5)
    msp = doc.modelspace()
    for wire, origin in dr.exact:
        for kind, at in _exact_entities(wire, origin):
            attribs = {"layer": "OUTLINE"}
            if kind == "LINE":
                msp.add_line(at["start"], at["end"], dxfattribs=attribs)
            elif kind == "CIRCLE":
                msp.add_circle(at["center"], at["radius"], dxfattribs=attribs)
            elif kind == "ARC":
                msp.add_arc(at["center"], at["radius"], at["start_angle"], at["end_angle"], dxfattribs=attribs)
            elif kind == "ELLIPSE":
                msp.add_ellipse(at["center"], at["major_axis"], at["ratio"], dxfattribs=attribs)
            elif kind == "SPLINE":
                _add_spline(msp, at, attribs)
            else:
                msp.add_lwpolyline(at["points"], dxfattribs=attribs)
    for kind, p in _sheet_lines(dr):
        msp.add_lwpolyline([tuple(map(float, q)) for q in p], dxfattribs={"layer": kind.upper()})
    for d in dr.dims:
        a, b, _ = _dim_geometry(d)
        if d.radius:
            (cx, cy), (px, py) = d.p1, d.p2
            dim = msp.add_radius_dim(center=(cx, cy), radius=math.hypot(px - cx, py - cy),
                                     angle=math.degrees(math.atan2(py - cy, px - cx)), text=d.text,
                                     dimstyle="EZDXF", dxfattribs={"layer": "DIMENSIONS"})
            dim.render()
            continue
        base = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)
        dim = msp.add_linear_dim(base=base, p1=d.p1, p2=d.p2, angle=90 if d.vertical else 0, text=d.text,
                                 dimstyle="EZDXF", dxfattribs={"layer": "DIMENSIONS"},
                                 override={"dimlfac": 1.0 / d.scale} if d.scale != 1.0 else None)
        dim.render()
    xs = [float(q[0]) for _, p in _sheet_lines(dr) for q in p]
    ys = [float(q[1]) for _, p in _sheet_lines(dr) for q in p]
    msp.add_mtext("\\P".join([dr.title, *dr.title_block, *dr.notes]), dxfattribs={"layer": "NOTES", "char_height": 0.8}).set_location((max(xs) + 8, max(ys)))
    _save_dxf(doc, path)


def _add_spline(msp, at: dict, attribs: dict) -> None:
    """A SPLINE entity of :func:`_spline_entity`'s data ``at`` in the modelspace ``msp``: control points,
    knots and weights as given (no fit points), flags CLOSED and PERIODIC for a closed one (as ezdxf's
    ``Spline.set_closed`` and AutoCAD write a closed spline), RATIONAL with weights."""
    from ezdxf.entities import Spline

    s = msp.add_spline(degree=at["degree"], dxfattribs=attribs)
    s.control_points = at["control_points"]
    s.knots = at["knots"]
    if at["weights"]:
        s.weights = at["weights"]
    s.dxf.flags = ((Spline.CLOSED | Spline.PERIODIC) if at["closed"] else 0) | (Spline.RATIONAL if at["weights"] else 0)


# stand-ins written where the header's GUIDs go, then replaced by GUIDs of the file's content
_FINGERPRINT_MARK = "{00000000-0000-0000-0000-0000000000F1}"
_VERSION_MARK = "{00000000-0000-0000-0000-0000000000F2}"


def _save_dxf(doc, path: Path) -> None:
    """Write the ezdxf document ``doc`` atomically to ``path``, as ``doc.saveas`` does, but reproducibly.

    ezdxf stamps the local time of writing into the header ($TDCREATE, $TDUPDATE) and its own
    marker, and a random $FINGERPRINTGUID and $VERSIONGUID: here every date is
    :func:`~tabletcad.io.timestamp.stamp_time` (UTC; ``SOURCE_DATE_EPOCH`` when set) and both GUIDs
    are derived from the rest of the file, so the same drawing gives the same bytes and a changed one
    new GUIDs; its CLASS section is in an order of names.  (ezdxf sets these in
    ``Drawing._update_metadata`` on every write; its public ``options.write_fixed_meta_data_for_testing``
    dates every file 2000-01-01 instead.)
    """
    import io

    import ezdxf
    from ezdxf.tools.juliandate import juliandate

    when = stamp_time()
    update = doc._update_metadata

    def stamped() -> None:
        update()
        day = juliandate(when.replace(tzinfo=None))
        for var in ("$TDCREATE", "$TDUCREATE", "$TDUPDATE", "$TDUUPDATE"):
            doc.header[var] = day
        doc.header["$FINGERPRINTGUID"], doc.header["$VERSIONGUID"] = _FINGERPRINT_MARK, _VERSION_MARK
        meta = doc.ezdxf_metadata()
        for key in ("CREATED_BY_EZDXF", "WRITTEN_BY_EZDXF"):
            meta[key] = f"{ezdxf.__version__} @ {when.isoformat()}"

    doc._update_metadata = stamped
    # ezdxf declares a CLASS for each entity type in use in the order of a set of strings, which
    # Python's per-process hash salt shuffles (LAYOUT and ACDBPLACEHOLDER swapped from one build to
    # the next): declared here first, by name; ezdxf then finds them declared
    doc.commit_pending_changes()
    for dxftype in sorted(doc.entitydb.dxf_types_in_use()):
        doc.classes.add_class(dxftype)
    stream = io.StringIO()
    doc.write(stream)
    text = stream.getvalue()
    for mark, role in ((_FINGERPRINT_MARK, "fingerprint"), (_VERSION_MARK, "version")):
        text = text.replace(mark, "{" + str(content_uuid("tabletcad DXF " + role, text)).upper() + "}", 1)
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding=doc.output_encoding, errors="dxfreplace") as fh:
            fh.write(text)


def write_drawing(ts, out_dir) -> list[Path]:
    """``drawing.svg``, ``drawing.pdf`` and ``drawing.dxf`` of the tool set's tablet in ``out_dir``."""
    out_dir = Path(out_dir)
    dr = drawing_model(ts)
    svg, pdf, dxf = out_dir / "drawing.svg", out_dir / "drawing.pdf", out_dir / "drawing.dxf"
    _write_matplotlib(dr, svg, pdf)
    _write_dxf(dr, dxf)
    ts.report["drawing"] = dict(views=list(dr.views), dimension_texts=[d.text for d in dr.dims], notes=dr.notes,
                                title=dr.title, title_block=dr.title_block, scale=dr.scale, paper=dr.paper,
                                visible_polylines={k: len(v["visible"]) for k, v in dr.views.items()})
    files = [svg, pdf, dxf]
    # complete punches and die, or the tips and die (a toolmaker's trial: tips-only tooling had no sheet)
    tr = tooling_model(ts) if ts.spec.body is not None else tips_model(ts)
    files += [out_dir / "tooling.svg", out_dir / "tooling.pdf", out_dir / "tooling.dxf"]
    _write_matplotlib(tr, files[3], files[4])
    _write_dxf(tr, files[5])
    ts.report["tooling_drawing"] = dict(views=list(tr.views), dimension_texts=[d.text for d in tr.dims],
                                        notes=tr.notes, scale=tr.scale, paper=tr.paper)
    return files


def _die_dims(die: dict, origin: tuple[float, float], tol) -> list[Dim]:
    """The die's outer diameter and height dimensions on its front view at ``origin``."""
    ox, oy = origin
    R = 0.5 * die["outer_diameter_mm"]
    zb, zt = oy + die["bottom_z_mm"], oy + die["top_z_mm"]
    return [Dim((ox - R, zt), (ox + R, zt), 4.0, f"Ø{_fmt(die['outer_diameter_mm'])} {tol('die_diameter')}"),
            Dim((ox + R, zb), (ox + R, zt), 3.0, f"H {_fmt(die['height_mm'])} {tol('die_height')}", vertical=True)]


def _die_note(die: dict, fr, tol) -> str:
    """The die's note: its size, the toleranced bore (the tablet's outline, grown by a band's bulge), the taper."""
    return (f"die Ø{_fmt(die['outer_diameter_mm'])} x {_fmt(die['height_mm'])}, bore {_plan_size(fr, -fr.bore_offset)} "
            f"{tol('bore_diameter')} (the tablet's {die['bore']} outline{_bore_growth(fr)}), taper {die['taper_deg']:g} deg")


def tips_model(ts) -> Drawing:
    """Front elevations of the upper and lower punch tips and the die (closed position, side by side), for
    tooling without complete punches: each tip's length, the die's diameter and height dimensioned, and the
    fit (tips, bore, clearance, taper) and the cups as the tips carry them in the notes."""
    rep = ts.report
    up, lo, die = rep["upper_punch"], rep["lower_punch"], rep["die"]
    fr = ts.frame
    views = {k.replace("_", " "): project_view(ts.parts[k], "front") for k in ("upper_punch", "lower_punch", "die")}
    wt = max(fr.length, fr.width)
    gap = 0.5 * wt + 0.5 * die["outer_diameter_mm"] + 20.0
    origins = {"upper punch": (0.0, 0.0), "lower punch": (wt + 20.0, 0.0), "die": (wt + 20.0 + gap, 0.0)}
    tol = ts.spec.drawing.tolerance_text
    dims: list[Dim] = []
    for name, tip, sgn in (("upper punch", up, 1.0), ("lower punch", lo, -1.0)):
        ox, oy = origins[name]
        z0 = oy + tip["tip_edge_z_mm"]
        z1 = z0 + sgn * tip["tip_length_mm"]
        dims.append(Dim((ox + 0.5 * wt, min(z0, z1)), (ox + 0.5 * wt, max(z0, z1)), 3.0,
                        f"tip {_fmt(tip['tip_length_mm'])} {tol('tip_length')}", vertical=True))
    dims += _die_dims(die, origins["die"], tol)
    notes = [f"{ts.tablet.name}: punch tips and die (no punch bodies: the tips fit the toolmaker's punches)"
             + (f", die TSM {die['tsm_size']}" if die.get("tsm_size") not in (None, "custom") else ""),
             f"tips {_plan_size(fr, fr.tip_inset(ts.spec.clearance_mm))} {tol('tip_diameter')} ({up['tip_outline']}; the "
             f"bore less the clearance {_fmt(ts.spec.clearance_mm)} per side{_fit_range(ts.spec)}); upper tip "
             f"{_fmt(up['tip_length_mm'])}, lower tip {_fmt(lo['tip_length_mm'])} from the tip edge",
             f"cups on the tips: upper {_fmt(up['cup_depth_on_tip_mm'])}, lower {_fmt(lo['cup_depth_on_tip_mm'])} deep "
             "from the tip edge (the tablet's face, as on the tablet's sheet)",
             f"{_die_note(die, fr, tol)}, upper punch entry {_fmt(die['punch_entry_mm'])} at the closed position"]
    notes += rating_notes(rep.get("tip_rating") or {}) + fit_notes(ts.spec)
    return Drawing(views, origins, dims, notes, title=f"{_title(ts)} — punch tips and die",
                   title_block=title_block(ts, "punch tips and die"))


def tooling_model(ts) -> Drawing:
    """Front elevations of the upper punch, lower punch and die (closed position, side by side)."""
    rep = ts.report
    up, lo, die = rep["upper_punch"]["body"], rep["lower_punch"]["body"], rep["die"]
    fr = ts.frame
    views = {k.replace("_", " "): project_view(ts.parts[k], "front") for k in ("upper_punch", "lower_punch", "die")}
    Dh = max(up["head_diameter_mm"], up["barrel_diameter_mm"])
    gap = 0.5 * Dh + 0.5 * die["outer_diameter_mm"] + 25.0
    # side by side: upper punch, lower punch, die; lower punch and die lifted so all start near y = 0
    origins = {"upper punch": (0.0, -fr.band_z[1]), "lower punch": (Dh + 25.0, lo["overall_length_mm"] - fr.band_z[0]),
               "die": (Dh + 25.0 + gap, -die["bottom_z_mm"])}
    dims: list[Dim] = []
    tol = ts.spec.drawing.tolerance_text
    for name, b, edge, sgn in (("upper punch", up, rep["upper_punch"]["tip_edge_z_mm"], 1.0),
                               ("lower punch", lo, rep["lower_punch"]["tip_edge_z_mm"], -1.0)):
        ox, oy = origins[name]
        z_tip, z_head = oy + edge, oy + b["head_flat_z_mm"]
        z_shoulder = z_tip + sgn * b["tip_length_mm"]
        rb, rh = 0.5 * b["barrel_diameter_mm"], 0.5 * b["head_diameter_mm"]
        dims.append(Dim((ox - rh, min(z_tip, z_head)), (ox - rh, max(z_tip, z_head)), -4.0,
                        f"overall {_fmt(b['overall_length_mm'])} {tol('overall_length')}", vertical=True))
        dims.append(Dim((ox + rb, min(z_tip, z_shoulder)), (ox + rb, max(z_tip, z_shoulder)), 3.0,
                        f"tip {_fmt(b['tip_length_mm'])} {tol('tip_length')}", vertical=True))
        zb = z_shoulder + sgn * 0.5 * b["barrel_length_mm"]
        dims.append(Dim((ox - rb, zb), (ox + rb, zb), 0.0,
                        f"Ø{_fmt(b['barrel_diameter_mm'])} {tol('barrel_diameter')}"))
        zh = z_head - sgn * 0.5 * b["head_height_mm"]
        dims.append(Dim((ox - rh, zh), (ox + rh, zh), sgn * (b["head_height_mm"] + 3.0),
                        f"Ø{_fmt(b['head_diameter_mm'])} {tol('head_diameter')}"))
    dims += _die_dims(die, origins["die"], tol)
    mod = up.get("modified_from_standard") or {}
    changed = "; ".join(f"{k.replace('_mm', '').replace('_deg', '').replace('_', ' ')} {_fmt(v['given'])} "
                        f"(standard {_fmt(v['standard'])})" for k, v in mod.items())
    notes = [f"{ts.tablet.name}: {up['standard']} {up['type'] or 'user-defined'} tooling"
             f"{', MODIFIED' if mod else ''}, {up['head']} heads" + (f"; modified: {changed}" if mod else ""),
             f"barrel Ø{_fmt(up['barrel_diameter_mm'])}, neck Ø{_fmt(up['neck_diameter_mm'])} x {_fmt(up['neck_length_mm'])}, "
             f"head Ø{_fmt(up['head_diameter_mm'])} (flat Ø{_fmt(up['head_flat_diameter_mm'])}), rim "
             f"{_fmt(up['head_rim_mm'])}, inside head angle {up['inside_head_angle_deg']:g} deg, "
             + (f"top angle {up['head_top_angle_deg']:g} deg" if up["head"] == "angled"
                else f"dome R{_fmt(up['dome_radius_mm'])}") + f", head height {_fmt(up['head_height_mm'])}",
             f"tip: straight {_fmt(up['tip_straight_mm'])}, relief {_fmt(up['tip_relief_mm'])} per side; "
             f"upper tip {_fmt(up['tip_length_mm'])}, lower tip {_fmt(lo['tip_length_mm'])}",
             f"working length (head flat to cup bottom): upper {_fmt(up['working_length_mm'])}, lower "
             f"{_fmt(lo['working_length_mm'])} {tol('working_length')}",
             f"{_die_note(die, fr, tol)}; tips {_plan_size(fr, fr.tip_inset(ts.spec.clearance_mm))} {tol('tip_diameter')} (the bore less the "
             f"clearance {_fmt(ts.spec.clearance_mm)} per side{_fit_range(ts.spec)})",
             ("standard dimensions: tabletcad/data/tooling_standards.toml (sources per value in report.json)"
              + (", but for the modified ones above (from [tooling.punch])" if mod else ""))
             if up["standard"] != "custom" else "user-defined set: every dimension from [tooling.punch]"]
    notes += rating_notes(ts.report.get("tip_rating") or {}) + fit_notes(ts.spec)  # (a toolmaker's trial: on the
    # tablet's sheet only; a 0.2 mm clearance's warning reached stderr, not the sheets)
    body = ts.spec.body
    if body is not None and body.key:  # (a toolmaker's trial: the keyway could not be made from the drawing)
        notes.append(f"key {_fmt(body.key_width_mm)} wide x {_fmt(body.key_length_mm)} long x {_fmt(body.key_height_mm)} "
                     f"proud, {_fmt(body.key_offset_mm)} up the barrel from the tip's back face, at "
                     f"{body.key_angle_deg:g} deg to +x")
    return Drawing(views, origins, dims, notes, title=f"{_title(ts)} — punches and die",
                   title_block=title_block(ts, "punches and die"))
