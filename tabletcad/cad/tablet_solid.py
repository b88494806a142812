"""The B-rep solid of a :class:`~tabletcad.geometry.tablet.Tablet`.

Every face of the tablet's solid (:mod:`tabletcad.brep.surfaces`: its patches, or the
walls and end faces of a hollow tablet) is fitted by a B-spline (kernel-neutral
data from :mod:`tabletcad.brep`) - for a tablet of revolution only each face's profile,
revolved exactly (:mod:`tabletcad.brep.revolved`) - the faces are sewn into one closed shell and
the shell becomes an outward solid checked by ``BRepCheck_Analyzer``.  Tablets
trimmed in ``u`` or ``v`` (cut-away views) are refused here: the CAD stage builds
their solids (:func:`tabletcad.cad.stage.cutaway_solid`).
"""

from __future__ import annotations

from typing import Any

from tabletcad.brep.surfaces import fit_options, tablet_profiles, tablet_surface_functions
from tabletcad.errors import GeometryError
from tabletcad.geometry.tablet import Tablet

__all__ = ["tablet_solid"]


def tablet_solid(tablet: Tablet, tol: float | None = None, *, revolved: bool | None = None, **kwargs: Any):
    """Fit, sew and validate the tablet's solid; returns a :class:`~tabletcad.cad.solid.TabletSolid`.

    ``tol`` is the largest allowed distance (mm) between each face and its PDE surface
    (default ``tablet.tol.fit``).  A tablet of revolution (:attr:`Tablet.revolution
    <tabletcad.geometry.tablet.Tablet.revolution>`) gets exact faces of revolution of
    fitted profiles (:func:`~tabletcad.cad.solid.revolved_solid`) unless ``revolved=False``
    or B-spline fit options are given; every other tablet gets B-spline faces.
    ``revolved=True`` refuses a tablet that is not of revolution.
    """
    from tabletcad.cad.solid import build_solid, revolved_solid

    tol = tablet.tol.fit if tol is None else tol
    profiles = tablet_profiles(tablet) if revolved is not False and not kwargs else None
    if revolved and profiles is None:
        raise GeometryError(f"{tablet.name}: not a tablet of revolution (or B-spline fit options given)", tablet)
    if profiles is not None:
        return revolved_solid(profiles[0], tol, name=tablet.name, names=profiles[1],
                              degree=fit_options(tablet)["u_degree"])
    funcs, names = tablet_surface_functions(tablet)
    return build_solid(funcs, tol, name=tablet.name, names=names,
                       **fit_options(tablet, **kwargs))
