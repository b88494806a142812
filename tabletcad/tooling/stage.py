"""The tooling stage of ``tabletcad build``: runs when the design has a ``[tooling]`` table.

The design parses and checks the table (:attr:`tabletcad.pipeline.design.Design.tooling_spec`);
:func:`tabletcad.pipeline.build.build_tablet` checks with :func:`check_tooling` that the
tablet can have tooling before any geometry is built, then calls :func:`tooling_stage` with
the solid the CAD stage made.

Writes the files :func:`tooling_outputs` names (``assembly.step``, the parts,
the drawings) into the build's staging
folder and adds the ``tooling`` section to ``report.json`` (``interference_mm3``,
``max_gap_mm`` and the per-method details).  Bad ``[tooling]`` input raises
:class:`~tabletcad.errors.DesignError` before anything is built (the CLI
exits with status 2 and the build writes nothing).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

from tabletcad.errors import DesignError, GeometryError
from tabletcad.geometry.tablet import Tablet
from tabletcad.pipeline.designreport import ReportOptions
from tabletcad.tooling.spec import ToolingSpec, band_heights, check_on_tablet, check_spline_offsets

__all__ = ["check_tooling", "tooling_outputs", "tooling_stage", "write_tooling", "write_finished_tablet"]


def tooling_outputs(spec: ToolingSpec) -> list[str]:
    """The files :func:`tooling_stage` writes for ``spec`` besides ``tablet.*`` (which it may replace):
    the assembly, the parts, the tablet's drawing, the punch and die drawing (complete punches with
    ``[tooling.punch]``, else the tips) and the plain tablet beside a scored or embossed one."""
    names = ["assembly.step", "upper_punch.step", "lower_punch.step", "die.step",
             "drawing.svg", "drawing.pdf", "drawing.dxf", "tooling.svg", "tooling.pdf", "tooling.dxf"]
    if spec.scores or spec.emboss:
        names.append("tablet_plain.step")
    return names


def check_tooling(tablet: Tablet, spec: ToolingSpec) -> None:
    """Refuse a tablet that cannot have tooling (a cut-away or a ring, one without a band, one too large for its
    die or for every TSM die when no die is given) and a ``[tooling]`` table its numbers refuse (a score or a
    figure deeper than its face allows, a groove wider than half the tablet, a clearance, gap or tip length, a
    figure that does not fit its face: :func:`~tabletcad.tooling.spec.check_on_tablet`; complete punches' tips too short for the die they run in:
    :func:`~tabletcad.tooling.spec.check_punch_lengths`; for a custom outline through points, an offset of it beyond
    its regular offsets: :func:`~tabletcad.tooling.spec.check_spline_offsets`), before any geometry is built: ``report`` and ``build``
    refuse alike, in a second where the tooling stage had refused after the solid was built.

    ``spec`` is the design's checked ``[tooling]`` table
    (:attr:`tabletcad.pipeline.design.Design.tooling_spec`); raises :class:`DesignError`.
    """
    t = tablet.trim
    if t.u != (0.0, 1.0) or not t.full_v or t.w[0] > 0:
        raise DesignError("[tooling]", tablet.name, "tooling needs a whole solid tablet (no [trim], no ring)")
    from tabletcad.pipeline.designreport import plan_diameter
    from tabletcad.tooling.spec import check_punch_lengths, check_relief_reach, die_height_for, standard_die_size

    band_z = band_heights(tablet)  # (a sphere has no band for the die to form)
    od = spec.die_outer_diameter_mm
    size, shaped = plan_diameter(tablet), tablet.revolution is None  # (its largest extent in plan: a square's diagonal)
    if od is None:  # the TSM die the build will take: one larger than a 'D' takes is refused here, not after the CAD
        standard_die_size(size, shaped=shaped)
    else:  # the die's wall around the tablet's plan (the bore adds at most 1e-6 mm to it)
        import numpy as np

        from tabletcad.tooling.spec import MIN_DIE_WALL_MM

        u, v = np.linspace(0.0, 1.0, 33), np.linspace(0.0, 2.0 * np.pi, 512, endpoint=False)
        reach = max(float(np.max(np.hypot(*p.evaluate_grid(u, v, components=True, axes=(0, 1)))))
                    for p in tablet.patches)
        if od / 2.0 - reach < MIN_DIE_WALL_MM:
            raise DesignError("[tooling] die_outer_diameter_mm", od,
                              f"must be >= {2 * (reach + MIN_DIE_WALL_MM):.4g} mm (the tablet reaches {reach:.4g} mm "
                              f"from the axis, the die's walls need {MIN_DIE_WALL_MM} mm)", "mm")
    check_on_tablet(tablet, spec)
    if spec.body is not None:  # complete punches: their tips against the die, their relief against the tablet's
        # width (the build checks both on its frame too, the relief by the outline's exact offset)
        check_punch_lengths(spec, band_z, die_height_for(spec, size, shaped))
        lo, hi = tablet.bounds()
        check_relief_reach(spec, min(float(hi[0] - lo[0]), float(hi[1] - lo[1])), float(hi[1] - lo[1]))
    check_spline_offsets(tablet, spec, size)  # (a custom outline through points: its offsets, as the frame builds them)


def write_tooling(ts, out: Path, *, drawing: bool = True) -> list[Path]:
    """Write the STEP files (and the drawing) of a :class:`~tabletcad.tooling.toolset.ToolSet`."""
    from tabletcad.tooling.assembly import write_assembly, write_parts

    out = Path(out)
    files = [write_assembly(ts.parts, out / "assembly.step", name=f"{ts.tablet.name}_tooling",
                            offsets={"upper_punch": ts.lift_mm})]
    files += write_parts(ts.parts, out)
    if drawing:
        from tabletcad.tooling.drawing import write_drawing

        files += write_drawing(ts, out)
    return files


def tooling_stage(*, tablet: Tablet, spec: ToolingSpec, shape, out: Path, report: dict[str, Any],
                  options: ReportOptions | None = None, fe_rating: Callable[[Any], dict] | None = None,
                  parallel: bool = False) -> None:
    """Tooling files of ``spec`` (the design's checked ``[tooling]`` table); the finished tablet as ``tablet.*``.

    ``shape`` is the tablet's solid (``TopoDS_Shape``) that the CAD stage built and wrote as
    ``tablet.step/.stl/.glb``; when scores or embossing change it, the plain STEP is kept as
    ``tablet_plain.step`` and ``tablet.*`` become the finished (scored, embossed) tablet, the
    one the punches fit.  ``options`` (the design's ``[report]`` table) gives the density for the
    masses of the split parts.  ``fe_rating``: called with the built
    :class:`~tabletcad.tooling.toolset.ToolSet` before the drawings are written, it returns the FE
    tip-force rating (``tooling.tip_rating.fe``, printed on the drawing beside the pressure rule's);
    the layer above passes it (:mod:`tabletcad.fe` may not be imported here).

    ``parallel``: on Linux with two or more cores, the parts' STEP files and the drawings are
    written by a forked process (:class:`tabletcad.io.forked.Forked`) while this one runs the
    closed-position check, whose gap another forked process measures beside the overlaps; the
    files and the report are the same.  With ``fe_rating`` the files wait for the check and the
    rating, as in one process.  For a process of its own (the
    command line), not for a Dask worker or FreeCAD.  Nothing is left running when a step fails.
    """
    from tabletcad.io.forked import Forked, can_fork
    from tabletcad.tooling.toolset import make_tooling

    out = Path(out)
    ts = make_tooling(tablet, spec, shape=shape, options=options, interference_check=False)
    forks = parallel and can_fork()
    if not forks or fe_rating is not None:
        # with an FE rating, which the drawing prints, the check comes first as in one process (no FE
        # solve for tooling that then fails it), then the rating, then the files
        _check_gap(ts, tablet.name, spec, forked=forks)
        if fe_rating is not None:
            ts.report["tip_rating"]["fe"] = fe_rating(ts)
        files = write_tooling(ts, out)
    else:  # the closed-position check (this process) and the writers (the child) are independent
        before = set(ts.report)

        def write():
            names = write_tooling(ts, out)
            return names, {k: v for k, v in ts.report.items() if k not in before}

        with Forked(write) as child:
            _check_gap(ts, tablet.name, spec, forked=True)
            files, added = child.result()
        ts.report.update(added)
    if spec.scores or spec.emboss:
        files += write_finished_tablet(ts, out)
    res = ts.report
    res["files"] = sorted(p.name for p in files)
    report["tooling"] = res


def _check_gap(ts, name: str, spec: ToolingSpec, forked: bool = False) -> None:
    """The closed-position check; a :class:`GeometryError` for an overlap or a gap above the clearance."""
    from tabletcad.tooling.toolset import check_closed_position

    check_closed_position(ts, forked=forked)
    res = ts.report
    if res.get("interference_mm3", 0.0) > 1e-6 or not res["interference"]["gap_within_clearance"]:
        raise GeometryError(
            f"{name}: tooling check failed: overlap {res['interference_mm3']:.3g} mm^3, largest gap "
            f"{res['max_gap_mm']:.4g} mm (clearance {spec.clearance_mm} mm)", ts)


def write_finished_tablet(ts, out: Path) -> list[Path]:
    """``tablet.step/.stl/.glb`` of the finished tablet (mesh checked), ``tablet_plain.step`` of the plain one."""
    import os

    import numpy as np

    from tabletcad.cad.export import export
    from tabletcad.cad.mesh import mesh_result
    from tabletcad.cad.stage import MESH_ANGULAR_RAD, MESH_LINEAR_MM
    from tabletcad.tooling.booleans import mesh_arrays

    out = Path(out)
    name = ts.tablet.name
    files = []
    if (out / "tablet.step").exists():
        os.replace(out / "tablet.step", out / "tablet_plain.step")
    else:
        export(ts.frame.shape, out / "tablet_plain.step", name=f"{name}_plain")
    files.append(out / "tablet_plain.step")
    finished = ts.parts["tablet"]
    # the triangulation the tooling checks made (Delabella, or Watson where Delabella leaves some
    # trimmed faces such as letter counters empty), meshed once per solid
    V, T = mesh_arrays(finished, MESH_LINEAR_MM, MESH_ANGULAR_RAD)
    mesh = mesh_result(np.array(V), np.array(T), MESH_LINEAR_MM, MESH_ANGULAR_RAD)
    if not mesh.ok:
        raise GeometryError(
            f"{name}: mesh check of the finished tablet failed (manifold3d {mesh.manifold_status}, "
            f"watertight {mesh.watertight}, winding {mesh.winding_consistent})", mesh)
    files.append(export(finished, out / "tablet.step", name=name))
    files += [export(finished, out / f"tablet{suffix}", name=name, mesh=mesh) for suffix in (".stl", ".glb")]
    return files
