"""GUI commands of the tabletcad workbench (registered lazily by the workbench's Initialize())."""

from __future__ import annotations

import FreeCAD
import FreeCADGui

from . import icon, objects
from .make import make_die, make_lower_punch, make_tablet, make_tooling, make_upper_punch

TOOLBAR = [
    "Tabletcad_Tablet",
    "Tabletcad_TabletFromDesign",
    "Tabletcad_UpperPunch",
    "Tabletcad_LowerPunch",
    "Tabletcad_Die",
    "Tabletcad_Tooling",
    "Tabletcad_ExportStep",
    "Tabletcad_Drawing",
]
MENU = TOOLBAR


def _selected_tablet():
    """The selected Tablet, else the document's only (or last) Tablet."""
    doc = FreeCAD.ActiveDocument
    if doc is None:
        return None
    for o in FreeCADGui.Selection.getSelection():
        if objects.is_tablet(o):
            return o
    tablets = [o for o in doc.Objects if objects.is_tablet(o)]
    return tablets[-1] if tablets else None


def _doc():
    return FreeCAD.ActiveDocument or FreeCAD.newDocument("tabletcad")


def _fit():
    if FreeCADGui.ActiveDocument is not None:
        FreeCADGui.SendMsgToActiveView("ViewFit")


def _transaction(doc, name, make):
    """``make()`` as one undo step named ``name`` (a command that adds objects is undone in one Std_Undo,
    which had taken back the edit before it); nothing of it is left when it fails."""
    doc.openTransaction(name)
    try:
        out = make()
    except Exception:
        doc.abortTransaction()
        raise
    doc.commitTransaction()
    return out


class _Command:
    name = ""
    icon = "Tablet"
    menu = ""
    tip = ""

    def GetResources(self):
        return {"Pixmap": icon(self.icon), "MenuText": self.menu, "ToolTip": self.tip}

    def IsActive(self):
        return True


class TabletCommand(_Command):
    name, icon = "Tabletcad_Tablet", "Tablet"
    menu = "Tablet..."
    tip = "Create a parametric tablet: family, dimensions and density in a task panel, checked as you type"

    def Activated(self):
        from .taskpanel import edit_tablet

        edit_tablet(None, _doc())


class TabletFromDesignCommand(_Command):
    name, icon = "Tabletcad_TabletFromDesign", "TabletDesign"
    menu = "Tablet from design file..."
    tip = "Create a tablet from a tabletcad design file (TOML)"

    def Activated(self):
        from PySide import QtGui

        from . import core_root

        root = core_root()
        start = str(root / "samples") if root else ""
        path, _ = QtGui.QFileDialog.getOpenFileName(
            None, "tabletcad design", start, "tabletcad design (*.toml)"
        )
        if not path:
            return
        from tabletcad.errors import TabletcadError

        doc = _doc()
        try:  # a design the core refuses adds nothing: its one line in the Report view (not a traceback)
            _transaction(doc, "Tablet from design", lambda: make_tablet(doc, path))
        except TabletcadError as exc:
            FreeCAD.Console.PrintError(f"tabletcad: {exc}\n")
            return
        _fit()


class _ToolCommand(_Command):
    def IsActive(self):
        return _selected_tablet() is not None


class UpperPunchCommand(_ToolCommand):
    name, icon, menu = "Tabletcad_UpperPunch", "UpperPunch", "Upper punch"
    tip = "Upper punch of the selected tablet (follows the tablet)"

    def Activated(self):
        doc = FreeCAD.ActiveDocument
        _transaction(doc, "Upper punch", lambda: make_upper_punch(doc, _selected_tablet()))


class LowerPunchCommand(_ToolCommand):
    name, icon, menu = "Tabletcad_LowerPunch", "LowerPunch", "Lower punch"
    tip = "Lower punch of the selected tablet (follows the tablet)"

    def Activated(self):
        doc = FreeCAD.ActiveDocument
        _transaction(doc, "Lower punch", lambda: make_lower_punch(doc, _selected_tablet()))


class DieCommand(_ToolCommand):
    name, icon, menu = "Tabletcad_Die", "Die", "Die"
    tip = "Die of the selected tablet: the bore is its outline (follows the tablet)"

    def Activated(self):
        doc = FreeCAD.ActiveDocument
        _transaction(doc, "Die", lambda: make_die(doc, _selected_tablet()))


class ToolingCommand(_ToolCommand):
    name, icon, menu = "Tabletcad_Tooling", "Tooling", "Punches and die"
    tip = "Upper punch, lower punch and die of the selected tablet"

    def Activated(self):
        doc = FreeCAD.ActiveDocument
        _transaction(doc, "Punches and die", lambda: make_tooling(doc, _selected_tablet()))
        _fit()


class ExportStepCommand(_ToolCommand):
    name, icon, menu = "Tabletcad_ExportStep", "ExportStep", "Export STEP..."
    tip = "Write the tablets and their tooling as STEP files"

    def Activated(self):
        from PySide import QtGui

        from . import tasks

        d = QtGui.QFileDialog.getExistingDirectory(None, "STEP output folder")
        if d:
            doc = FreeCAD.ActiveDocument
            _transaction(doc, "Export STEP", lambda: tasks.export_step(doc, d))


class DrawingCommand(_ToolCommand):
    name, icon, menu = "Tabletcad_Drawing", "TabletDesign", "Drawing (TechDraw)"
    tip = "TechDraw page of the selected tablet: top and side views with length, width and height"

    def Activated(self):
        from .techdraw import make_page

        doc = FreeCAD.ActiveDocument
        page, _, _ = _transaction(doc, "Tablet drawing", lambda: make_page(doc, _selected_tablet()))
        if hasattr(page, "ViewObject") and page.ViewObject is not None:
            page.ViewObject.show()


COMMANDS = [
    TabletCommand,
    TabletFromDesignCommand,
    UpperPunchCommand,
    LowerPunchCommand,
    DieCommand,
    ToolingCommand,
    ExportStepCommand,
    DrawingCommand,
]


def register() -> None:
    for cls in COMMANDS:
        if cls.name not in FreeCADGui.listCommands():
            FreeCADGui.addCommand(cls.name, cls())
