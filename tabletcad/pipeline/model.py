"""Scripting facade: tablets and tooling parts that behave like build123d / cadquery objects.

::

    import tabletcad

    m = tabletcad.make("concave_round", diameter=10, band=2, cup_depth=1)
    m.volume                      # mm³, the core's quadrature
    part = m.to_build123d()       # build123d.Solid on the same topology (moving it leaves m as it is)
    wp = m.to_cadquery()          # cadquery.Workplane holding the solid
    m.export("tablet.step")
    tools = m.tooling(clearance_mm=0.03)
    tools.upper_punch.to_build123d()

The core :class:`tabletcad.geometry.tablet.Tablet` never imports OpenCascade; this
module sits after it in the flow and imports the CAD layer only inside the
methods that need it, so ``import tabletcad.pipeline.model`` stays numpy-only.
"""

from __future__ import annotations

import html
import math
import io
import uuid
import json
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any, NamedTuple, Sequence

import numpy as np

from tabletcad.errors import DesignError, GeometryError
from tabletcad.geometry.tablet import Tablet
from tabletcad.pipeline.design import Design
from tabletcad.tolerance import DEFAULT

__all__ = ["BoundingBox", "TabletModel", "PartModel", "ToolingModel", "make", "load", "show", "mesh_html", "mesh_png"]

#: Tessellation used for the notebook view (mm, rad): coarse enough for a small page.
VIEW_DEFLECTION = (0.02, 0.35)


class Vec3(NamedTuple):
    """A point or extent (mm) that reads as build123d's ``Vector`` does (``.X``, ``.Y``, ``.Z``, ``length``) and
    computes as it does: ``+`` and ``-`` with another vector or a 3-tuple, ``*`` and ``/`` by a number, unary
    ``-`` (a tuple's ``+`` had joined two boxes' corners into a 6-tuple, its ``*`` repeated them); it is a tuple
    otherwise (unpacking, indexing, equality)."""

    X: float
    Y: float
    Z: float

    @property
    def length(self) -> float:
        """Euclidean length (mm)."""
        return math.sqrt(self.X * self.X + self.Y * self.Y + self.Z * self.Z)

    def _other(self, other: Any) -> tuple[float, float, float]:
        o = tuple(other)
        if len(o) != 3:
            raise TypeError(f"a vector takes a vector or 3 numbers, not {len(o)}")
        return float(o[0]), float(o[1]), float(o[2])

    def __add__(self, other: Any) -> "Vec3":  # type: ignore[override]
        x, y, z = self._other(other)
        return Vec3(self.X + x, self.Y + y, self.Z + z)

    __radd__ = __add__

    def __sub__(self, other: Any) -> "Vec3":
        x, y, z = self._other(other)
        return Vec3(self.X - x, self.Y - y, self.Z - z)

    def __rsub__(self, other: Any) -> "Vec3":
        x, y, z = self._other(other)
        return Vec3(x - self.X, y - self.Y, z - self.Z)

    def __mul__(self, k: Any) -> "Vec3":  # type: ignore[override]
        if isinstance(k, bool) or not isinstance(k, (int, float, np.integer, np.floating)):
            return NotImplemented
        return Vec3(self.X * k, self.Y * k, self.Z * k)

    __rmul__ = __mul__

    def __truediv__(self, k: Any) -> "Vec3":
        if isinstance(k, bool) or not isinstance(k, (int, float, np.integer, np.floating)):
            return NotImplemented
        return Vec3(self.X / k, self.Y / k, self.Z / k)

    def __neg__(self) -> "Vec3":
        return Vec3(-self.X, -self.Y, -self.Z)


