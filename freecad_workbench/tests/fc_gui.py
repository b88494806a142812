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

result = {"ok": False}
try:
    FreeCADGui.activateWorkbench("TabletcadWorkbench")
    wb = FreeCADGui.activeWorkbench()
    result["workbench"] = wb.name()
    result["commands"] = [c for c in FreeCADGui.listCommands() if c.startswith("Tabletcad_")]
    doc = FreeCAD.newDocument("gui")
    FreeCADGui.runCommand("Tabletcad_Tablet")
    tab = doc.Objects[-1]
    tab.Family = "concave_round"
    tab.CupDepth = 1.0
    doc.recompute()
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(tab)
    result["active"] = {
        c: FreeCADGui.Command.get(c).isActive() if hasattr(FreeCADGui, "Command") else None
        for c in ("Tabletcad_UpperPunch", "Tabletcad_Tooling")
    }
    FreeCADGui.runCommand("Tabletcad_Tooling")
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
    ]
    view = FreeCADGui.ActiveDocument.ActiveView
    view.viewIsometric()
    view.fitAll()
    from PySide import QtGui

    mw = FreeCADGui.getMainWindow()
    mw.resize(1200, 800)
    QtGui.QApplication.processEvents()
    result["window"] = bool(mw.grab().save(os.environ["TABLETCAD_FC_WINDOW"]))
    if os.environ.get("TABLETCAD_FC_SAVEIMAGE") == "1":
        # without an OpenGL context (plain offscreen platform) saveImage aborts FreeCAD
        view.saveImage(os.environ["TABLETCAD_FC_SHOT"], 1000, 750, "White")
        result["shot"] = os.environ["TABLETCAD_FC_SHOT"]
    result["ok"] = True
except Exception as exc:
    result["error"] = repr(exc)
    result["traceback"] = traceback.format_exc()
with open(os.environ["TABLETCAD_FC_OUTPUT"], "w") as fh:
    json.dump(result, fh)
os._exit(0)  # leave the GUI's event loop
