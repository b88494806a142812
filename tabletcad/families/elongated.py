"""Elongated tablets: capsule, modified capsule and oval (mm).

* ``capsule``: stadium plan (two semicircles of the width joined by straight
  sides); the cup runs across the whole width, so its cross-section is a
  single radius (or compound) arc and its ends are spherical (or compound)
  caps of revolution.
* ``modified_capsule``: four-arc plan with slightly curved sides of
  ``side_radius``; the end radius follows from tangency.
* ``oval``: four-arc plan given its ``end_radius``; the side radius follows.

For the four-arc plans the swept cup is horizontal at ``cup_width`` (at most
the end radius, the default) and the face centre is a flat plateau.
"""

from __future__ import annotations

from tabletcad.errors import check_positive
from tabletcad.families.outline import four_arc_oval, four_arc_oval_from_side_radius, stadium_outline
from tabletcad.families.shaped import outline_tablet
from tabletcad.families.family import lengths_checked
from tabletcad.families.sweep import DEFAULT_A
from tabletcad.geometry.tablet import Tablet
from tabletcad.tolerance import DEFAULT, Tolerances

__all__ = ["capsule", "modified_capsule", "oval"]


@lengths_checked()
def capsule(length: float = 18.0, width: float = 8.0, band: float = 3.0, cup_depth: float = 1.2, land: float = 0.0,
            central_radius: float = 0.0, edge_radius: float = 0.0, *, a=DEFAULT_A, tol: Tolerances = DEFAULT) -> Tablet:
    """Capsule: stadium plan ``length`` × ``width``, cup across the width, optional land (mm).

    ``central_radius`` and ``edge_radius`` both > 0 make the cup compound.
    """
    Ln = check_positive("length", length, "mm")
    W = check_positive("width", width, "mm")
    ol = stadium_outline(Ln, W)
    return outline_tablet(ol, band, cup_depth, land, W / 2.0, central_radius, edge_radius, name="capsule",
                          family="capsule", params=dict(length=Ln, width=W), reach=W / 2.0,
                          info=dict(shape="capsule", elongated=True), a=a, tol=tol)


@lengths_checked()
def modified_capsule(length: float = 18.0, width: float = 8.0, side_radius: float = 40.0, band: float = 3.0,
                     cup_depth: float = 0.6, land: float = 0.0, cup_width: float = 0.0, *, a=DEFAULT_A,
                     tol: Tolerances = DEFAULT) -> Tablet:
    """Modified capsule: four-arc plan ``length`` × ``width`` with sides of ``side_radius`` (mm)."""
    Ln = check_positive("length", length, "mm")
    W = check_positive("width", width, "mm")
    ol = four_arc_oval_from_side_radius(Ln, W, side_radius)
    ol.name = "modified_capsule"
    return outline_tablet(ol, band, cup_depth, land, cup_width, name="modified_capsule", family="modified_capsule",
                          params=dict(length=Ln, width=W, side_radius=float(side_radius)), reach=W / 2.0,
                          info=dict(elongated=True), a=a, tol=tol)


@lengths_checked()
def oval(length: float = 12.0, width: float = 7.0, end_radius: float = 2.5, band: float = 3.0, cup_depth: float = 0.8,
         land: float = 0.0, cup_width: float = 0.0, *, a=DEFAULT_A, tol: Tolerances = DEFAULT) -> Tablet:
    """Oval: four-arc plan ``length`` × ``width`` with ends of ``end_radius`` (mm)."""
    Ln = check_positive("length", length, "mm")
    W = check_positive("width", width, "mm")
    ol = four_arc_oval(Ln, W, end_radius)
    ol.name = "oval"
    return outline_tablet(ol, band, cup_depth, land, cup_width, name="oval", family="oval",
                          params=dict(length=Ln, width=W, end_radius=float(end_radius)), reach=W / 2.0,
                          info=dict(elongated=True), a=a, tol=tol)
