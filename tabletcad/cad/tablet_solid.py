"""The B-rep solid of a :class:`~tabletcad.geometry.tablet.Tablet`.

Every face of the tablet's solid (:mod:`tabletcad.brep.surfaces`: its patches, or the
walls and end faces of a hollow tablet) is fitted by a B-spline (kernel-neutral
data from :mod:`tabletcad.brep`), the faces are sewn into one closed shell and
the shell becomes an outward solid checked by ``BRepCheck_Analyzer``.  Tablets
trimmed in ``u`` or ``v`` (cut-away views) are refused here: the CAD stage builds
their solids (:func:`tabletcad.cad.stage.cutaway_solid`).
"""

from __future__ import annotations

from typing import Any

from tabletcad.brep.surfaces import fit_options, tablet_surface_functions
from tabletcad.geometry.tablet import Tablet

__all__ = ["tablet_solid"]


def tablet_solid(tablet: Tablet, tol: float | None = None, **kwargs: Any):
    """Fit, sew and validate the tablet's solid; returns a :class:`~tabletcad.cad.solid.TabletSolid`.

    ``tol`` is the largest allowed distance (mm) between each B-spline face
    and its PDE surface (default ``tablet.tol.fit``).
    """
    from tabletcad.cad.solid import build_solid

    funcs, names = tablet_surface_functions(tablet)
    return build_solid(funcs, tablet.tol.fit if tol is None else tol, name=tablet.name, names=names,
                       **fit_options(tablet, **kwargs))