@dataclass(frozen=True)
class BoundingBox:
    """An axis-aligned box (mm), named as build123d's ``BoundBox``: ``min`` and ``max`` corners, ``size``
    (each a :class:`Vec3`: ``box.size.X``), ``diagonal`` and ``center()``."""

    min: Vec3
    max: Vec3

    def __post_init__(self) -> None:
        object.__setattr__(self, "min", Vec3(*map(float, self.min)))
        object.__setattr__(self, "max", Vec3(*map(float, self.max)))

    @property
    def size(self) -> Vec3:
        """Extents along x, y, z (mm)."""
        return Vec3(*(b - a for a, b in zip(self.min, self.max)))

    @property
    def diagonal(self) -> float:
        """Length of the box's diagonal (mm)."""
        return float(np.linalg.norm(self.size))

    def center(self) -> Vec3:
        """The box's centre (mm)."""
        return Vec3(*(0.5 * (a + b) for a, b in zip(self.min, self.max)))


class _Shaped:
    """The shared build123d/cadquery vocabulary of a tablet and of each tooling part: ``to_*``, ``volume``,
    ``area``, ``bounding_box()``, ``export``, ``mesh``, and the Booleans ``-``, ``+`` and ``&`` with another
    model or a build123d shape (build123d does the Boolean on :meth:`to_build123d`; its result, which for an
    empty ``&`` is None as build123d's own; another operand is a TypeError)."""

    #: True where OCC's face merging, which build123d runs after a Boolean, crashed the process on the
    #: model's faces (a shaped cut-away's flat B-spline faces): its Booleans skip the merge
    _skip_clean = False

    name: str

    def to_occ(self):  # pragma: no cover - overridden
        raise NotImplementedError

    @property
    def area(self) -> float:
        """Surface area (mm²) of the B-rep by OpenCascade's adaptive integration."""
        from tabletcad.cad.solid import mass_properties

        return mass_properties(self.to_occ()).area

    def bounding_box(self) -> BoundingBox:
        """The solid's axis-aligned box (mm) from its exact geometry (``BRepBndLib::AddOptimal``)."""
        from tabletcad.cad.solid import tight_bounds

        return BoundingBox(*tight_bounds(self.to_occ()))

    def _boolean(self, other: Any, op: str):
        from tabletcad.cad.interop import build123d_boolean

        skip = self._skip_clean or getattr(other, "_skip_clean", False)  # (a shaped cut-away: faces not merged)
        if isinstance(other, _Shaped):
            other = other.to_build123d()
        return build123d_boolean(self.to_occ(), other, op, skip_clean=skip)

    def __sub__(self, other: Any):
        """``self.to_build123d() - other`` (a model or a build123d shape): a build123d shape."""
        return self._boolean(other, "-")

    def __add__(self, other: Any):
        """``self.to_build123d() + other``: the union, a build123d shape."""
        return self._boolean(other, "+")

    def __and__(self, other: Any):
        """``self.to_build123d() & other``: the intersection, a build123d shape."""
        return self._boolean(other, "&")

    def to_build123d(self):
        """A ``build123d.Solid`` on the solid's own topology and geometry (no copy), in a new shape object:
        moving it (``.move``, ``.locate``) leaves this model, its exports and its tooling where they were."""
        from tabletcad.cad.interop import to_build123d

        return to_build123d(self.to_occ())

    def to_cadquery(self, plane: str = "XY"):
        """A ``cadquery.Workplane`` on ``plane`` whose stack holds the solid."""
        from tabletcad.cad.interop import to_cadquery_workplane

        return to_cadquery_workplane(self.to_occ(), plane)

    @property
    def occ_volume(self) -> float:
        """Volume (mm³) of the B-rep by OpenCascade's adaptive integration."""
        from tabletcad.cad.solid import mass_properties

        return mass_properties(self.to_occ()).volume

    def export(self, path: str | Path, **kw: Any) -> Path:
        """Write the solid in the format named by the suffix (.step .stl .3mf .glb .brep)."""
        from tabletcad.cad.export import export

        return export(self.to_occ(), path, name=kw.pop("name", self.name), **kw)

    def mesh(self, linear_deflection: float = DEFAULT.mesh_deflection, angular_deflection: float = DEFAULT.mesh_angle,
             check: bool = False):
        """:class:`tabletcad.cad.mesh.MeshResult` of the solid (mm, rad)."""
        from tabletcad.cad.mesh import tessellate

        return tessellate(self.to_occ(), linear_deflection, angular_deflection, check=check)

    def _view_meshes(self) -> list[tuple[str, np.ndarray, np.ndarray]]:
        m = self.mesh(*VIEW_DEFLECTION)
        return [(self.name, m.vertices, m.triangles)]

    def _repr_html_(self) -> str | None:
        """The notebook's 3-D view; None (the notebook then shows the PNG) for a view with no solid to mesh:
        a cut-away in ``u`` or a hollow tablet (a :class:`GeometryError` had printed its traceback first)."""
        try:
            meshes = self._view_meshes()
        except GeometryError:
            return None
        return mesh_html(meshes, title=self.name)

    def _repr_png_(self) -> bytes:
        return mesh_png(self._view_meshes(), title=self.name)


