"""GUI entry point of ``freecad.tabletcad_wb``: FreeCAD imports it at start-up."""

import FreeCADGui as Gui
from freecad.tabletcad_wb import icon


class TabletcadWorkbench(Gui.Workbench):
    """Pharmaceutical tablets as PDE surfaces, with their punches and dies."""

    MenuText = "tabletcad"
    ToolTip = "Pharmaceutical tablets (Bloor-Wilson PDE surfaces) and their compression tooling"
    Icon = icon("Workbench")

    def Initialize(self):
        from freecad.tabletcad_wb import commands  # commands are registered only when the workbench is opened

        commands.register()
        self.appendToolbar("tabletcad", commands.TOOLBAR)
        self.appendMenu("tabletcad", commands.MENU)

    def Activated(self):
        pass

    def Deactivated(self):
        pass

    def GetClassName(self):
        return "Gui::PythonWorkbench"


Gui.addWorkbench(TabletcadWorkbench())
