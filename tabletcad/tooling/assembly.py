"""STEP files of the tooling: one assembly with named parts, and each part alone.

``assembly.step`` holds an XCAF assembly named ``<tablet>_tooling`` whose
components are labelled ``tablet``, ``upper_punch``, ``lower_punch`` and
``die`` and coloured (:data:`PART_COLOURS`, surface colours of the parts), in the press position of the chosen punch gap (the upper punch
lifted by ``gap - band`` from the closed position).  ``upper_punch.step``,
``lower_punch.step`` and ``die.step`` hold one part each at the closed
position.  Every file is written atomically (:mod:`tabletcad.io.atomic`).
"""

from __future__ import annotations

from pathlib import Path

from OCP.TCollection import TCollection_ExtendedString
from OCP.TDataStd import TDataStd_Name
from OCP.TopLoc import TopLoc_Location
from OCP.gp import gp_Trsf, gp_Vec
from OCP.BRep import BRep_Builder
from OCP.TDF import TDF_Label

try:  # OCP >= 8.0
    from OCP.collections import Sequence_TDF_Label as TDF_LabelSequence
except ImportError:  # pragma: no cover - OCP 7.x
    from OCP.TDF import TDF_LabelSequence
from OCP.TopoDS import TopoDS_Compound
from OCP.Quantity import Quantity_Color, Quantity_TypeOfColor
from OCP.XCAFDoc import XCAFDoc_ColorType, XCAFDoc_DocumentTool, XCAFDoc_ShapeTool

from tabletcad.cad.export import export_step, step_document, write_step_document
from tabletcad.errors import GeometryError

__all__ = ["write_assembly", "write_parts", "read_assembly_colours", "PART_NAMES", "PART_COLOURS"]

PART_NAMES = ("tablet", "upper_punch", "lower_punch", "die")
# sRGB 0..1, as the FreeCAD workbench shows them: tablet off-white, punches steel blue, die grey
PART_COLOURS = {
    "tablet": (0.93, 0.93, 0.86),
    "upper_punch": (0.62, 0.68, 0.78),
    "lower_punch": (0.62, 0.68, 0.78),
    "die": (0.55, 0.55, 0.58),
}


def write_assembly(parts: dict, path, *, name: str = "tooling", offsets: dict | None = None) -> Path:
    """Write an XCAF assembly of ``parts`` (name -> solid) to ``path``; ``offsets`` (name -> dz mm)
    place components (as locations, the part shapes are stored once)."""
    offsets = offsets or {}
    doc, tool = step_document("AP214", assembly=True)
    names = [p for p in PART_NAMES if p in parts]
    builder, comp = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(comp)
    for part in names:
        tr = gp_Trsf()
        tr.SetTranslation(gp_Vec(0.0, 0.0, float(offsets.get(part, 0.0))))
        dz = float(offsets.get(part, 0.0))
        builder.Add(comp, parts[part].Moved(TopLoc_Location(tr)) if dz else parts[part])
    top = tool.AddShape(comp, True)  # an assembly: one component (and one part) per sub-shape
    TDataStd_Name.Set_s(top, TCollection_ExtendedString(str(name), True))  # UTF-8
    colours = XCAFDoc_DocumentTool.ColorTool_s(doc.Main())
    labels = TDF_LabelSequence()
    XCAFDoc_ShapeTool.GetComponents_s(top, labels, False)
    if labels.Length() != len(names):
        raise GeometryError(f"the assembly has {labels.Length()} components, expected {len(names)}", parts)
    for k, part in enumerate(names):
        comp_label = labels.Value(k + 1)
        TDataStd_Name.Set_s(comp_label, TCollection_ExtendedString(part, True))
        ref = TDF_Label()
        if XCAFDoc_ShapeTool.GetReferredShape_s(comp_label, ref):
            TDataStd_Name.Set_s(ref, TCollection_ExtendedString(part, True))
            r, g, b = PART_COLOURS[part]
            colours.SetColor(ref, Quantity_Color(r, g, b, Quantity_TypeOfColor.Quantity_TOC_sRGB),
                             XCAFDoc_ColorType.XCAFDoc_ColorSurf)
    return write_step_document(doc, path, what=f"the assembly {name}", obj=parts)


def write_parts(parts: dict, out_dir, names=("upper_punch", "lower_punch", "die")) -> list[Path]:
    """``<out_dir>/<name>.step`` for each part (one named solid per file)."""
    out = []
    for n in names:
        out.append(export_step(parts[n], Path(out_dir) / f"{n}.step", name=n))
    return out


def read_assembly_colours(path) -> dict:
    """``{part name: (r, g, b)}`` of an assembly STEP as OCP's XCAF reader sees them (for checks)."""
    from OCP.STEPCAFControl import STEPCAFControl_Reader
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_ColorTool

    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    reader = STEPCAFControl_Reader()
    reader.SetColorMode(True)
    reader.SetNameMode(True)
    reader.ReadFile(str(path))
    reader.Transfer(doc)
    top = TDF_LabelSequence()
    XCAFDoc_DocumentTool.ShapeTool_s(doc.Main()).GetFreeShapes(top)
    comps = TDF_LabelSequence()
    XCAFDoc_ShapeTool.GetComponents_s(top.Value(1), comps, False)
    out = {}
    for i in range(1, comps.Length() + 1):
        ref, name = TDF_Label(), TDataStd_Name()
        XCAFDoc_ShapeTool.GetReferredShape_s(comps.Value(i), ref)
        if not ref.FindAttribute(TDataStd_Name.GetID_s(), name):
            continue
        c = Quantity_Color()
        for lab in (comps.Value(i), ref):
            kinds = (XCAFDoc_ColorType.XCAFDoc_ColorGen, XCAFDoc_ColorType.XCAFDoc_ColorSurf)
            if any(XCAFDoc_ColorTool.GetColor_s(lab, t, c) for t in kinds):
                srgb = c.Values(Quantity_TypeOfColor.Quantity_TOC_sRGB)
                out[name.Get().ToExtString()] = tuple(round(x, 4) for x in srgb)
                break
    return out