@dataclass(frozen=True, eq=False)
class PartModel(_Shaped):
    """One solid of a tool set (``tablet``, ``upper_punch``, ``lower_punch``, ``die``)."""

    name: str
    _shape: Any = field(repr=False)  # the tool set's TopoDS_Shape, never handed out itself

    @property
    def shape(self):
        """The part's shape (a solid), a new handle on its topology and geometry each time
        (:func:`tabletcad.cad._occ.handle`: moving it leaves the part, the tool set and its exports where
        they are; the attribute had handed out the tool set's own shape)."""
        from tabletcad.cad._occ import handle

        return handle(self._shape)

    def to_occ(self):
        """:attr:`shape`."""
        return self.shape

    @property
    def volume(self) -> float:
        """Volume (mm³) by OpenCascade's adaptive integration."""
        return self.occ_volume

    def __repr__(self) -> str:
        return f"PartModel({self.name!r})"


@dataclass(frozen=True, eq=False)
class ToolingModel:
    """A tablet's tool set (:func:`tabletcad.tooling.toolset.make_tooling`) as scriptable parts.

    ``parts`` are at the closed position; :meth:`placed` lifts the upper punch to the
    spec's gap.  ``report`` is the ``tooling`` section of ``report.json``.
    """

    toolset: Any  # tabletcad.tooling.toolset.ToolSet
    parts: dict[str, PartModel] = field(init=False)

    def __post_init__(self) -> None:
        from tabletcad.readonly import TableDict

        object.__setattr__(self, "parts", TableDict({k: PartModel(k, v) for k, v in self.toolset.parts.items()}))

    @property
    def report(self) -> dict[str, Any]:
        """The ``tooling`` section of ``report.json``: a copy (changing it leaves the tool set's as it is)."""
        import copy

        return copy.deepcopy(self.toolset.report)

    def placed(self) -> dict[str, PartModel]:
        """Parts at the press position of the spec's ``gap_mm``."""
        return {k: PartModel(k, v) for k, v in self.toolset.placed().items()}

    def __getitem__(self, name: str) -> PartModel:
        return self.parts[name]

    def __getattr__(self, name: str) -> PartModel:
        parts = self.__dict__.get("parts", {})
        if name in parts:
            return parts[name]
        raise AttributeError(name)

    def _repr_html_(self) -> str:
        meshes = []
        for p in self.placed().values():
            meshes.extend(p._view_meshes())
        return mesh_html(meshes, title="tooling")

    def _repr_png_(self) -> bytes:
        meshes = []
        for p in self.placed().values():
            meshes.extend(p._view_meshes())
        return mesh_png(meshes, title="tooling")

    def __repr__(self) -> str:
        return f"ToolingModel({', '.join(self.parts)})"


