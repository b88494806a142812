"""``tabletcad build``: every output of a design, written all-or-nothing into a folder.

Outputs are produced in a staging folder on the target's file system (inside it when it exists) and moved into
place only when all of them succeeded, so a failure leaves no partial file;
the folder then holds exactly this build's files besides any files tabletcad
did not write (:mod:`tabletcad.io.outputs`).
The CAD outputs (STEP, STL, GLB, tooling) are added when the ``cad`` extra
is installed (:func:`cad_available`).
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from tabletcad.geometry.tablet import Tablet
from tabletcad.io.forked import Forked, can_fork
from tabletcad.io.outputs import STAGING_MARKER, check_replaceable, publish, staging_folder
from tabletcad.io.signals import signals_deferred
from tabletcad.pipeline.design import Design
from tabletcad.pipeline.designreport import ReportOptions
from tabletcad.pipeline.plot import plot_tablet
from tabletcad.pipeline.report import geometry_report, to_json
from tabletcad.tooling.spec import ToolingSpec

__all__ = ["build_design", "build_outputs", "build_tablet", "cad_available", "import_shared", "CAD_MODULES",
           "SHARED_IMPORTS"]

#: The modules of the ``cad`` extra the CAD stage imports (OpenCascade, the mesh checks).
CAD_MODULES = ("OCP", "manifold3d", "trimesh")


def cad_available() -> bool:
    """Whether the ``cad`` extra is installed, so that a build writes the CAD outputs.

    Only looks the modules up (nothing is imported): once they are there, a
    failure to import the CAD layer is an error, never a build without its
    CAD files.  With the environment variable ``TABLETCAD_REQUIRE_CAD`` set the
    answer is always yes (a missing module is then an error too).
    """
    if os.environ.get("TABLETCAD_REQUIRE_CAD"):
        return True
    return all(importlib.util.find_spec(m) is not None for m in CAD_MODULES)


def build_outputs(cad: bool, tooling: ToolingSpec | None = None) -> list[str]:
    """Every file a build may write (relative names): the report and picture, with ``cad`` the CAD files,
    with ``tooling`` its parts and drawings (checked against the output folder before any geometry)."""
    names = ["report.json", "tablet.png"] + (["tablet.step", "tablet.stl", "tablet.glb"] if cad else [])
    if tooling is not None:
        from tabletcad.tooling.stage import tooling_outputs

        names += tooling_outputs(tooling)
    return names


#: the matplotlib modules that both forked children of a parallel tooling build draw with: the picture's
#: (:func:`~tabletcad.pipeline.plot.plot_tablet`) and the drawings' (:mod:`tabletcad.tooling.drawing`)
SHARED_IMPORTS = ("matplotlib.figure", "matplotlib.backends.backend_agg")


def import_shared() -> None:
    """Import :data:`SHARED_IMPORTS` in this process, before it forks the children that draw.

    A forked child inherits the modules its parent has imported; those it imports itself are its own.
    The picture's child and the drawings' child had each imported matplotlib's figure and Agg canvas
    (0.29-0.31 s of CPU each time, measured in a fresh process after tabletcad's own imports): imported
    once here, the parallel build of ``samples/tooling/concave_round_bisect.toml`` spends that once.
    """
    for name in SHARED_IMPORTS:
        importlib.import_module(name)


def fe_breaking_force_section(tablet: Any, options: Any, tooling: Any, cad: bool) -> dict[str, Any]:
    """The report's ``fe_breaking_force`` (``[report] fe_breaking_force = true``): the coarse-mesh FE
    prediction (:func:`tabletcad.fe.objective.report_breaking_force`) when the build makes a CAD solid,
    else a note saying it was not computed.  One function for ``tabletcad build`` and a sweep's rows."""
    if not cad:
        return {"breaking_force_N": None, "note": "not computed: this build made no CAD solid"}
    from tabletcad.fe.objective import report_breaking_force

    return report_breaking_force(tablet, options, tooling)


def build_tablet(tablet: Tablet, out_dir: str | Path, *, tooling: ToolingSpec | None = None,
                 options: ReportOptions | None = None, cad: bool | None = None, progress: bool = True,
                 parallel: bool = False, picture: bool = True,
                 announce: Callable[[dict[str, Any]], None] | None = None) -> dict[str, Any]:
    """Write ``report.json``, ``tablet.png``, the CAD files and the tooling of ``tablet`` into ``out_dir``.

    The steps, in order: the geometry report (:func:`~tabletcad.pipeline.report.geometry_report`,
    with the report ``options``); with ``cad`` (default: :func:`cad_available`) the solid, its
    checks and ``tablet.step/.stl/.glb`` (:func:`tabletcad.cad.stage.cad_stage`), then, with a
    ``tooling`` specification, the punches, die and drawings made from that solid
    (:func:`tabletcad.tooling.stage.tooling_stage`; with ``[tooling.fe_rating]`` the FE tip-force
    rating, :func:`fe_tip_rating`, before the drawings); when the options ask for it
    (``[report] fe_breaking_force = true``), the FE breaking force on the coarse mesh
    (:func:`tabletcad.fe.objective.report_breaking_force`); last the picture.  Whether the tablet can
    have tooling is checked before any geometry is built.  :func:`build_design` takes both
    from a design.  ``parallel``: the picture is drawn by a forked process beside the CAD stage, and the
    tooling's files are written by another beside the closed-position check (the command line's
    ``build``; for a process of its own, not a Dask worker or FreeCAD: see
    :func:`~tabletcad.tooling.stage.tooling_stage`); the files are the same.  Matplotlib, which the
    picture's child and the drawings' child both draw with, is imported before the first fork
    (:func:`import_shared`), once for both.  ``picture=False`` leaves ``tablet.png`` out (a sweep that
    keeps only other files: the picture, 0.08 CPU-s, was most of a report-and-CAD-files design's
    0.1 CPU-s and the only reason its worker imported Matplotlib); nothing else changes.

    ``announce``, if given, is called with the report once every file is made, before they are put in
    place: the command line prints its summary there, so that a refused standard output (a full disk)
    leaves ``out_dir`` as it was.

    Returns the report; ``report["outputs"]`` names the files this build wrote.
    Nothing in ``out_dir`` changes if any step fails.  The folder is owned by
    the build (:mod:`tabletcad.io.outputs`): files of an earlier build that
    this one does not write are removed, files tabletcad did not write are kept.
    """
    out_dir = Path(out_dir)
    cad = cad_available() if cad is None else cad
    if tooling is not None:  # refused before the (slow) geometry, with or without the CAD stage
        from tabletcad.tooling.stage import check_tooling

        check_tooling(tablet, tooling)
    if not cad:
        tooling = None
    # every file this build may write, refused before the geometry if the folder holds one it may not replace
    names = build_outputs(cad, tooling)
    check_replaceable(out_dir, names)
    steps = 2 + cad + (tooling is not None)
    with staging_folder(out_dir) as staging:
        from tqdm import tqdm

        # the bar shows on a terminal only (disable=None), never in a log or a pipe
        with tqdm(total=steps, desc="build", unit="step", disable=None if progress else True, leave=False) as bar, \
                contextlib.ExitStack() as helpers:
            report = geometry_report(tablet, options)
            bar.update()
            forks = parallel and can_fork() and picture
            if forks and cad and tooling is not None:  # two children will draw: their modules imported once
                import_shared()
            # the picture needs only the tablet: drawn by a forked process beside the CAD stage (a Ctrl-C
            # waits until the child is in ``helpers``, whose exit then stops it)
            drawn = None
            if forks:
                with signals_deferred():
                    drawn = helpers.enter_context(Forked(lambda: plot_tablet(tablet, staging / "tablet.png")))
            if cad:
                from tabletcad.cad.stage import cad_stage

                # a tooling build converts faces of revolution to rational B-splines
                # (see tabletcad.tooling.outline.tablet_frame)
                shape = cad_stage(tablet=tablet, out=staging, report=report)
                bar.update()
                if tooling is not None:
                    from tabletcad.tooling.stage import tooling_stage

                    fe = None if tooling.fe_rating is None else (lambda ts: fe_tip_rating(ts, options))
                    tooling_stage(tablet=tablet, spec=tooling, shape=shape, out=staging, report=report, options=options,
                                  fe_rating=fe, parallel=parallel)
                    bar.update()
            if options is not None and options.fe_breaking_force:  # [report] fe_breaking_force = true
                report["fe_breaking_force"] = fe_breaking_force_section(tablet, options, tooling, cad)
            if drawn is not None:
                drawn.result()
            elif picture:
                plot_tablet(tablet, staging / "tablet.png")
            bar.update()
        names = sorted(p.name for p in staging.iterdir() if p.name != STAGING_MARKER) + ["report.json"]
        report["outputs"] = sorted(names)
        (staging / "report.json").write_text(to_json(report), encoding="utf-8")
        if announce is not None:
            announce(report)
        publish(staging, out_dir)
        return report


def fe_tip_rating(ts: Any, options: ReportOptions | None) -> dict[str, Any]:
    """``tooling.tip_rating.fe`` of a tooling build (``[tooling.fe_rating]``): the FE punch analysis
    (:func:`tabletcad.fe.punch.fe_tip_rating`) at the design's compaction force, or a note saying why
    not (the fe extra missing): the drawing then states the pressure rule's rating alone."""
    missing = [m for m in ("gmsh", "skfem") if importlib.util.find_spec(m) is None]
    if missing:
        return dict(allowed_force_kN=None, note=f"not computed: the FE punch analysis needs the fe extra ({missing[0]} "
                                                "is missing: pip install 'tabletcad[fe]')")
    from tabletcad.fe.punch import fe_tip_rating as rate

    return rate(ts, ts.spec.fe_rating, None if options is None else options.compaction_force_kN)


def build_design(design: str | Path | Design, out_dir: str | Path, *, cad: bool | None = None,
                 progress: bool = True, parallel: bool = False,
                 announce: Callable[[dict[str, Any]], None] | None = None) -> dict[str, Any]:
    """:func:`build_tablet` of a design (a :class:`~tabletcad.pipeline.design.Design` or a design file):
    its tablet, its ``[tooling]`` specification and its ``[report]`` options."""
    if not isinstance(design, Design):
        design = Design.from_toml(design)
    return build_tablet(design.build(), out_dir, tooling=design.tooling_spec, options=design.report_options,
                        cad=cad, progress=progress, parallel=parallel, announce=announce)
