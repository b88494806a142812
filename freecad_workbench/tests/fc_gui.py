"""GUI smoke test, run as ``freecad fc_gui.py``.

QT_QPA_PLATFORM=offscreen, with DISPLAY of an Xvfb when there is one (OpenGL for saveImage).

Loads the workbench, runs its commands, and writes the screenshot of the 3D view
(ActiveView.saveImage, needs OpenGL: only when TABLETCAD_FC_SAVEIMAGE=1) and a grab of the
main window.  Env: TABLETCAD_FC_OUTPUT, TABLETCAD_FC_SHOT, TABLETCAD_FC_WINDOW.
"""

import json
import os
import traceback

import FreeCAD
import FreeCADGui

result = {"ok": False, "reached": []}


def mark(name):  # how far the script got (written at once: a hang shows where), and when
    import time

    result["reached"].append(name)
    result.setdefault("reached_at", []).append(round(time.perf_counter(), 2))
    with open(os.environ["TABLETCAD_FC_OUTPUT"], "w") as fh:
        json.dump(result, fh)


try:
    FreeCADGui.activateWorkbench("TabletcadWorkbench")
    wb = FreeCADGui.activeWorkbench()
    result["workbench"] = wb.name()
    result["commands"] = [c for c in FreeCADGui.listCommands() if c.startswith("Tabletcad_")]
    doc = FreeCAD.newDocument("gui")
    from PySide import QtGui

    from freecad.tabletcad_wb import taskpanel

    # the Tablet command opens the task panel: family, dimensions, live validation, figures
    FreeCADGui.runCommand("Tabletcad_Tablet")
    panel = taskpanel.current
    mark("panel")
    result["panel_shown"] = FreeCADGui.Control.activeDialog()
    # a bevel that leaves a band of 0.0005 mm: the design's rule, checked by the recompute's function as you
    # type (the panel had said "valid" and OK refused it), quoting the field as typed
    panel.family.setCurrentIndex(panel.model.families.index("ffbe"))
    for key, text in (("bevel_angle", "45"), ("bevel_width", "0.15 cm"), ("thickness", "3.0005")):
        panel.type_text(key, text)
    result["panel_band"] = [panel.ok, panel.status.text()]
    panel.family.setCurrentIndex(panel.model.families.index("concave_round"))
    result["panel_fields"] = sorted(panel.spins)
    result["panel_suffix"] = panel.spins["diameter"].text()
    panel.type_text("cup_depth", "10 mm")  # deeper than a hemisphere: refused as you type
    result["panel_invalid"] = [panel.ok, panel.status.text()]
    mark("invalid")
    panel.type_text("cup_depth", "1")
    # units as typed (a plain spin box had read '0.4 in' as 0.4 mm), a quantity of another kind refused
    panel.type_text("diameter", "10 kg")
    result["panel_kg"] = [panel.ok, panel.status.text()]
    panel.type_text("diameter", "0.4 in")
    result["panel_inch"] = panel.model.values["diameter"]
    typed = {}
    for text in ("10.1234", "0.41 in", "1.2345 cm"):  # as typed, not rounded to the display's decimals (a review)
        panel.type_text("diameter", text)
        typed[text] = [panel.spins["diameter"].text(), panel.model.values["diameter"]]
    result["panel_typed"] = typed
    panel.type_text("diameter", "1 cm")  # (the drawing's checks below take the family's 10 mm)
    result["panel_valid"] = [panel.ok, panel.status.text(), panel.figures.text()]
    mark("valid")
    mw = FreeCADGui.getMainWindow()
    mw.resize(1200, 800)
    QtGui.QApplication.processEvents()
    if os.environ.get("TABLETCAD_FC_PANEL"):
        result["panel_png"] = bool(mw.grab().save(os.environ["TABLETCAD_FC_PANEL"]))
    mark("panel_png")
    result["panel_accept"] = bool(panel.accept())
    mark("accept")
    result["panel_closed"] = FreeCADGui.Control.activeDialog() is False
    tab = doc.Objects[-1]
    result["panel_tablet"] = [tab.Family, float(tab.CupDepth.Value), float(tab.Diameter.Value), bool(tab.isValid())]
    # editing one field keeps the others' exact values (the fields show 2-3 decimals; OK had written every
    # field back rounded, and capped at 100 mm)
    before = {k: getattr(tab, k) for k in ("Diameter", "Land", "CupDepth")}
    tab.Diameter = "10.0004 mm"
    tab.Land = "0.08349 mm"
    doc.recompute()
    from freecad.tabletcad_wb.taskpanel import edit_tablet

    edit = edit_tablet(tab)
    edit.type_text("cup_depth", "1.1 mm")
    result["panel_edit_accept"] = bool(edit.accept())
    result["panel_edited"] = [float(tab.Diameter.Value), float(tab.Land.Value), float(tab.CupDepth.Value),
                              bool(tab.isValid())]
    for k, v in before.items():  # (the checks below read the panel's tablet as it was made)
        setattr(tab, k, v)
    doc.recompute()
    # a design file's tablet is not edited in the panel (OK had made it the panel's first family)
    stadium = os.path.join(os.environ["TABLETCAD_ROOT"], "samples", "free_form_stadium.toml")
    from freecad.tabletcad_wb.make import make_tablet

    dt = make_tablet(doc, stadium)
    volume = float(dt.Volume)
    FreeCADGui.ActiveDocument.setEdit(dt.Name, 0)
    QtGui.QApplication.processEvents()
    result["design_file_edit"] = [taskpanel.current is None, FreeCADGui.Control.activeDialog(), dt.Family,
                                  float(dt.Volume) == volume]
    doc.removeObject(dt.Name)
    doc.recompute()

    # a refused value: what the Report view shows
    tab.CupDepth = 10.0
    doc.recompute()
    QtGui.QApplication.processEvents()
    reports = [w for w in mw.findChildren(QtGui.QTextEdit) if "report" in (w.objectName() or "").lower()]
    text = reports[0].toPlainText() if reports else ""
    result["report_view"] = [ln for ln in text.splitlines() if "cup_depth" in ln or "Traceback" in ln or "File " in ln]
    result["report_found"] = bool(reports)
    tab.CupDepth = 1.0
    doc.recompute()
    mark("report")
    # "Tablet from design" with a file the core refuses: its one line in the Report view, nothing added (an
    # invalid tablet had been)
    missing = os.path.join(os.environ["TABLETCAD_FC_WORK"], "no_such_design.toml")
    n_objects = len(doc.Objects)
    _open = QtGui.QFileDialog.getOpenFileName
    QtGui.QFileDialog.getOpenFileName = staticmethod(lambda *a, **k: (missing, ""))
    try:
        FreeCADGui.runCommand("Tabletcad_TabletFromDesign")
    finally:
        QtGui.QFileDialog.getOpenFileName = _open
    QtGui.QApplication.processEvents()
    text = reports[0].toPlainText() if reports else ""
    result["design_refused"] = [len(doc.Objects) - n_objects, missing,
                                [ln for ln in text.splitlines() if "no_such_design" in ln or "Traceback" in ln]]
    mark("design_refused")
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(tab)
    result["active"] = {
        c: FreeCADGui.Command.get(c).isActive() if hasattr(FreeCADGui, "Command") else None
        for c in ("Tabletcad_UpperPunch", "Tabletcad_Tooling")
    }
    FreeCADGui.runCommand("Tabletcad_Tooling")
    mark("tooling")
    for o in doc.Objects:
        if getattr(getattr(o, "Proxy", None), "Type", "") == "TabletcadPunch":
            o.Gap = 4.0
    doc.recompute()
    FreeCADGui.Selection.clearSelection()
    result["objects"] = [
        dict(
            name=o.Name,
            label=o.Label,
            valid=bool(o.isValid()),
            shape_valid=bool(o.Shape.isValid()),
            view_provider=type(o.ViewObject.Proxy).__name__
            if o.ViewObject is not None and o.ViewObject.Proxy
            else None,
            icon=o.ViewObject.Proxy.getIcon() if o.ViewObject is not None and o.ViewObject.Proxy else None,
        )
        for o in doc.Objects
        if getattr(getattr(o, "Proxy", None), "Type", "").startswith("Tabletcad")
    ]
    view = FreeCADGui.ActiveDocument.ActiveView
    view.viewIsometric()
    view.fitAll()
    mark("view")
    QtGui.QApplication.processEvents()
    result["window"] = bool(mw.grab().save(os.environ["TABLETCAD_FC_WINDOW"]))
    if os.environ.get("TABLETCAD_FC_SAVEIMAGE") == "1":
        # without an OpenGL context (plain offscreen platform) saveImage aborts FreeCAD
        view.saveImage(os.environ["TABLETCAD_FC_SHOT"], 1000, 750, "White")
        result["shot"] = os.environ["TABLETCAD_FC_SHOT"]
    # TechDraw page (1.0 projects in a worker thread: wait for it in the event loop)
    import time

    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(tab)
    FreeCADGui.runCommand("Tabletcad_Drawing")
    dims = [o for o in doc.Objects if o.TypeId == "TechDraw::DrawViewDimExtent"]
    t_end = time.time() + 60.0
    while time.time() < t_end and not all(d.getRawValue() > 0 for d in dims):
        QtGui.QApplication.processEvents()
        time.sleep(0.05)
        doc.recompute()
    result["drawing"] = {d.Label: float(d.getRawValue()) for d in dims}
    mark("drawing")
    result["ok"] = True
    asm = os.environ.get("TABLETCAD_FC_ASSEMBLY")
    if asm:  # FreeCAD's GUI STEP import of the tooling assembly: names and colours
        with open(os.environ["TABLETCAD_FC_OUTPUT"], "w") as fh:
            json.dump(result, fh)  # in case the import kills FreeCAD
        from freecad.tabletcad_wb.tasks import import_step

        d = FreeCAD.newDocument("assembly")
        import_step(asm, d)  # ImportGui.insert (0.20: without link groups)
        parts = {}
        for o in d.Objects:
            if o.TypeId == "Part::Feature" and o.Shape.Solids and o.ViewObject is not None:
                vo = o.ViewObject
                if hasattr(vo, "ShapeAppearance"):  # 1.0: materials
                    cols = [list(m.DiffuseColor)[:3] for m in vo.ShapeAppearance]
                else:
                    cols = [list(c)[:3] for c in (vo.DiffuseColor or [vo.ShapeColor])]
                parts[o.Label] = dict(valid=bool(o.Shape.isValid()), colours=cols)
        result["assembly"] = parts
        result["assembly_objects"] = [
            [o.Name, o.Label, o.TypeId, len(o.Shape.Solids) if hasattr(o, "Shape") else None] for o in d.Objects
        ]
        prefs = FreeCAD.ParamGet("User parameter:BaseApp/Preferences/Mod/Import")
        result["import_prefs"] = [prefs.GetBool("UseLinkGroup", True), prefs.GetInt("ImportMode", 0)]
except Exception as exc:
    result["error"] = repr(exc)
    result["traceback"] = traceback.format_exc()
with open(os.environ["TABLETCAD_FC_OUTPUT"], "w") as fh:
    json.dump(result, fh)
os._exit(0)  # leave the GUI's event loop