@dataclass(frozen=True, eq=False)
class TabletModel(_Shaped):
    """A core :class:`~tabletcad.geometry.tablet.Tablet` (``.tablet``) with CAD, export and notebook methods.

    The B-rep is fitted on first use (:func:`tabletcad.cad.tablet_solid.tablet_solid`) and kept.
    ``design``: the :class:`~tabletcad.pipeline.design.Design` it was built from (:func:`load`,
    :func:`make`), whose ``[report]`` options and ``[tooling]`` specification :meth:`report` and
    :meth:`tooling` use, and which :meth:`replace` changes; None for a model of a bare core tablet.

    Models of equal designs (the same tables, read from the same folder) are equal and hash alike: a build
    is a function of its design (``make("oval", ...) == make("oval", ...)``, ``m == m.replace()``); a model
    of a bare core tablet is equal only to itself.
    """

    tablet: Tablet
    design: Design | None = None

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, TabletModel):
            return NotImplemented
        if self.design is None or other.design is None:
            return self is other
        return self.design == other.design and self.design.folder == other.design.folder

    def __hash__(self) -> int:
        return object.__hash__(self) if self.design is None else hash(self.design)

    @property
    def name(self) -> str:
        return self.tablet.name

    def replace(self, **changes: Any) -> TabletModel:
        """The same design with ``[tablet]`` values changed (mm, deg), its other tables kept:
        ``m.replace(length=18.0)``.  The tablet's ``params`` are what it was built with, derived values
        included (a capsule's cup width), so ``make(family, **params)`` with one of them changed may
        refuse what this accepts.  Checked as :func:`make` checks, before any geometry."""
        if self.design is None:
            raise ValueError(f"{self.name}: a model of a bare core tablet has no design to change; make it with "
                             "tabletcad.make or tabletcad.load")
        data = self.design.to_dict()
        data["tablet"].update(changes)
        design = Design.from_dict(data, default_name=self.design.name, comment=self.design.comment,
                                  folder=self.design.folder)
        return TabletModel(design.build(), design)

    @property
    def volume(self) -> float:
        """Volume (mm³) from the core's Gauss quadrature of the PDE patches."""
        return self.tablet.volume()

    @property
    def area(self) -> float:
        """Surface area (mm²) of the (trimmed) solid's boundary by the core's quadrature, as :attr:`volume`:
        the patches' outer faces, and a trimmed tablet's cut faces (``[trim] u``, ``v``) and inner faces
        (``w``) too (:meth:`~tabletcad.geometry.tablet.Tablet.faces`), no B-rep needed.  On cut-aways in
        ``v`` it agrees with OpenCascade's area of :meth:`to_occ` to 5e-8 relative; it had been taken from
        that solid, so a view with none (trimmed in ``u``, a hollow round cut-away) raised GeometryError."""
        return self.tablet.surface_area()

    @property
    def _skip_clean(self) -> bool:
        """A shaped cut-away (its flat faces stay B-splines, on which OCC's face merging crashed)."""
        return not self._whole and self.tablet.revolution is None

    def bounding_box(self) -> BoundingBox:
        """The tablet's axis-aligned box (mm) from the core (:meth:`~tabletcad.geometry.tablet.Tablet.bounds`,
        polished to ~1e-9 mm; a cut-away's with its cut faces), no B-rep needed."""
        lo, hi = self.tablet.bounds()
        return BoundingBox(tuple(map(float, lo)), tuple(map(float, hi)))

    @cached_property
    def _solid(self):
        from tabletcad.cad.tablet_solid import tablet_solid

        return tablet_solid(self.tablet, revolved=False)

    @property
    def solid(self):
        """The validated :class:`~tabletcad.cad.solid.TabletSolid` (B-spline faces, sewn), a copy whose
        ``shape`` is a new handle (moving it leaves the model, its exports and its tooling where they are).

        B-spline faces even for a tablet of revolution (whose ``tabletcad build`` STEP has exact
        surfaces of revolution): a surface of revolution has no normal at its pole, where
        cadquery's ``faces(">Z").workplane()`` asks for one (the face's centre projects onto it).
        """
        from dataclasses import replace

        from tabletcad.cad._occ import handle

        sol = self._solid
        return replace(sol, shape=handle(sol.shape), faces=tuple(handle(f) for f in sol.faces))

    def to_occ(self):
        """The tablet's ``TopoDS_Solid``; for a cut-away view (``[trim] u`` or ``v``) the cut-away's,
        made and checked as ``tabletcad build`` makes it (:func:`tabletcad.cad.stage.cutaway_solid`).  A new
        handle on its topology and geometry each call (:func:`tabletcad.cad._occ.handle`): moving it
        (``Move``, build123d's ``.move``) leaves the model, its exports and its tooling where they were."""
        from tabletcad.cad._occ import handle

        return handle(self._solid.shape if self._whole else self._cutaway_shape.shape)

    @property
    def _whole(self) -> bool:
        t = self.tablet.trim
        return t.u == (0.0, 1.0) and t.full_v

    @cached_property
    def _cutaway_shape(self):
        """The cut-away's solid as ``tabletcad build`` makes and checks it
        (:func:`tabletcad.cad.stage.cutaway_shape`).  A wedge-cut one's mesh is made and checked with it, as
        the build's is (a failed check refuses the cut-away); a shaped one's (ruled cut faces), which
        never refuses it, when first asked for (:attr:`_cutaway_mesh`): a Boolean of the solid needs none."""
        from tabletcad.cad.stage import cutaway_mesh, cutaway_shape
        from tabletcad.errors import GeometryError

        made = cutaway_shape(self.tablet, {"volume_mm3": self.tablet.volume()})
        if isinstance(made, str):
            raise GeometryError(f"{self.name}: no solid for this cut-away view: {made}", self.tablet)
        if made.chain is None:
            self.__dict__["_cutaway_mesh"] = cutaway_mesh(made)[1]
        return made

    @cached_property
    def _cutaway_mesh(self):
        """The cut-away's mesh as ``tabletcad build`` makes and checks it (its faces' own grids; OCC's
        mesher leaves the folded cut faces of a shaped cut-away open), or None where that tessellation
        does not close."""
        from tabletcad.cad.stage import cutaway_mesh

        made = self._cutaway_shape  # (a wedge-cut cut-away's mesh is made with its solid)
        return self.__dict__["_cutaway_mesh"] if "_cutaway_mesh" in self.__dict__ else cutaway_mesh(made)[1]

    def mesh(self, linear_deflection: float = DEFAULT.mesh_deflection, angular_deflection: float = DEFAULT.mesh_angle,
             check: bool = False):
        """:class:`tabletcad.cad.mesh.MeshResult` of the solid (mm, rad); a cut-away's at the default
        deflections is the one ``tabletcad build`` writes (checked)."""
        if not self._whole and (linear_deflection, angular_deflection) == (DEFAULT.mesh_deflection, DEFAULT.mesh_angle) \
                and self._cutaway_mesh is not None:
            return self._cutaway_mesh
        return super().mesh(linear_deflection, angular_deflection, check=check)

    def export(self, path: str | Path, **kw: Any) -> Path:
        """Write the tablet in the format named by the suffix (.step .stl .3mf .glb .brep), as ``tabletcad
        build`` writes it: a whole tablet of revolution with exact faces of revolution (:meth:`to_occ` keeps
        B-spline faces for cadquery), a cut-away's mesh formats from the mesh the build writes (unless other
        deflections are asked for)."""
        from tabletcad.cad.export import export

        mesh_kw = {"linear_deflection", "angular_deflection", "relative", "mesh"}
        if not self._whole and Path(path).suffix.lower() in (".stl", ".3mf", ".glb") and not mesh_kw & set(kw) \
                and self._cutaway_mesh is not None:
            kw["mesh"] = self._cutaway_mesh
        if self._whole:  # the solid tabletcad build writes (exact faces of revolution where it has them)
            return export(self._export_solid, path, name=kw.pop("name", self.name), **kw)
        return super().export(path, **kw)

    @cached_property
    def _export_solid(self):
        """What :meth:`export` writes of a whole tablet: ``tabletcad build``'s solid, with faces of revolution
        of its fitted profiles for a tablet of revolution (a new user read the concave round's exported STEP
        3.9e-9 low against the build's 5.0e-11: B-spline faces fit to 0.1 µm), else :attr:`solid`."""
        from tabletcad.brep.surfaces import tablet_profiles
        from tabletcad.cad.tablet_solid import tablet_solid

        return tablet_solid(self.tablet) if tablet_profiles(self.tablet) is not None else self._solid

    def report(self) -> dict[str, Any]:
        """The geometry and design report (the content of ``report.json``)."""
        from tabletcad.pipeline.report import geometry_report

        return geometry_report(self.tablet, None if self.design is None else self.design.report_options)

    def tooling(self, spec: Any = None, **kw: Any) -> ToolingModel:
        """Punch tips, die and the featured tablet.

        ``spec``: a :class:`~tabletcad.tooling.spec.ToolingSpec`, a ``[tooling]`` table as a
        dict, or ``None`` (the design's own ``[tooling]`` table, else the defaults);
        keyword arguments replace fields of the spec (``clearance_mm=0.03``...).
        """
        from tabletcad.tooling.spec import ToolingSpec, parse_tooling
        from tabletcad.tooling.toolset import make_tooling

        folder = None if self.design is None else self.design.folder
        if spec is None and not kw and self.design is not None and self.design.tooling_spec is not None:
            spec = self.design.tooling_spec  # parsed and checked when the design was read
        elif spec is None:  # the design's table with the keywords in it, parsed and checked again
            spec = {} if self.design is None or self.design.tooling is None else self.design.tooling
        if isinstance(spec, dict):
            spec = parse_tooling({**spec, **kw}, base=folder)
        elif isinstance(spec, ToolingSpec):
            spec = spec.with_(**kw) if kw else spec
        else:
            raise DesignError("tooling spec", type(spec).__name__, "must be a ToolingSpec, a dict or None")
        return ToolingModel(make_tooling(self.tablet, spec, shape=self.to_occ(),
                                         options=None if self.design is None else self.design.report_options))

    def _repr_png_(self) -> bytes:
        from tabletcad.pipeline.plot import tablet_png

        return tablet_png(self.tablet)

    def __repr__(self) -> str:
        return f"TabletModel({self.tablet.name!r}, family={self.tablet.family!r})"


