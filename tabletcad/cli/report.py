"""``tabletcad report DESIGN.toml``: the design report of an industry-family tablet.

Prints a readable table (volume, area, cup, plan, weight, punch-tip check,
tensile strength, FDA size flag, nominal certificate and seams), or one line
per design for several designs; ``--json`` prints the report as JSON instead,
``--json-file``, ``--csv`` and ``--xlsx`` write it (CSV and workbook: one row
per design, every scalar of the report); ``--plot`` draws the design's picture, or several
designs side by side at one scale (PNG).  ``--solve-for`` with a target
weight or volume first solves for the band, thickness, cup depth, height or
dome of any family that has it (:func:`tabletcad.families.inverse.solve_for`).  Options not given on the command line
are read from the design file's ``[report]`` table.  Bad input: one line on
stderr, exit status 2, nothing written.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import click

from tabletcad.errors import MISSING, DesignError, one_token

__all__ = ["COMMANDS", "load_family_design", "nominal_note"]



def load_family_design(path: Path):
    """Read a design file; return ``(tablet, design)`` (the :class:`~tabletcad.pipeline.design.Design`).

    Besides the families of :data:`tabletcad.families.FAMILIES`, ``family = "custom_outline"`` is read
    here with ``outline = [[x, y], ...]`` (points, mm) or ``segments = [...]``
    (``["line", [x0, y0], [x1, y1]]`` / ``["arc", [cx, cy], r, theta0, sweep]``,
    angles in rad) plus the keys of :func:`tabletcad.families.outline_tablet`.
    """
    from tabletcad.pipeline.design import Design

    design = Design.from_toml(path)
    return design.build(), design


def _fmt(v: Any, unit: str = "", digits: int = 4) -> str:
    """A figure with ``digits`` significant figures (4: 0.1 % and below a micrometre on a tablet's
    dimensions), its unit, "-" for None and yes/NO for booleans."""
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "NO"
    if isinstance(v, float):
        return f"{v:.{digits}g}" + (f" {unit}" if unit else "")
    return str(v) + (f" {unit}" if unit else "")


#: the thesis's shapes whose ``length`` runs along the tablet's axis (its thickness), not in plan
_AXIAL_LENGTH = ("thesis.oblong", "thesis.rod")


def nominal_note(family: str, params: dict[str, Any], length: float, width: float, thickness: float) -> str:
    """`` (PDE surface; nominal 10 x 10 x 3 mm)`` when one of the thesis's shapes measures other than
    its design's own dimensions at the printed precision (its PDE surface bulges between the
    thesis's boundary curves), else ``""``.  The nominal reads as the measure does, length x width x
    thickness: a rod's or an oblong's ``length`` is its thickness (along its axis), a spheroid's
    ``height`` and a sphere's ``diameter`` are too, a ring's plan is its ``outer_diameter``."""
    D = params.get("diameter", params.get("outer_diameter"))
    if family in _AXIAL_LENGTH:
        L = W = D
        T = params.get("length")
    else:
        L, W = params.get("length", D), params.get("width", D)
        T = params.get("thickness", params.get("height", D if family == "thesis.spherical" else None))
    if L is None or W is None or not family.startswith("thesis."):
        return ""
    nominal = (f"{L:.4g}", f"{W:.4g}") + ((f"{T:.4g}",) if T is not None else ())
    measured = (f"{length:.4g}", f"{width:.4g}", f"{thickness:.4g}")[: len(nominal)]
    return "" if nominal == measured else f" (PDE surface; nominal {' x '.join(nominal)} mm)"


def _nominal_note(r: dict[str, Any]) -> str:
    return nominal_note(r["family"], r.get("params") or {}, r["length_mm"], r["width_mm"], r["overall_thickness_mm"])


def _cup_radii(r: dict[str, Any]) -> str:
    """``13.9 mm`` (a single-radius cup), ``central 16 mm, edge 2.5 mm`` (a compound cup), or ``-``
    (a flat face, or a shape without a cup radius)."""
    radii = r.get("cup_radii_mm") or {}
    if len(radii) > 1:
        return ", ".join(f"{k} {_fmt(v, 'mm')}" for k, v in radii.items())
    return _fmt(r.get("cup_radius_mm"), "mm")


def _table(name: str, sec: dict[str, Any]) -> str:
    r = sec["design_report"]
    kind = f"{r['shape']}, {r['face']} face" if r["shape"] is not None else "no shape formulas"
    rows = [
        ("design", f"{name} ({r['family']}, {kind})"
                   + ("; a cut-away view: the figures below are the uncut design's"
                      if r.get("cut_away") and r["shape"] is not None else "")),
        ("length x width x thickness", f"{r['length_mm']:.4g} x {r['width_mm']:.4g} x {r['overall_thickness_mm']:.4g} mm"
                                       + _nominal_note(r)),
        ("band (wall) height", _fmt(r["band_mm"], "mm")),
        ("land", _fmt(r["land_mm"], "mm")),
        ("cup depth", _fmt(r["cup_depth_mm"], "mm") + (
            f" (from the band; {_fmt(r['params']['cup_depth_below_bevel_mm'], 'mm')} below the bevel: the design's cup_depth)"
            if "cup_depth_below_bevel_mm" in (r.get("params") or {}) else "")),
        ("cup radius" if len(r.get("cup_radii_mm") or {}) <= 1 else "cup radii", _cup_radii(r)),
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
        given = ""  # the force given, as a pressure on the tip (15000 kN typed for 15 kN: 1.9e5 MPa, shown now)
        if pc.get("compaction_force_kN") is not None and pc.get("compaction_pressure_MPa") is not None:
            given = (f"{pc['compaction_force_kN']:g} kN is {pc['compaction_pressure_MPa']:.4g} MPa on "
                     f"{pc['tip_face_area_mm2']:.4g} mm2; ")
        rows.append(("punch-tip check", f"not checked: {given}{pc['limit_basis']}" if pc.get("allowed_force_kN") is None
                     else f"limit {pc['allowed_force_kN']:.4g} kN ({pc['limit_basis']}); give compaction_force_kN"))
    else:
        on = ("plan area not known" if pc.get("tip_face_area_mm2") is None  # (a shaped cut-away, Tablet.plan_area)
              else f"{pc['compaction_pressure_MPa']:.4g} MPa on {pc['tip_face_area_mm2']:.4g} mm2")
        rows.append(("punch-tip check", f"{'OK' if pc['ok'] else 'OVER LIMIT'}: {pc['compaction_force_kN']:g} kN of "
                     f"{pc['allowed_force_kN']:.4g} kN ({on}; {pc['limit_basis']})"))
    fe = sec.get("fe_breaking_force")
    if fe is not None:
        plain = f"; {fe['note']}" if fe.get("note") else ""
        rows.append(("FE breaking force", f"{fe['breaking_force_N']:.4g} N across the width (elastic first-crack "
                                          f"estimate, coarse mesh; σ_t {fe['tensile_strength_MPa']:.4g} MPa{plain})"))
    fda = r["fda_size"]
    rows.append(("FDA size (largest <= 22 mm)", f"{'OK' if fda['ok'] else 'TOO LARGE'} ({fda['largest_dimension_mm']:.4g} mm)"))
    if sec["nominal_certified"] is not None:
        rows.append(("nominal deviation (certified)", f"{sec['nominal_max_deviation_um']:.3g} um <= {sec['nominal_tolerance_um']:g} um: {_fmt(sec['nominal_certified'])}"))
    elif sec["nominal_max_deviation_um"] is not None:
        rows.append(("PDE surface vs exact shape", f"{sec['nominal_max_deviation_um']:.3g} um (not certified: the thesis's curves)"))
    for s in sec["seams"]:
        angle = "-" if s["max_angle_deg"] != s["max_angle_deg"] else f"{s['max_angle_deg']:.3f} deg"  # nan: a pole
        if s["expected_sharp"] is None:
            expected = "G1" if s["g1"] else "an edge"
        else:
            expected = f"expected {'sharp (nominal edge)' if s['expected_sharp'] else 'G1'}: {_fmt(s['as_expected'])}"
        rows.append((f"seam {s['patches'][0]}-{s['patches'][1]}", f"{angle}, gap {s['max_gap_mm'] * 1e3:.3f} um, {expected}"))
    w = max(len(k) for k, _ in rows)
    return "\n".join(f"{k:<{w}}  {v}" for k, v in rows)


#: The dimensions --solve-for takes: :data:`tabletcad.families.inverse.VARY` (not imported here, to keep
#: the command line's start light; tests/test_inverse_all_families.py checks that they agree).
_SOLVABLE = ("band", "thickness", "cup_depth", "height", "dome")


def _solved(tablet, design, opts, vary: str, target_weight: float | None, target_volume: float | None):
    """``tablet`` with ``vary`` solved for the target weight or volume; ``(tablet, inverse section)``.

    The family is rebuilt from the design's own ``[tablet]`` dimensions (mm, deg) and its
    smoothing parameter ``a``; a custom outline keeps its outline.  Errors name the command's
    options (``--solve-for``, ``--target-volume``...) or the design's keys (``tablet.band``).
    """
    import functools

    from tabletcad.families.inverse import VARY, _family_function, solve_for

    if tablet.family == "free_form":
        raise DesignError("--solve-for", vary, f"free_form designs have none of the dimensions that can be solved for "
                          f"({', '.join(VARY)}): their patches are given curve by curve")
    given = {k: v for k, v in design.tablet.items() if k not in ("family", "name")}
    try:
        if tablet.family == "custom_outline":  # its outline stays, its cup dimensions vary
            from tabletcad.families import outline_tablet

            family = functools.partial(outline_tablet, tablet.nominal.outline)
            dims = {k: v for k, v in tablet.params.items() if k in given}
        else:
            family = _family_function(tablet.family)
            dims = {k: v for k, v in given.items() if k != "a"}
        if given.get("a") is not None:
            dims["a"] = given["a"]
        r = solve_for(family, target_weight_mg=target_weight, target_volume_mm3=target_volume, vary=vary,
                      solid_fraction=opts.solid_fraction if target_weight is not None else None,
                      true_density_mg_mm3=opts.true_density_mg_mm3 if target_weight is not None else None, **dims)
    except DesignError as exc:  # the Python API's argument names as the command's options
        option = {"target_volume_mm3": "--target-volume", "target_weight_mg": "--target-weight", "vary": "--solve-for",
                  vary: "--solve-for", "family": "tablet.family", "solid_fraction": "--solid-fraction",
                  "true_density_mg_mm3": "--true-density",
                  **{k: f"tablet.{k}" for k in given if k != vary}}
        option = {one_token(k): v for k, v in option.items()}.get(exc.parameter)  # (parameters are one token)
        raise exc.renamed(option or one_token(exc.parameter)) from None
    from dataclasses import replace

    solved = replace(r.tablet, name=tablet.name) if hasattr(r.tablet, "name") else r.tablet
    section = dict(solved_for=vary, value_mm=r.value, given_mm=given.get(vary), target_weight_mg=target_weight,
                   target_volume_mm3=target_volume, nominal_volume_mm3=r.volume_mm3, weight_mg=r.weight_mg,
                   evaluations=r.evaluations)
    return solved, section


def _g(value: float | None) -> str:
    """A figure to 4 significant digits, ``-`` when the shape has none."""
    return "-" if value is None else f"{value:.4g}"


def _comparison(rows: list[tuple[str, dict[str, Any]]]) -> str:
    """One line per design: the figures a designer compares."""
    head = ("design", "family", "L x W x T mm", "band mm", "cup mm", "cup radius mm", "volume mm3", "area mm2",
            "SA/V 1/mm", "weight mg")
    lines = [head]
    for name, sec in rows:
        r = sec["design_report"]
        radii = r.get("cup_radii_mm") or {}
        radius = "/".join(f"{v:.4g}" for v in radii.values()) if radii else "-"
        lines.append((name, r["family"], f"{r['length_mm']:.4g} x {r['width_mm']:.4g} x {r['overall_thickness_mm']:.4g}",
                      _g(r["band_mm"]), _g(r["cup_depth_mm"]), radius, f"{r['volume_mm3']:.4g}",
                      f"{r['surface_area_mm2']:.4g}", f"{r['surface_area_mm2'] / r['volume_mm3']:.4g}",
                      "-" if r["weight_mg"] is None else f"{r['weight_mg']:.4g}"))
    w = [max(len(str(row[i])) for row in lines) for i in range(len(head))]
    return "\n".join("  ".join(str(c).ljust(w[i]) if i < 2 else str(c).rjust(w[i]) for i, c in enumerate(row)).rstrip()
                     for row in lines)


def _write_tables(payloads: list[dict[str, Any]], csv_out: Path | None, xlsx_out: Path | None, staged: dict[str, Path]) -> None:
    """One row per design: ``design``, ``file``, its family and dimensions (``tablet.<key>``, mm), then
    every scalar of its report under dotted names (units in the names)."""
    from tabletcad.pipeline.report import flatten_report

    rows = [{"design": p["design"]["name"], "file": p["design"]["file"], "tablet.family": p["design"]["family"],
             **{f"tablet.{k}": v for k, v in p["design"]["params"].items() if isinstance(v, (int, float, str, bool))},
             **{k: v for k, v in flatten_report(p).items() if not k.startswith(("design.", "units."))}}
            for p in payloads]
    columns: list[str] = []
    for row in rows:
        columns += [k for k in row if k not in columns]
    if csv_out is not None:
        import csv

        with open(staged["csv"], "w", newline="", encoding="utf-8") as fh:
            w = csv.DictWriter(fh, fieldnames=columns, restval="")
            w.writeheader()
            w.writerows({k: ("" if v is None else repr(v) if isinstance(v, float) else v) for k, v in row.items()}
                        for row in rows)
    if xlsx_out is not None:
        from openpyxl import Workbook

        wb = Workbook()
        ws = wb.active
        ws.title = "report"
        ws.append(columns)
        for row in rows:
            ws.append([row.get(k) for k in columns])
        ws.freeze_panes = "C2"
        _save_workbook(wb, staged["xlsx"])


def _save_workbook(wb, path: Path) -> None:
    """Write the openpyxl workbook ``wb`` to ``path`` dated by :func:`~tabletcad.io.timestamp.stamp_time`:
    its ``created`` and ``modified`` properties and its zip entries (``Workbook.save`` gives the properties
    the time of writing, UTC, and the entries the local time), so that with ``SOURCE_DATE_EPOCH`` two runs
    write the same bytes."""
    import io
    import zipfile

    from openpyxl.writer.excel import ExcelWriter

    from tabletcad.io.timestamp import redate_zip, stamp_time

    when = stamp_time()
    wb.properties.created = wb.properties.modified = when.replace(tzinfo=None)  # (openpyxl's: naive, UTC)
    buf = io.BytesIO()
    ExcelWriter(wb, zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED, allowZip64=True)).save()  # (closes it)
    path.write_bytes(redate_zip(buf.getvalue(), when))


def _write_plot(tablets: list, path: Path) -> None:
    """One design: its picture (:func:`~tabletcad.pipeline.plot.plot_tablet`); several: their
    profiles and plans side by side at one scale (:func:`~tabletcad.pipeline.plot.plot_tablets`)."""
    from tabletcad.pipeline.plot import plot_tablet, plot_tablets

    if len(tablets) == 1:
        plot_tablet(tablets[0], path)
    else:
        plot_tablets(tablets, path)


@click.command("report")
@click.argument("designs", metavar="DESIGN.toml...", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("--solid-fraction", type=float, default=None, help="Solid fraction (1 - porosity), 0-1.")
@click.option("--true-density", "true_density", type=float, default=None, help="True density, mg/mm3 (= g/cm3).")
@click.option("--breaking-force", type=float, default=None, help="Breaking force, N (tensile strength).")
@click.option("--compaction-force", type=float, default=None, help="Compaction force, kN (punch-tip check).")
@click.option("--max-punch-force", type=float, default=None, help="Punch-tip force limit, kN (user-given).")
@click.option("--max-punch-pressure", type=float, default=None, help="Punch-tip pressure limit, MPa (user-given).")
@click.option("--solve-for", "solve_for", type=click.Choice(_SOLVABLE), default=None,
              help="Solve for this dimension (mm) to reach --target-weight or --target-volume; the others stay "
                   "(height, dome: the thesis's spheroids, caplet, oblong and rod).")
@click.option("--target-weight", type=float, default=None, help="Target weight, mg (needs solid fraction and true density).")
@click.option("--target-volume", type=float, default=None, help="Target volume, mm3.")
@click.option("--json", "as_json", is_flag=True, help="Print the report as JSON on stdout (a list for several designs).")
@click.option("--json-file", type=click.Path(path_type=Path), default=None, help="Write the report as JSON to this file.")
@click.option("--csv", "csv_out", type=click.Path(path_type=Path), default=None, help="Write one row per design (every scalar of the report) as CSV.")
@click.option("--xlsx", "xlsx_out", type=click.Path(path_type=Path), default=None, help="The same table as an Excel workbook (needs openpyxl).")
@click.option("--plot", "plot_out", type=click.Path(path_type=Path), default=None,
              help="Write a picture (PNG): the design's, or several designs side by side at one scale.")
def report_cmd(designs: tuple[Path, ...], solid_fraction, true_density, breaking_force, compaction_force, max_punch_force,
               max_punch_pressure, solve_for, target_weight, target_volume, as_json: bool, json_file: Path | None,
               csv_out: Path | None, xlsx_out: Path | None, plot_out: Path | None = None) -> None:
    """Design report of one or more DESIGN.toml (any family): volumes, cup, weight, checks.

    One design prints its report; several print one line each.  --solve-for finds the band,
    thickness, cup depth, height or dome that gives --target-weight or --target-volume (any
    family that has it), then reports that design.
    """
    from tabletcad.cli.outputs import check_output, staged
    from tabletcad.pipeline.designreport import design_report, shape_report
    from tabletcad.families.sweep import SweepNominal
    from tabletcad.pipeline.report import REPORT_UNITS, to_json

    for d in designs:
        if d.suffix.lower() == ".json":
            raise DesignError("DESIGN", str(d), "is a design .toml; write JSON with --json-file (--json prints to stdout)")
        if not d.is_file():
            raise DesignError("DESIGN", str(d), "is a folder, not a file" if d.is_dir() else
                              "is a pipe or device, not a file (save the design to a .toml file)" if d.exists() else
                              "does not exist")
    check_output("--json-file", json_file, (".json",))
    check_output("--csv", csv_out, (".csv",))
    check_output("--xlsx", xlsx_out, (".xlsx",))
    check_output("--plot", plot_out, (".png",))
    if xlsx_out is not None:
        try:
            import openpyxl  # noqa: F401
        except ImportError:
            raise DesignError("--xlsx", str(xlsx_out), "needs openpyxl: pip install 'tabletcad[tables]'") from None
    if solve_for is None and (target_weight is not None or target_volume is not None):
        raise DesignError("--solve-for", MISSING, f"a target needs the dimension to solve for: {', '.join(_SOLVABLE)}")
    if solve_for is not None and (target_weight is None) == (target_volume is None):
        raise DesignError("--target-weight/--target-volume", "both" if target_weight is not None else "none",
                          "give exactly one target for --solve-for")

    payloads, shown, tablets = [], [], []
    for design in designs:
        try:
            tablet, spec = load_family_design(design)
        except DesignError as exc:  # with several designs, say which file it is
            if len(designs) == 1:
                raise
            raise DesignError(exc.parameter, exc.value, f"{exc.allowed} (in {design})", exc.unit) from None
        if spec.tooling_spec is not None:  # refused as build refuses it (the report builds no tooling)
            from tabletcad.tooling.stage import check_tooling

            try:
                check_tooling(tablet, spec.tooling_spec)
            except DesignError as exc:
                if len(designs) == 1:
                    raise
                raise DesignError(exc.parameter, exc.value, f"{exc.allowed} (in {design})", exc.unit) from None
        try:
            opts = spec.report_options.merged(
                solid_fraction=solid_fraction, true_density_mg_mm3=true_density, breaking_force_N=breaking_force,
                compaction_force_kN=compaction_force, max_punch_force_kN=max_punch_force, max_punch_pressure_MPa=max_punch_pressure)
        except DesignError as exc:  # named as given: the option, else "[report].solid_fraction" (one token)
            options = {"solid_fraction": ("--solid-fraction", solid_fraction), "true_density_mg_mm3": (
                "--true-density", true_density), "breaking_force_N": ("--breaking-force", breaking_force),
                "compaction_force_kN": ("--compaction-force", compaction_force), "max_punch_force_kN": (
                "--max-punch-force", max_punch_force), "max_punch_pressure_MPa": ("--max-punch-pressure", max_punch_pressure)}
            option, value = options.get(exc.parameter.removeprefix("report."), (None, None))
            raise exc.renamed(option if value is not None else one_token(exc.parameter)) from None
        inverse = None
        if solve_for is not None:
            carried = [f"[{k}]" for k in ("trim", "reshape") if getattr(spec, k) is not None and tablet.family != "free_form"]
            if carried:
                raise DesignError("--solve-for", solve_for, f"the design sets {', '.join(carried)}, which the inverse "
                                  "calculation does not carry (it rebuilds the family from its dimensions)")
            tablet, inverse = _solved(tablet, spec, opts, solve_for, target_weight, target_volume)
        # industry families: the certified report; the thesis's shapes and free-form designs:
        # the same figures from their own geometry, without a certificate
        sec = design_report(tablet, opts) if isinstance(tablet.nominal, SweepNominal) else shape_report(tablet, opts)
        if opts.fe_breaking_force:  # [report] fe_breaking_force = true: the coarse-mesh FE prediction
            from tabletcad.fe.objective import report_breaking_force

            try:
                sec["fe_breaking_force"] = report_breaking_force(tablet, opts, spec.tooling_spec)
            except DesignError as exc:  # a missing [report] input: one token, as above
                raise exc.renamed(one_token(exc.parameter)) from None
        payload = dict(design=dict(name=tablet.name, file=str(design), family=tablet.family, params=dict(tablet.params)),
                       units=dict(REPORT_UNITS),
                       **({"inverse": inverse} if inverse is not None else {}), **sec)
        json.loads(to_json(payload))  # fail before writing if not serialisable
        payloads.append(payload)
        shown.append((tablet.name, sec))
        tablets.append(tablet)

    document = payloads[0] if len(payloads) == 1 else payloads
    with staged(json=json_file, csv=csv_out, xlsx=xlsx_out, plot=plot_out) as st:
        if json_file is not None:
            st["json"].write_text(to_json(document) if isinstance(document, dict)
                                  else "[\n" + ",\n".join(to_json(p).rstrip("\n") for p in payloads) + "\n]\n",
                                  encoding="utf-8")
        if csv_out is not None or xlsx_out is not None:
            _write_tables(payloads, csv_out, xlsx_out, st)
        if plot_out is not None:
            _write_plot(tablets, st["plot"])
        # printed before the files are moved into place: a refused standard output (a full disk) leaves none
        # of them (it had left --csv, --plot and --json-file, exit 2)
        _print_report(document, payloads, shown, as_json,
                      (("json", json_file), ("csv", csv_out), ("xlsx", xlsx_out), ("plot", plot_out)))


def _print_report(document: dict | list, payloads: list[dict[str, Any]], shown: list, as_json: bool,
                  files: tuple[tuple[str, Path | None], ...]) -> None:
    """Print the reports: the JSON document, or each solved dimension, the table (one design) or the
    comparison (several), and the files written (option, path)."""
    from tabletcad.pipeline.report import to_json

    if as_json:
        click.echo(to_json(document).rstrip("\n") if isinstance(document, dict)
                   else "[\n" + ",\n".join(to_json(p).rstrip("\n") for p in payloads) + "\n]")
        return
    for p in payloads:
        if "inverse" in p:
            inv = p["inverse"]
            target = (f"{inv['target_weight_mg']:.6g} mg" if inv["target_weight_mg"] is not None
                      else f"{inv['target_volume_mm3']:.6g} mm3")
            click.echo(f"{p['design']['name']}: {inv['solved_for']} = {inv['value_mm']:.4g} mm gives {target}"
                       + (f" (was {inv['given_mm']:.4g} mm)" if inv["given_mm"] is not None else ""))
    click.echo(_table(*shown[0]) if len(shown) == 1 else _comparison(shown))
    for option, path in files:
        if path is not None:
            click.echo(f"{option} -> {path}")


COMMANDS = [report_cmd]
