"""A TechDraw page of a Tablet: top and side views with the main dimensions.

:func:`make_page` adds a ``TechDraw::DrawPage`` (FreeCAD's A4 landscape template) with
two ``DrawViewPart`` views of the tablet - top (looking down z) and side (looking along
y) - and TechDraw's extent dimensions (``TechDraw.makeExtentDim``: the overall size of
a view along a direction) for the length (x) and width (y) on the top view and the
height (z) on the side view.  Works headless (``freecadcmd``): the projection and the
dimensions are computed by TechDraw's App layer, the page is saved with the document.
"""

from __future__ import annotations

import os

import FreeCAD

__all__ = ["make_page"]


def _template() -> str:
    for name in ("A4_LandscapeTD.svg", "A4_Landscape_blank.svg"):
        p = os.path.join(FreeCAD.getResourceDir(), "Mod", "TechDraw", "Templates", name)
        if os.path.isfile(p):
            return p
    return ""


def _view(doc, page, tablet, name, direction, scale, x, y):
    view = doc.addObject("TechDraw::DrawViewPart", name)
    page.addView(view)
    view.Source = [tablet]
    view.Direction = direction
    view.XDirection = FreeCAD.Vector(1, 0, 0)
    view.ScaleType = "Custom"
    view.Scale = scale
    view.X, view.Y = x, y
    return view


def make_page(doc, tablet, scale: float | None = None):
    """Page with the tablet's top and side views and its length, width and height (mm).

    ``scale``: drawing scale (default: the longest side about 60 mm on paper).
    Returns ``(page, views, dimensions)``, recomputed; ``dimensions`` maps
    ``length``/``width``/``height`` to ``DrawViewDimExtent`` objects."""
    import TechDraw

    bb = tablet.Shape.BoundBox
    if scale is None:
        scale = float(max(1, round(60.0 / max(bb.XLength, bb.YLength, bb.ZLength, 1e-9))))
    page = doc.addObject("TechDraw::DrawPage", "TabletDrawing")
    tmpl = doc.addObject("TechDraw::DrawSVGTemplate", "Template")
    tmpl.Template = _template()
    page.Template = tmpl
    page.Label = f"{tablet.Label} drawing"
    top = _view(doc, page, tablet, "TopView", FreeCAD.Vector(0, 0, 1), scale, 100.0, 120.0)
    side = _view(doc, page, tablet, "SideView", FreeCAD.Vector(0, -1, 0), scale, 210.0, 120.0)
    doc.recompute()
    dims = {}
    for key, view, direction in (("length", top, 0), ("width", top, 1), ("height", side, 1)):
        before = {o.Name for o in doc.Objects}
        TechDraw.makeExtentDim(view, [], direction)  # returns None: the new object is found
        (dim,) = [o for o in doc.Objects if o.Name not in before and o.TypeId == "TechDraw::DrawViewDimExtent"]
        dim.Label = f"{tablet.Label} {key}"
        dims[key] = dim
    _keep_projections(top, side)
    doc.recompute()
    return page, [top, side], dims


def _keep_projections(*views) -> None:
    """Spare the views a second projection after their extent dimensions were added.

    ``makeExtentDim`` adds its two end points to the view as cosmetic vertices, both to the
    ``CosmeticVertexes`` property and to the geometry just projected; the property's change marks the
    view for recompute, and FreeCAD 0.20 projected each view again for the same edges (the capsule's
    two views 1.0 s more, doubling the page's time; views, cosmetic vertices and dimensions measured
    bit-identical without it).  FreeCAD 1.0 projects in a worker thread and had not re-projected.

    Parameters
    ----------
    *views : TechDraw.DrawViewPart
        The page's views, projected and given their dimensions (a view whose source, direction or
        scale changed later is recomputed as usual).
    """
    for view in views:
        view.purgeTouched()