def make(family: str, *, report: dict | None = None, tooling: dict | None = None, trim: dict | None = None,
         reshape: dict | None = None, patches: Sequence[dict] | None = None, **dims: Any) -> TabletModel:
    """A tablet of a named family (``tabletcad shapes`` lists them) with dimensions in mm.

    Checked as a design file's ``[tablet]`` table is (:class:`~tabletcad.pipeline.design.Design`):
    every required dimension given, numbers only (no ``"10"``), lengths within ±1000 mm and 0
    or at least ``Tolerances.min_length``; ``a`` (the smoothing parameter) may be given.
    ``report``, ``tooling``, ``trim`` and ``reshape``: the design's ``[report]``, ``[tooling]``, ``[trim]``
    and ``[reshape]`` tables as dicts (``report=dict(solid_fraction=0.85, true_density_mg_mm3=1.5)`` gives
    :meth:`TabletModel.report` its weight, ``trim=dict(v=[0.0, 3.14159])`` a cut-away), checked as a
    design file's are. ``patches``: a ``free_form`` tablet's ``[[patch]]`` tables, each a dict
    ``{"curves": [...]}`` of four curve tables (``"previous"`` repeats the previous patch's last curve), as
    in ``samples/free_form_stadium.toml``.
    """
    import numpy as np

    # numpy's scalars (np.arange(...)[i], np.float32) are the numbers they hold; arrays are not numbers
    dims = {k: v.item() if isinstance(v, np.generic) else v for k, v in dims.items()}
    data: dict[str, Any] = {"tablet": {"family": family, **dims}}
    if patches is not None and not (isinstance(patches, (list, tuple)) and all(isinstance(p, dict) for p in patches)):
        raise DesignError("patches", patches, 'must be a list of [[patch]] tables, each a dict {"curves": [...]}')
    for table, value in (("report", report), ("tooling", tooling), ("trim", trim), ("reshape", reshape),
                         ("patch", None if patches is None else list(patches))):
        if value is not None:
            data[table] = value
    design = Design.from_dict(data, default_name=str(family).split(".")[-1])
    return TabletModel(design.build(), design)


