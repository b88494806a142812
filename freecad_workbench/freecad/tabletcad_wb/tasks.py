"""What the macros do (importable, so the macros stay thin and the tests can call the same code).

Every task works headless (``freecadcmd``); with the GUI up it also shows its result.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import FreeCAD

from . import core_root, objects
from .make import make_tablet, make_tooling

__all__ = [
    "active_doc",
    "export_step",
    "heckel",
    "import_step",
    "optimise",
    "out_dir",
    "sample",
    "tablet_from_design",
]


def sample(rel: str) -> Path:
    """A file of the repository's ``samples/`` folder."""
    root = core_root()
    if root is None:
        raise FileNotFoundError("the tabletcad repository was not found (run freecad_workbench/install.sh)")
    return root / "samples" / rel


def out_dir(default: str = "tabletcad_out") -> Path:
    """``$TABLETCAD_OUT`` or ``./tabletcad_out``; created."""
    p = Path(os.environ.get("TABLETCAD_OUT") or Path.cwd() / default)
    p.mkdir(parents=True, exist_ok=True)
    return p


def active_doc(name: str = "tabletcad"):
    return FreeCAD.ActiveDocument or FreeCAD.newDocument(name)


def _fit_view():
    if FreeCAD.GuiUp:
        import FreeCADGui

        if FreeCADGui.ActiveDocument is not None:
            view = FreeCADGui.ActiveDocument.ActiveView
            if hasattr(view, "viewIsometric"):
                view.viewIsometric()
            FreeCADGui.SendMsgToActiveView("ViewFit")


def tablet_from_design(path, doc=None):
    """Tablet object from a design file (TOML); recomputed."""
    doc = doc or active_doc()
    obj = make_tablet(doc, str(path))
    if not obj.isValid():
        raise RuntimeError(f"{obj.Label}: {obj.getStatusString()}")
    _fit_view()
    return obj


def export_step(doc=None, directory=None, with_tooling=True):
    """Write every tablet (and its tooling, made if missing) as STEP: one file per object
    (``Shape.exportStep``) and one file with all of them (``Import.export``).
    Returns ``{label: path}`` (``"all"`` for the combined file)."""
    import Import

    doc = doc or FreeCAD.ActiveDocument
    if doc is None:
        raise RuntimeError("no document: create a tablet first")
    directory = Path(directory) if directory else out_dir("tabletcad_step")
    directory.mkdir(parents=True, exist_ok=True)
    tablets = [o for o in doc.Objects if objects.is_tablet(o)]
    if not tablets:
        raise RuntimeError(f"document {doc.Label} has no tabletcad Tablet")
    skipped = {}
    if with_tooling:
        made = {}
        for t in tablets:
            linked = [
                o
                for o in t.InList
                if getattr(getattr(o, "Proxy", None), "Type", "") in ("TabletcadPunch", "TabletcadDie")
            ]
            if not linked:
                try:
                    made[t.Label] = make_tooling(doc, t, recompute=False)
                except Exception as exc:  # (a tablet too large for a standard die: refused before any part)
                    skipped[t.Label] = " ".join(str(exc).split())
        doc.recompute()
        # a tablet that cannot have tooling (a sphere has no band, a cut-away no whole outline) is exported
        # alone: the tools made for it, which could not be built, are taken out again
        for label, parts in made.items():
            bad = [o for o in parts if not o.isValid() or o.Shape.isNull()]
            if bad:
                skipped[label] = " ".join(str(bad[0].getStatusString() or "recompute failed").split())
                for o in parts:
                    doc.removeObject(o.Name)
        if skipped:
            doc.recompute()
    wanted = [
        o for o in doc.Objects if getattr(getattr(o, "Proxy", None), "Type", "").startswith("Tabletcad")
    ]
    bad = [o.Label for o in wanted if not o.isValid() or o.Shape.isNull()]
    if bad:
        raise RuntimeError(f"not exported, recompute failed: {', '.join(bad)}")
    out = {}
    all_name = _safe(doc.Label) + "_all"
    taken = {all_name.casefold()}
    for o in wanted:
        # two labels may make one file name ("CR 9mm" and "CR_9mm"): the second had overwritten the first's file
        stem = base = _safe(o.Label)
        k = 1
        while stem.casefold() in taken:  # (casefold: a file system that ignores case too)
            k += 1
            stem = f"{base}_{k}"
        taken.add(stem.casefold())
        p = directory / (stem + ".step")
        o.Shape.exportStep(str(p))
        out[o.Label] = str(p)
    allp = directory / (all_name + ".step")
    Import.export(wanted, str(allp))
    out["all"] = str(allp)
    for label, why in skipped.items():
        FreeCAD.Console.PrintWarning(f"tabletcad: {label} exported without tooling: {why}\n")
    FreeCAD.Console.PrintMessage(f"tabletcad: STEP written to {directory}\n")
    return out


