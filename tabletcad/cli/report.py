"""``tabletcad report DESIGN.toml``: the design report of an industry-family tablet.

Prints a readable table (volume, area, cup, plan, weight, punch-tip check,
tensile strength, FDA size flag, nominal certificate and seams) and, with
``--json``, writes the report as JSON.  Options not given on the command line
are read from the design file's ``[report]`` table.  Bad input: one line on
stderr, exit status 2, nothing written.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import click

from tabletcad.errors import DesignError, one_token

__all__ = ["COMMANDS", "load_family_design"]



def load_family_design(path: Path):
    """Read a design file; return ``(tablet, report_table)``.

    Besides the registered families, ``family = "custom_outline"`` is read
    here with ``outline = [[x, y], ...]`` (points, mm) or ``segments = [...]``
    (``["line", [x0, y0], [x1, y1]]`` / ``["arc", [cx, cy], r, theta0, sweep]``,
    angles in rad) plus the keys of :func:`tabletcad.families.outline_tablet`.
    """
    from tabletcad.design import design_from_dict, read_design_file

    data = read_design_file(path)
    return design_from_dict(data, default_name=Path(path).stem), data.get("report")


def _fmt(v: Any, unit: str = "", digits: int = 6) -> str:
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "NO"
    if isinstance(v, float):
        return f"{v:.{digits}g}" + (f" {unit}" if unit else "")
    return str(v) + (f" {unit}" if unit else "")


def _table(name: str, sec: dict[str, Any]) -> str:
    r = sec["design_report"]
    rows = [
        ("design", f"{name} ({r['family']}, {r['shape']}, {r['face']} face)"),
        ("length x width x thickness", f"{r['length_mm']:.4g} x {r['width_mm']:.4g} x {r['overall_thickness_mm']:.4g} mm"),
        ("band (wall) height", _fmt(r["band_mm"], "mm")),
        ("land", _fmt(r["land_mm"], "mm")),
        ("cup depth", _fmt(r["cup_depth_mm"], "mm")),
        ("shape factor (cup depth / width)", _fmt(r["shape_factor"])),
        ("volume", _fmt(r["volume_mm3"], "mm3")),
        ("surface area", _fmt(r["surface_area_mm2"], "mm2")),
        ("SA / V", _fmt(r["sa_to_volume_per_mm"], "1/mm")),
        ("cup volume (one face)", _fmt(r["cup_volume_mm3"], "mm3")),
        ("plan area", _fmt(r["plan_area_mm2"], "mm2")),
        ("plan perimeter", _fmt(r["plan_perimeter_mm"], "mm")),
        ("weight", _fmt(r["weight_mg"], "mg") if r["weight_mg"] is not None else f"- ({r['weight_basis']})"),
    ]
    ts = r["tensile_strength"]
    if ts.get("tensile_strength_MPa") is not None:
        rows.append(("tensile strength", f"{ts['tensile_strength_MPa']:.4g} MPa at {ts['breaking_force_N']:g} N ({ts['formula']})"))
        for f in ts.get("range_flags", []):
            rows.append(("  range flag", f))
    else:
        rows.append(("tensile strength", "- (" + (ts.get("note") or "; ".join(ts.get("range_flags", []))) + ")"))
    pc = r["punch_tip_check"]
    if pc.get("ok") is None:
        rows.append(("punch-tip check", f"not checked: {pc['limit_basis']}" if pc.get("allowed_force_kN") is None
                     else f"limit {pc['allowed_force_kN']:.4g} kN ({pc['limit_basis']}); give compaction_force_kN"))
    else:
        rows.append(("punch-tip check", f"{'OK' if pc['ok'] else 'OVER LIMIT'}: {pc['compaction_force_kN']:g} kN of {pc['allowed_force_kN']:.4g} kN "
                     f"({pc['compaction_pressure_MPa']:.4g} MPa on {pc['tip_face_area_mm2']:.4g} mm2; {pc['limit_basis']})"))
    fda = r["fda_size"]
    rows.append(("FDA size (largest <= 22 mm)", f"{'OK' if fda['ok'] else 'TOO LARGE'} ({fda['largest_dimension_mm']:.4g} mm)"))
    rows.append(("nominal deviation (certified)", f"{sec['nominal_max_deviation_um']:.3g} um <= {sec['nominal_tolerance_um']:g} um: {_fmt(sec['nominal_certified'])}"))
    for s in sec["seams"]:
        kind = "sharp (nominal edge)" if s["expected_sharp"] else "G1"
        rows.append((f"seam {s['patches'][0]}-{s['patches'][1]}", f"{s['max_angle_deg']:.4g} deg, gap {s['max_gap_mm']:.2g} mm, expected {kind}: {_fmt(s['as_expected'])}"))
    w = max(len(k) for k, _ in rows)
    return "\n".join(f"{k:<{w}}  {v}" for k, v in rows)


@click.command("report")
@click.argument("design", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--solid-fraction", type=float, default=None, help="Solid fraction (1 - porosity), 0-1.")
@click.option("--true-density", "true_density", type=float, default=None, help="True density, mg/mm3 (= g/cm3).")
@click.option("--breaking-force", type=float, default=None, help="Breaking force, N (tensile strength).")
@click.option("--compaction-force", type=float, default=None, help="Compaction force, kN (punch-tip check).")
@click.option("--max-punch-force", type=float, default=None, help="Punch-tip force limit, kN (user-given).")
@click.option("--max-punch-pressure", type=float, default=None, help="Punch-tip pressure limit, MPa (user-given).")
@click.option("--json", "json_out", type=click.Path(dir_okay=False, path_type=Path), default=None, help="Also write the report as JSON here.")
def report_cmd(design: Path, solid_fraction, true_density, breaking_force, compaction_force, max_punch_force,
               max_punch_pressure, json_out: Path | None) -> None:
    """Design report of DESIGN.toml (industry families): volumes, cup, weight, checks."""
    from tabletcad.families.designreport import ReportOptions, design_report
    from tabletcad.families.sweep import SweepNominal
    from tabletcad.report import to_json

    if json_out is not None and json_out.suffix.lower() != ".json":
        raise DesignError("--json", str(json_out), "must end in .json")
    tablet, table = load_family_design(design)
    if not isinstance(tablet.nominal, SweepNominal):
        from tabletcad.families import FAMILY_FUNCTIONS

        raise DesignError("tablet.family", tablet.family,
                          "the design report needs an industry family: " + ", ".join(f.__name__ for f in FAMILY_FUNCTIONS) + ", custom_outline")
    try:
        opts = ReportOptions.from_table(table).merged(
            solid_fraction=solid_fraction, true_density_mg_mm3=true_density, breaking_force_N=breaking_force,
            compaction_force_kN=compaction_force, max_punch_force_kN=max_punch_force, max_punch_pressure_MPa=max_punch_pressure)
    except DesignError as exc:  # "[report] solid_fraction" -> "[report].solid_fraction": one token
        raise exc.renamed(one_token(exc.parameter)) from None
    sec = design_report(tablet, opts)
    click.echo(_table(tablet.name, sec))
    if json_out is not None:
        from tabletcad.io.atomic import atomic_write_text

        payload = dict(design=dict(name=tablet.name, family=tablet.family, params=dict(tablet.params)),
                       units=dict(length="mm", area="mm2", volume="mm3", angle="deg", force="N (kN where named)", stress="MPa", mass="mg"),
                       **sec)
        json.loads(to_json(payload))  # fail before writing if not serialisable
        atomic_write_text(json_out, to_json(payload))
        click.echo(f"-> {json_out}")


COMMANDS = [report_cmd]
