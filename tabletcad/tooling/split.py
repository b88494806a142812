"""The scored tablet split along its score planes: the parts' volumes and masses, the break surface.

A bisect score breaks the tablet along the vertical plane through the axis that contains
the groove's centre line (``direction_deg``); a quadrisect along that plane and the one at
90 degrees.  The parts are the tablet's common with the plan sectors between those planes
(exact OCC Booleans), the break surface the tablet's common with each plane (its area
counted once per plane).  Masses are volume × solid fraction × true density when the
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
from tabletcad.tooling.booleans import boolean, raw_boolean, volume
from tabletcad.tooling.outline import TabletFrame, face_area, prism

__all__ = ["split_directions", "split_parts", "SPLIT_LOSS_LIMIT_PERCENT", "SPLIT_LOSS_SOURCE"]

#: FDA guidance for industry, Tablet Scoring: Nomenclature, Labeling, and Data for Evaluation (March 2013)
SPLIT_LOSS_LIMIT_PERCENT = 3.0
SPLIT_LOSS_SOURCE = ("FDA Guidance for Industry 'Tablet Scoring: Nomenclature, Labeling, and Data for Evaluation' "
                     "(2013): loss of mass on splitting < 3.0 % (summarised at https://excel-in-science.com/learnexcel/"
                     "tablet-scoring-guidance-for-pharmaceutical-analysis)")


def split_directions(scores) -> list[float]:
    """The distinct break-plane directions (degrees in [0, 180)) of the scores."""
    out: list[float] = []
    for s in scores:
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


def split_parts(frame: TabletFrame, solid, scores, *, density_mg_mm3: float | None = None) -> dict | None:
    """Parts and break surface of ``solid`` split along the score planes (see the module docstring)."""
    dirs = split_directions(scores)
    if not dirs:
        return None
    R = 2.0 * max(frame.length, frame.width) + 2.0
    z0, z1 = frame.z_min - 1.0, frame.z_max + 1.0
    rays = sorted({(d + k * 180.0) % 360.0 for d in dirs for k in (0, 1)})
    parts = []
    for k, a in enumerate(rays):
        b = rays[(k + 1) % len(rays)] + (360.0 if k + 1 == len(rays) else 0.0)
        fan = [(0.0, 0.0, 0.0)] + [(R * math.cos(math.radians(t)), R * math.sin(math.radians(t)), 0.0)
                                   for t in (a + (b - a) * j / 4.0 for j in range(5))]
        sector = prism(_polygon_wire(fan), z0, z1)
        v = volume(boolean("common", solid, sector, what=f"split part {k}"))
        parts.append(dict(from_deg=a, to_deg=b % 360.0, volume_mm3=v))
    total = sum(p["volume_mm3"] for p in parts)
    share = total / len(parts)
    for p in parts:
        p["deviation_from_equal_share_percent"] = 100.0 * (p["volume_mm3"] / share - 1.0)
        p["mass_mg"] = None if density_mg_mm3 is None else p["volume_mm3"] * density_mg_mm3
    area = 0.0
    for d in dirs:
        c, s = math.cos(math.radians(d)), math.sin(math.radians(d))
        plane = BRepBuilderAPI_MakeFace(_polygon_wire([(-R * c, -R * s, z0), (R * c, R * s, z0), (R * c, R * s, z1), (-R * c, -R * s, z1)]), True).Face()
        area += sum(face_area(f) for f in explore(raw_boolean("common", solid, plane), "Face"))
    worst = max(abs(p["deviation_from_equal_share_percent"]) for p in parts)
    return dict(directions_deg=dirs, parts=parts, n_parts=len(parts), volume_mm3=total,
                break_surface_area_mm2=area, density_mg_mm3=density_mg_mm3,
                max_deviation_from_equal_share_percent=worst,
                split_loss_limit_percent=SPLIT_LOSS_LIMIT_PERCENT, split_loss_limit_source=SPLIT_LOSS_SOURCE,
                within_limit=worst < SPLIT_LOSS_LIMIT_PERCENT,
                note="geometric screen: the parts' nominal share of the tablet against the limit on the measured "
                     "loss of mass on splitting")
