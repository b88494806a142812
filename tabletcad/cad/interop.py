"""The solid as build123d and cadquery objects (both imported lazily).

Version constraints (the pins in ``pyproject.toml``):

* One OpenCascade for everything, OCP 7.9.3.1.1: the ``cad`` extra installs
  ``build123d==0.12.0`` on ``cadquery-ocp-novtk==7.9.3.1.1`` (build123d 0.13
  moved to OCP 8.0, which cadquery 2.8.0 cannot import).
* The ``cadquery`` extra adds ``cadquery==2.8.0`` with the VTK build
  ``cadquery-ocp==7.9.3.1.1`` of the same OCP (cadquery imports ``OCP.IVtkOCC``,
  which only the VTK wheel ships); both wheels install identical OCP files.

Both libraries wrap the solid's own topology and geometry (no copy, no translation) in a
new shape object (:func:`~tabletcad.cad._occ.handle`): moving or reorienting what they
return leaves the tablet or part it came from where it was.  This module also checks that
the installed library uses the OCP that built the shape.
"""

from __future__ import annotations

from typing import Any

from OCP.TopoDS import TopoDS_Shape

from tabletcad.cad._occ import cast, explore, handle, shape_type
from tabletcad.geometry.tablet import Tablet

__all__ = ["to_build123d", "to_build123d_part", "to_cadquery", "to_cadquery_workplane", "from_any", "build123d_boolean"]

_CQ_HINT = (
    "cadquery is not importable with this OCP ({err}); install the 'cadquery' extra "
    "(cadquery==2.8.0 with cadquery-ocp==7.9.3.1.1, the OCP of build123d 0.12.0): pip install 'tabletcad[cad,cadquery]'"
)
_BD_HINT = (
    "build123d is not importable ({err}); install the 'cad' extra "
    "(build123d==0.12.0 on cadquery-ocp-novtk==7.9.3.1.1): pip install 'tabletcad[cad]'"
)


def from_any(obj: Any) -> TopoDS_Shape:
    """The ``TopoDS_Shape`` of a tablet, a TabletSolid, a build123d or cadquery object (or a shape itself).

    A core :class:`~tabletcad.geometry.tablet.Tablet` gets its validated B-rep solid
    (:func:`tabletcad.cad.tablet_solid.tablet_solid`: fitted, sewn and checked); a scripting
    model (``tabletcad.make``, ``tabletcad.load``, a tooling part) gives its own.
    """
    if isinstance(obj, TopoDS_Shape):
        return obj
    if isinstance(obj, Tablet):
        from tabletcad.cad.tablet_solid import tablet_solid

        return tablet_solid(obj, revolved=False).shape  # B-spline faces: see TabletModel.solid
    to_occ = getattr(obj, "to_occ", None)
    if callable(to_occ):
        return from_any(to_occ())
    for attr in ("shape", "wrapped"):
        s = getattr(obj, attr, None)
        if isinstance(s, TopoDS_Shape):
            return s
    val = getattr(obj, "val", None)  # cadquery Workplane
    if callable(val):
        return from_any(val())
    raise TypeError(f"no TopoDS_Shape in {type(obj).__name__}")


def _solid_of(obj: Any):
    """The one solid of ``obj`` as a new handle (:func:`~tabletcad.cad._occ.handle`)."""
    shape = from_any(obj)
    if shape_type(shape) == "Solid":
        return handle(shape)
    solids = explore(shape, "Solid")
    if len(solids) != 1:
        raise TypeError(f"expected exactly one solid, found {len(solids)}")
    return handle(solids[0])


def _import_build123d():
    try:
        import build123d
    except Exception as exc:  # ImportError, or OCP mismatch errors
        raise ImportError(_BD_HINT.format(err=exc)) from exc
    return build123d


def _import_cadquery():
    try:
        import cadquery
    except Exception as exc:
        raise ImportError(_CQ_HINT.format(err=exc)) from exc
    return cadquery


def to_build123d(obj: Any):
    """A ``build123d.Solid`` wrapping the solid (its topology and geometry in a new handle: see the module)."""
    bd = _import_build123d()
    return bd.Solid(_solid_of(obj))


def to_build123d_part(obj: Any):
    """A ``build123d.Part`` (a compound holding the solid), usable in BuildPart / algebra mode."""
    bd = _import_build123d()
    return bd.Part(bd.Compound([bd.Solid(_solid_of(obj))]).wrapped)


def to_cadquery(obj: Any):
    """A ``cadquery.Solid`` wrapping the solid."""
    cq = _import_cadquery()
    return cq.Solid(_solid_of(obj))


def to_cadquery_workplane(obj: Any, plane: str = "XY"):
    """A ``cadquery.Workplane`` on ``plane`` whose stack holds the solid."""
    cq = _import_cadquery()
    return cq.Workplane(plane).add(cq.Solid(_solid_of(obj)))


def build123d_boolean(a: Any, b: Any, op: str, *, skip_clean: bool = False):
    """``a - b``, ``a + b`` or ``a & b`` (``op``) by build123d, ``a`` a solid (:func:`to_build123d`), ``b`` a
    build123d shape; NotImplemented when ``b`` is none.  ``skip_clean``: without build123d's face merging
    (``SkipClean``; OCCT 7.9's ``ShapeUpgrade_UnifySameDomain`` crashed on a shaped cut-away's flat B-spline
    faces)."""
    bd = _import_build123d()
    if not isinstance(b, bd.Shape):
        return NotImplemented
    a = to_build123d(a)

    def run():
        return a - b if op == "-" else a + b if op == "+" else a & b

    if skip_clean:
        with bd.SkipClean():
            return run()
    return run()