def load(path: str | Path) -> TabletModel:
    """The tablet of a TOML design file, with the design (:meth:`Design.from_toml
    <tabletcad.pipeline.design.Design.from_toml>`)."""
    design = Design.from_toml(path)
    return TabletModel(design.build(), design)


def show(*objs: Any, **kw: Any):
    """Show objects in VS Code through ``ocp_vscode.show`` when it is installed.

    Models and core tablets are passed as build123d solids.  Without ocp_vscode, prints one line
    and returns None.
    """
    try:
        import ocp_vscode
    except ImportError:
        print("tabletcad.show: ocp_vscode is not installed (pip install ocp_vscode); "
              "in Jupyter, display the object itself instead")
        return None
    shapes = []
    for o in objs:
        if isinstance(o, Tablet):
            o = TabletModel(o)
        if isinstance(o, ToolingModel):
            shapes.extend(p.to_build123d() for p in o.placed().values())
        elif isinstance(o, _Shaped):
            shapes.append(o.to_build123d())
        else:
            shapes.append(o)
    return ocp_vscode.show(*shapes, **kw)


_PALETTE = ("#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#76b7b2", "#edc948")

_VIEW_JS = r"""
(function(){
const root=document.getElementById(%(id)s), cv=root.querySelector('canvas'), g=cv.getContext('2d');
const M=%(data)s; let ry=-0.8, rx=0.9, zoom=1, drag=null;
let lo=[1e300,1e300,1e300], hi=[-1e300,-1e300,-1e300];
for(const m of M) for(let i=0;i<m.v.length;i+=3) for(let k=0;k<3;k++){lo[k]=Math.min(lo[k],m.v[i+k]);hi[k]=Math.max(hi[k],m.v[i+k]);}
const c=[0,1,2].map(k=>(lo[k]+hi[k])/2), R=Math.max(1e-9,Math.hypot(hi[0]-lo[0],hi[1]-lo[1],hi[2]-lo[2])/2);
function rgb(h){return [1,3,5].map(i=>parseInt(h.substr(i,2),16));}
function draw(){
  const W=cv.width,H=cv.height,s=zoom*0.45*Math.min(W,H)/R, cy=Math.cos(ry),sy=Math.sin(ry),cx=Math.cos(rx),sx=Math.sin(rx);
  const tris=[];
  for(const m of M){const col=rgb(m.c), P=[];
    for(let i=0;i<m.v.length;i+=3){const x=m.v[i]-c[0],y=m.v[i+1]-c[1],z=m.v[i+2]-c[2];
      const x1=cy*x-sy*y, y1=sy*x+cy*y; P.push([x1, cx*y1-sx*z, sx*y1+cx*z]);}
    for(let i=0;i<m.t.length;i+=3){const a=P[m.t[i]],b=P[m.t[i+1]],d=P[m.t[i+2]];
      const u=[b[0]-a[0],b[1]-a[1],b[2]-a[2]],w=[d[0]-a[0],d[1]-a[1],d[2]-a[2]];
      const n=[u[1]*w[2]-u[2]*w[1],u[2]*w[0]-u[0]*w[2],u[0]*w[1]-u[1]*w[0]], L=Math.hypot(n[0],n[1],n[2])||1;
      const lam=Math.abs(0.3*n[0]-0.5*n[1]+0.8*n[2])/L/Math.hypot(0.3,0.5,0.8);
      tris.push([a[1]+b[1]+d[1],a,b,d,col.map(q=>Math.round(q*(0.35+0.7*lam)))]);}}
  tris.sort((p,q)=>q[0]-p[0]);
  g.fillStyle='#fff'; g.fillRect(0,0,W,H);
  for(const t of tris){g.beginPath();g.moveTo(W/2+s*t[1][0],H/2-s*t[1][2]);g.lineTo(W/2+s*t[2][0],H/2-s*t[2][2]);
    g.lineTo(W/2+s*t[3][0],H/2-s*t[3][2]);g.closePath();const f='rgb('+t[4].join(',')+')';g.fillStyle=f;g.strokeStyle=f;g.fill();g.stroke();}
}
cv.onmousedown=e=>{drag=[e.clientX,e.clientY];}; window.addEventListener('mouseup',()=>{drag=null;});
cv.onmousemove=e=>{if(!drag)return; ry+=(e.clientX-drag[0])*0.01; rx+=(e.clientY-drag[1])*0.01; drag=[e.clientX,e.clientY]; draw();};
cv.onwheel=e=>{e.preventDefault(); zoom*=Math.exp(-e.deltaY*0.001); draw();};
draw();
})();
"""


