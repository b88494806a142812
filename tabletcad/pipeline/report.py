"""The geometry report of a tablet (``report.json``): keys carry their units."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from tabletcad.io.jsontext import json_text
from tabletcad.pipeline.designreport import ReportOptions, design_report, shape_design_report
from tabletcad.families.sweep import SweepNominal
from tabletcad.geometry.tablet import Tablet

__all__ = ["geometry_report", "to_json", "flatten_report"]

#: the units of a report's figures (its keys also carry them: ``volume_mm3``, ``weight_mg``)
REPORT_UNITS = dict(length="mm", area="mm2", volume="mm3", angle="deg", force="N (kN where named)", stress="MPa",
                    mass="mg")

def geometry_report(tablet: Tablet, options: ReportOptions | None = None) -> dict[str, Any]:
    """Volume, area, dimensions, per-patch figures, seams and nominal deviation.

    All lengths in mm, areas in mm², volumes in mm³, angles in degrees.  A tablet of an
    industry family also gets its design report (:func:`~tabletcad.pipeline.designreport.design_report`),
    which reads ``options`` (a design's ``[report]`` table: :attr:`Design.report_options
    <tabletcad.pipeline.design.Design.report_options>`).
    """
    props = tablet.properties()
    dims = tablet.dimensions()
    solid_v = tablet.solid_volume()
    seams = tablet.seams()
    dev = tablet.nominal_deviation()
    patches = []
    mirror = tablet.mirror()  # a mirror solid's twins: their patches' stray (a reflection moves no detail)
    for i, (p, pp) in enumerate(zip(tablet.patches, props["patches"])):
        stray_of = p if mirror is None else tablet.patches[min(i, mirror[1][i])]
        s = p.spine([0.0, 1.0])
        patches.append(
            dict(
                index=i,
                surface_area_mm2=pp["surface_area_mm2"],
                volume_mm3=pp["volume_mm3"],
                smoothing_parameter_a=float(p.a),
                fourier_modes=int(p.modes),
                remainder_term=bool(p.has_remainder),
                form=p.form,
                u_nodes=list(p.u_nodes),
                spine_height_mm=float(s[1, 2] - s[0, 2]),
                stray_mm=stray_of.stray(),
                fold_depth_mm=p.checked_fold_depth,  # the figure its check compared with its limit (fold_limit)
            )
        )
    v = props["volume_mm3"]
    a = props["surface_area_mm2"]
    rep: dict[str, Any] = dict(
        units=dict(REPORT_UNITS),
        design=dict(name=tablet.name, family=tablet.family, params=dict(tablet.params)),
        trim=dict(u=list(tablet.trim.u), v_rad=list(tablet.trim.v), w=list(tablet.trim.w)),
        volume_mm3=v,
        surface_area_mm2=a,
        sa_to_volume_per_mm=a / v if v > 0 else math.nan,
        solid_volume_mm3=solid_v,
        volume_check_rel=abs(solid_v - v) / v if v > 0 else math.nan,
        height_mm=dims["height_mm"],
        width_mm=dims["width_mm"],
        length_mm=dims["length_mm"],
        plan_area_mm2=tablet.plan_area(),
        patches=patches,
        seams=seams,
        nominal=None
        if dev is None
        else dict(max_deviation_um=dev * 1000.0),
    )
    if isinstance(tablet.nominal, SweepNominal):  # the industry families' design report
        rep.update(design_report(tablet, options))
    else:  # the thesis's shapes and free-form designs: the same report from their own geometry
        rep["design_report"] = shape_design_report(tablet, options)
    return rep


def to_json(report: dict[str, Any]) -> str:
    """JSON text (NaN/inf written as null: :func:`tabletcad.io.jsontext.json_text`)."""
    return json_text(report) + "\n"


def flatten_report(report: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """Every scalar of a report (numbers, booleans, strings, None) under dotted keys; lists are left out.

    ``{"volume_mm3": 1.0, "design_report": {"weight_mg": 2.0}}`` becomes
    ``{"volume_mm3": 1.0, "design_report.weight_mg": 2.0}``.  NumPy scalars become
    Python ones; the order is the report's own.
    """
    import numpy as np

    out: dict[str, Any] = {}
    for k, v in report.items():
        name = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(flatten_report(v, name + "."))
        elif isinstance(v, (list, tuple, np.ndarray)):
            continue
        elif isinstance(v, np.generic):
            out[name] = v.item()
        else:
            out[name] = v
    return out
