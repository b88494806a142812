"""The scored tablet split along its score planes: the parts' volumes and masses, the break surface.

A bisect score breaks the tablet along the vertical plane through the axis that contains
the groove's centre line (``direction_deg``); a quadrisect along that plane and the one at
90 degrees.  The parts are the cells of the tablet split by those planes (one exact OCC
splitter, ``BRepAlgoAPI_Splitter``; each part's cell found by the sector its centroid lies in),
the break surface the cells' faces on the planes (its area counted once per plane).  Masses are volume × solid fraction × true density when the
design's ``[report]`` table gives both.

The FDA guidance *Tablet Scoring: Nomenclature, Labeling, and Data for Evaluation* (2013)
asks that the loss of mass on splitting be below 3.0 % between the split portions and the
whole tablet — a measured figure.  The geometric screen here reports how far each part's
nominal mass is from its equal share, in percent, next to that 3.0 %: a design whose parts
differ by more cannot meet it.
"""

from __future__ import annotations

import math

from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
from OCP.gp import gp_Pnt

from tabletcad.cad._occ import explore
from tabletcad.errors import GeometryError
from tabletcad.tooling.booleans import split_solid, volume_centroid
from tabletcad.tooling.outline import TabletFrame, face_area

__all__ = ["split_directions", "split_parts", "SPLIT_LOSS_LIMIT_PERCENT", "SPLIT_LOSS_SOURCE"]

#: FDA guidance for industry, Tablet Scoring: Nomenclature, Labeling, and Data for Evaluation (March 2013)
SPLIT_LOSS_LIMIT_PERCENT = 3.0
SPLIT_LOSS_SOURCE = ("FDA Guidance for Industry 'Tablet Scoring: Nomenclature, Labeling, and Data for Evaluation' "
                     "(2013): loss of mass on splitting < 3.0 % (summarised at https://excel-in-science.com/learnexcel/"
                     "tablet-scoring-guidance-for-pharmaceutical-analysis)")


def split_directions(scores) -> list[float]:
    """The distinct break-plane directions (degrees in [0, 180)) of the scores.  A short score
    (``length_mm`` given) ends on the face: it is decorative and breaks nothing."""
    out: list[float] = []
    for s in scores:
        if s.length_mm is not None:
            continue
        for d in ((s.direction_deg,) if s.kind == "bisect" else (s.direction_deg, s.direction_deg + 90.0)):
            d = d % 180.0
            if all(min(abs(d - e), 180.0 - abs(d - e)) > 1e-9 for e in out):
                out.append(d)
    return sorted(out)


def _polygon_wire(points):
    poly = BRepBuilderAPI_MakePolygon()
    for p in points:
        poly.Add(gp_Pnt(*p))
    poly.Close()
    return poly.Wire()


def _on_a_plane(face, normals, tol: float = 1e-7) -> bool:
    """Whether ``face`` is planar and lies in one of the vertical planes through the axis with plan ``normals``."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.GeomAbs import GeomAbs_SurfaceType

    surf = BRepAdaptor_Surface(face)
    if surf.GetType() != GeomAbs_SurfaceType.GeomAbs_Plane:
        return False
    pl = surf.Plane()
    n, o = pl.Axis().Direction(), pl.Location()
    return any(abs(abs(n.X() * a + n.Y() * b) - 1.0) < tol and abs(n.Z()) < tol and abs(o.X() * a + o.Y() * b) < tol
               for a, b in normals)


def split_parts(frame: TabletFrame, solid, scores, *, density_mg_mm3: float | None = None) -> dict | None:
    """Parts and break surface of ``solid`` split along the score planes (see the module docstring)."""
    dirs = split_directions(scores)
    if not dirs:
        return None
    R = 2.0 * max(frame.length, frame.width) + 2.0
    z0, z1 = frame.z_min - 1.0, frame.z_max + 1.0
    rays = sorted({(d + k * 180.0) % 360.0 for d in dirs for k in (0, 1)})
    planes = []
    for d in dirs:
        c, s = math.cos(math.radians(d)), math.sin(math.radians(d))
        planes.append(BRepBuilderAPI_MakeFace(_polygon_wire([(-R * c, -R * s, z0), (R * c, R * s, z0), (R * c, R * s, z1),
                                                             (-R * c, -R * s, z1)]), True).Face())
    # one splitter: the tablet cut by every plane at once (the cells between the planes are the parts,
    # the cells' faces on the planes the break surface)
    cells = split_solid(solid, planes, what="split parts")
    parts = [dict(from_deg=a, to_deg=rays[(k + 1) % len(rays)], volume_mm3=0.0, cells=0) for k, a in enumerate(rays)]
    for cell in cells:
        # a part lies in a convex sector (at most 180 degrees): its centroid is inside it
        vol, (cx, cy, _) = volume_centroid(cell)
        ang = math.degrees(math.atan2(cy, cx)) % 360.0
        k = max(j for j, a in enumerate(rays) if a <= ang) if ang >= rays[0] else len(rays) - 1
        parts[k]["volume_mm3"] += vol
        parts[k]["cells"] += 1
    if any(p["cells"] != 1 for p in parts):
        raise GeometryError(f"splitting the tablet along its scores gave {[p['cells'] for p in parts]} pieces per part, "
                            "expected one each", solid)
    for p in parts:
        del p["cells"]
    total = sum(p["volume_mm3"] for p in parts)
    share = total / len(parts)
    for p in parts:
        p["deviation_from_equal_share_percent"] = 100.0 * (p["volume_mm3"] / share - 1.0)
        p["mass_mg"] = None if density_mg_mm3 is None else p["volume_mm3"] * density_mg_mm3
    area = 0.0
    normals = [(-math.sin(math.radians(d)), math.cos(math.radians(d))) for d in dirs]
    seen: list = []
    for cell in cells:
        for f in explore(cell, "Face"):
            if any(f.IsSame(g) for g in seen):
                continue
            seen.append(f)
            if _on_a_plane(f, normals):
                area += face_area(f)
    worst = max(abs(p["deviation_from_equal_share_percent"]) for p in parts)
    return dict(directions_deg=dirs, parts=parts, n_parts=len(parts), volume_mm3=total,
                break_surface_area_mm2=area, density_mg_mm3=density_mg_mm3,
                max_deviation_from_equal_share_percent=worst,
                split_loss_limit_percent=SPLIT_LOSS_LIMIT_PERCENT, split_loss_limit_source=SPLIT_LOSS_SOURCE,
                within_limit=worst < SPLIT_LOSS_LIMIT_PERCENT,
                note="geometric screen: the parts' nominal share of the tablet against the limit on the measured "
                     "loss of mass on splitting")