def mesh_html(meshes: list[tuple[str, np.ndarray, np.ndarray]], *, title: str = "", width: int = 480,
              height: int = 360) -> str:
    """Self-contained HTML (a canvas and inline JavaScript, no network) showing triangle meshes.

    ``meshes``: ``(name, vertices (n, 3) mm, triangles (m, 3) int)``; drag to rotate, wheel to zoom.
    """
    data = [
        dict(n=name, c=_PALETTE[i % len(_PALETTE)],
             v=[round(float(x), 4) for x in np.asarray(V, float).ravel()],
             t=[int(k) for k in np.asarray(T).ravel()])
        for i, (name, V, T) in enumerate(meshes)
    ]
    uid = f"tabletcad-view-{uuid.uuid4().hex}"  # unique across kernels and notebooks on one page
    js = _VIEW_JS % {"id": json.dumps(uid), "data": json.dumps(data, separators=(",", ":"))}
    names = ", ".join(html.escape(str(m[0])) for m in meshes)
    return (f'<div id="{uid}" class="tabletcad-view"><canvas width="{width}" height="{height}" '
            f'style="border:1px solid #ccc"></canvas><div style="font:12px sans-serif">'
            f"{html.escape(title)}: {names} (drag to rotate, wheel to zoom; mm)</div>"
            f"<script>{js}</script></div>")