def import_step(path, doc=None):
    """Insert a STEP file (e.g. the tooling's ``assembly.step``) with its part names and colours:
    ``ImportGui.insert`` with the GUI up, else ``Import.insert``.

    FreeCAD 0.20's importer with link groups (its default) crashes on every multi-part STEP
    file, FreeCAD's own exports too (headless: SIGSEGV; GUI: caught, then one grey compound);
    on 0.20 the Import preference ``UseLinkGroup`` is switched off for this import and
    restored afterwards.  Returns the new document objects."""
    doc = doc or active_doc()
    prefs = FreeCAD.ParamGet("User parameter:BaseApp/Preferences/Mod/Import")
    old = prefs.GetBool("UseLinkGroup", True)
    legacy = tuple(int(x) for x in FreeCAD.Version()[:2]) < (1, 0)
    before = {o.Name for o in doc.Objects}
    try:
        if legacy:
            prefs.SetBool("UseLinkGroup", False)
        if FreeCAD.GuiUp:
            import ImportGui

            ImportGui.insert(str(path), doc.Name)
        else:
            import Import

            Import.insert(str(path), doc.Name)
    finally:
        prefs.SetBool("UseLinkGroup", old)
    return [o for o in doc.Objects if o.Name not in before]


def _safe(label: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in label)


def heckel(press_path, png=None, show=True):
    """Heckel analysis of a press record (CSV + TOML metadata beside it): fit, PNG plot.
    Returns a summary dict (``Py_MPa``, ``K_per_MPa``, ``A``, ``r2``, ``window_MPa``, ``png``)."""
    from tabletcad.mechanics import compaction_curves, fit_heckel, plot_heckel, read_press_data

    press_path = Path(press_path)
    data = read_press_data(press_path)
    curves = compaction_curves(data)
    fit = fit_heckel(curves)
    png = Path(png) if png else out_dir("tabletcad_heckel") / (press_path.stem + "_heckel.png")
    plot_heckel(fit, png, title=f"Heckel: {press_path.stem}")
    summary = dict(
        Py_MPa=float(fit.Py_MPa),
        K_per_MPa=float(fit.K_per_MPa),
        A=float(fit.A),
        r2=float(fit.r2),
        window_MPa=[float(x) for x in fit.window_MPa],
        n_points=int(fit.n_points),
        png=str(png),
    )
    FreeCAD.Console.PrintMessage("tabletcad Heckel: " + json.dumps(summary) + "\n")
    if show and FreeCAD.GuiUp:
        _show_image(png)
    return summary


def _show_image(png):
    try:
        import ImageGui

        ImageGui.open(str(png))
    except Exception as exc:  # the Image workbench is optional
        FreeCAD.Console.PrintWarning(f"tabletcad: cannot show {png} ({exc})\n")


def optimise(problem_path, doc=None, directory=None, method=None, **solver_options):
    """Solve an optimisation problem file and load its optimum as a Tablet.
    Returns ``(result, design_path, tablet_object)``."""
    from tabletcad.optimise import solve
    from tabletcad.optimise.files import load_problem

    problem, default_method, options = load_problem(Path(problem_path))
    options = {**options, **solver_options}
    result = solve(problem, method or default_method, **options)
    FreeCAD.Console.PrintMessage(
        f"tabletcad optimise: {result.status} {result.objective_name} = "
        f"{result.objective:.6g} {result.objective_unit} "
        f"at {json.dumps({k: round(float(v), 6) for k, v in result.x.items()})}\n"
    )
    if problem.to_toml is None:
        raise RuntimeError(f"problem {problem.name} has no design to load")
    directory = Path(directory) if directory else out_dir("tabletcad_optimise")
    design = directory / f"{_safe(problem.name)}.toml"
    design.write_text(problem.to_toml(result.x, result.design), encoding="utf-8")
    obj = tablet_from_design(design, doc)
    return result, design, obj