def mesh_png(meshes: list[tuple[str, np.ndarray, np.ndarray]], *, title: str = "", size: float = 4.0) -> bytes:
    """PNG bytes of triangle meshes drawn shaded in one 3-D view with equal axes (mm).

    ``meshes``: ``(name, vertices (n, 3) mm, triangles (m, 3) int)``.  The figure has its own Agg
    canvas: no global matplotlib backend is set.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.colors import to_rgb
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    fig = Figure(figsize=(size, size))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(projection="3d")
    light = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for i, (name, V, T) in enumerate(meshes):
        V, T = np.asarray(V, float), np.asarray(T, int)
        tri = V[T]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
        shade = 0.35 + 0.65 * np.clip(n @ light, 0.0, 1.0)
        colours = np.clip(np.outer(shade, to_rgb(_PALETTE[i % len(_PALETTE)])), 0.0, 1.0)
        alpha = 0.25 if name == "die" and len(meshes) > 1 else 1.0  # the die would hide the punches
        ax.add_collection3d(Poly3DCollection(tri, facecolors=colours, linewidths=0.0, alpha=alpha, label=name))
        lo, hi = np.minimum(lo, V.min(axis=0)), np.maximum(hi, V.max(axis=0))
    c, r = (lo + hi) / 2, float(np.max(hi - lo)) / 2
    ax.set(xlim=(c[0] - r, c[0] + r), ylim=(c[1] - r, c[1] + r), zlim=(c[2] - r, c[2] + r))
    ax.set_box_aspect((1, 1, 1))
    ax.set_axis_off()
    ax.set_title(f"{title} ({2 * r:.3g} mm across)" if title else f"{2 * r:.3g} mm across", fontsize=9)
    from tabletcad.io.figures import save_figure

    buf = io.BytesIO()
    save_figure(fig, buf, fmt="png", dpi=80)
    return buf.getvalue()
