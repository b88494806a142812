"""FeaturePython objects: Tablet, UpperPunch, LowerPunch, Die.

``execute()`` only calls the core (:mod:`tabletcad`) and :mod:`.geometry` and
assigns ``obj.Shape``.  When the core refuses the parameters (a
:class:`tabletcad.errors.TabletcadError`: zero or negative diameter, cup too
deep, ...) ``execute()`` raises: FreeCAD marks the object as failed with the
core's message (``obj.isValid()`` is False, ``obj.getStatusString()`` holds
the message) and the previous valid shape stays in ``obj.Shape``.
"""

from __future__ import annotations

import os
import time

import FreeCAD

from . import geometry

__all__ = [
    "DESIGN_FILE",
    "DieProxy",
    "PunchProxy",
    "TabletProxy",
    "ViewProviderTabletcad",
    "family_names",
    "is_tablet",
    "prop_name",
]

DESIGN_FILE = "design_file"
_READONLY = 1  # editor mode: read-only
_OUTPUT = 8  # Prop_Output: setting it does not touch the object
_HIDDEN = 4


def family_names() -> list[str]:
    from tabletcad import shapes

    shapes._load_plugins()
    return sorted(shapes.FAMILIES)


def prop_name(param: str) -> str:
    """Core parameter name -> FreeCAD property name (``cup_depth`` -> ``CupDepth``)."""
    return "".join(w[:1].upper() + w[1:] for w in param.split("_"))


def is_tablet(obj) -> bool:
    return getattr(getattr(obj, "Proxy", None), "Type", None) == TabletProxy.Type


def _family(name):
    from tabletcad import shapes

    shapes._load_plugins()
    return shapes.FAMILIES.get(name)


def _qty(value, unit):
    return FreeCAD.Units.Quantity(float(value), FreeCAD.Units.Unit(unit))


class _Proxy:
    """Common proxy plumbing: persistence for FreeCAD 0.20 (__getstate__) and 1.x (dumps)."""

    Type = "Tabletcad"

    def __init__(self, obj):
        obj.Proxy = self
        self._ready = True

    def __getstate__(self):
        return {"Type": self.Type, "version": 1}

    def __setstate__(self, state):
        self._ready = False  # until onDocumentRestored

    def dumps(self):
        return self.__getstate__()

    def loads(self, state):
        self.__setstate__(state)

    def _setup(self, obj):
        """Add the object's properties (only those missing: also run on restore)."""

    def onDocumentRestored(self, obj):
        self._setup(obj)  # units are not saved by FreeCAD 0.20; properties added since the save
        self._ready = True

    @staticmethod
    def _add(obj, kind, name, group, doc, default=None, mode=0, hidden=False):
        if name not in obj.PropertiesList:
            obj.addProperty(kind, name, group, doc, _OUTPUT if mode else 0, False, hidden)
            if default is not None:
                setattr(obj, name, default)
        if mode:
            obj.setEditorMode(name, mode)


# ============================================================================ Tablet
class TabletProxy(_Proxy):
    """A tablet of a tabletcad family (dimensions as properties) or from a design file."""

    Type = "TabletcadTablet"

    def __init__(self, obj, family: str = "flat_faced_round"):
        self._ready = False
        obj.Proxy = self
        self._setup(obj)
        obj.Family = family
        self._sync_dimensions(obj, reset=True)
        self._ready = True

    # ---------------------------------------------------------------- properties
    def _setup(self, obj):
        names = family_names() + [DESIGN_FILE]
        if "Family" not in obj.PropertiesList:
            obj.addProperty(
                "App::PropertyEnumeration", "Family", "Tablet", "tabletcad family (or design_file)"
            )
            obj.Family = names
        else:  # keep the list current with the installed families
            cur = obj.Family
            obj.Family = names
            if cur in names:
                obj.Family = cur
        self._add(
            obj,
            "App::PropertyFile",
            "DesignFile",
            "Tablet",
            "tabletcad design (TOML), used when Family is design_file",
        )
        self._add(
            obj,
            "App::PropertyLength",
            "FitTolerance",
            "Tablet",
            "largest distance between the B-spline faces and the PDE surfaces",
            _qty(1e-4, "mm"),
        )
        self._add(obj, "App::PropertyQuantity", "Density", "Material", "apparent density of the tablet")
        obj.Density = FreeCAD.Units.Unit("kg/m^3")
        if obj.Density.Value == 0.0:
            obj.Density = FreeCAD.Units.Quantity("1200 kg/m^3")
        self._add(
            obj,
            "App::PropertyVolume",
            "Volume",
            "Results",
            "volume of the PDE tablet (tabletcad quadrature)",
            mode=_READONLY,
        )
        self._add(
            obj,
            "App::PropertyVolume",
            "SolidVolume",
            "Results",
            "exact volume of the B-spline solid in Shape (Gauss quadrature of its faces)",
            mode=_READONLY,
        )
        self._add(
            obj,
            "App::PropertyArea",
            "Area",
            "Results",
            "surface area of the PDE tablet (tabletcad quadrature)",
            mode=_READONLY,
        )
        self._add(
            obj,
            "App::PropertyArea",
            "PlanArea",
            "Results",
            "area of the silhouette seen along z",
            mode=_READONLY,
        )
        self._add(obj, "App::PropertyQuantity", "Weight", "Results", "Volume x Density", mode=_READONLY)
        obj.Weight = FreeCAD.Units.Unit("kg")
        self._add(
            obj,
            "App::PropertyLength",
            "FitDeviation",
            "Results",
            "largest measured B-spline fit deviation",
            mode=_READONLY,
        )
        self._add(
            obj,
            "App::PropertyFloat",
            "RecomputeTime",
            "Results",
            "seconds of the last recompute",
            mode=_READONLY,
        )
        self._add(
            obj,
            "App::PropertyString",
            "RimData",
            "Internal",
            "rim curves (JSON) used by the punches and the die",
            mode=_READONLY | _HIDDEN,
            hidden=True,
        )

    def _dimension_props(self, obj):
        return [p for p in obj.PropertiesList if obj.getGroupOfProperty(p) == "Dimensions"]

    def _sync_dimensions(self, obj, reset=False):
        """Make the Dimensions group hold exactly the current family's parameters."""
        fam = _family(obj.Family)
        wanted = {} if fam is None else {prop_name(k): (k, u) for k, u in fam.params.items()}
        for p in self._dimension_props(obj):
            if p not in wanted:
                obj.removeProperty(p)
        defaults = fam.defaults if fam is not None else {}
        for p, (k, unit) in wanted.items():
            if p not in obj.PropertiesList:
                kind = "App::PropertyAngle" if unit == "deg" else "App::PropertyLength"
                obj.addProperty(kind, p, "Dimensions", f"{k} ({unit})")
                reset = True
            if reset and defaults.get(k) is not None:
                setattr(obj, p, _qty(defaults[k], "deg" if unit == "deg" else "mm"))

    def onChanged(self, obj, prop):
        if prop == "Family" and getattr(self, "_ready", False):
            self._sync_dimensions(obj, reset=True)

    # ---------------------------------------------------------------- core
    def spec(self, obj) -> dict:
        """What the core is asked to build: ``{family, params, design}``."""
        if obj.Family == DESIGN_FILE:
            return {"family": None, "params": {}, "design": obj.DesignFile}
        fam = _family(obj.Family)
        params = {}
        for k in fam.params:
            p = prop_name(k)
            if p in obj.PropertiesList:
                params[k] = float(getattr(obj, p).Value)
        return {"family": obj.Family, "params": params, "design": None}

    def core_tablet(self, obj):
        s = self.spec(obj)
        if s["design"] is not None and not s["design"]:
            from tabletcad.errors import DesignError

            raise DesignError(
                "DesignFile", "", "set a tabletcad design file (TOML) when Family is design_file"
            )
        return geometry.tablet_from_spec(s["family"], s["params"], s["design"])

    def execute(self, obj):
        t0 = time.perf_counter()
        tablet = self.core_tablet(obj)
        geo = geometry.build_tablet(tablet, tol=float(obj.FitTolerance.Value) or None)
        pl = obj.Placement
        obj.Shape = geo.solid
        obj.Placement = pl
        obj.Volume = _qty(geo.volume, "mm^3")
        obj.SolidVolume = _qty(geo.props["solid_volume_mm3"], "mm^3")
        obj.Area = _qty(geo.area, "mm^2")
        obj.PlanArea = _qty(geo.props.get("plan_area_mm2", float("nan")), "mm^2")
        obj.Weight = _qty(geo.volume, "mm^3") * obj.Density
        obj.FitDeviation = _qty(geo.max_fit_deviation, "mm")
        obj.RimData = geo.rims_json()
        obj.RecomputeTime = time.perf_counter() - t0


# ============================================================================ tooling
def _tablet_of(obj):
    from tabletcad.errors import DesignError

    tab = obj.Tablet
    if tab is None or not is_tablet(tab):
        raise DesignError("Tablet", getattr(tab, "Name", None), "link a tabletcad Tablet")
    if tab.Shape.isNull() or not tab.RimData:
        raise DesignError("Tablet", tab.Label, "the linked tablet has no valid solid yet (recompute it)")
    return tab


def _local_shape(tab):
    s = tab.Shape.copy()
    s.Placement = FreeCAD.Placement()
    return s


class PunchProxy(_Proxy):
    """Upper or lower punch tip of a tablet: prism on its rim minus the tablet."""

    Type = "TabletcadPunch"

    def __init__(self, obj, tablet=None, which="upper"):
        super().__init__(obj)
        self._setup(obj)
        obj.Which = which
        obj.Tablet = tablet

    def _setup(self, obj):
        self._add(obj, "App::PropertyLink", "Tablet", "Punch", "the tablet this punch forms")
        if "Which" not in obj.PropertiesList:
            obj.addProperty("App::PropertyEnumeration", "Which", "Punch", "upper or lower punch")
            obj.Which = ["upper", "lower"]
        self._add(
            obj,
            "App::PropertyLength",
            "Length",
            "Punch",
            "length of the punch tip beyond the band edge",
            _qty(10.0, "mm"),
        )
        self._add(
            obj,
            "App::PropertyDistance",
            "Gap",
            "Punch",
            "lift-off from the tablet (exploded view)",
            _qty(0.0, "mm"),
        )
        self._add(obj, "App::PropertyVolume", "Volume", "Results", "volume of the punch tip", mode=_READONLY)

    def execute(self, obj):
        tab = _tablet_of(obj)
        rims = geometry.rims_from_json(tab.RimData)
        shape = geometry.punch_shape(_local_shape(tab), rims, obj.Which, float(obj.Length.Value))
        gap = float(obj.Gap.Value)
        lift = FreeCAD.Placement(
            FreeCAD.Vector(0, 0, gap if obj.Which == "upper" else -gap), FreeCAD.Rotation()
        )
        obj.Shape = shape
        obj.Placement = tab.Placement.multiply(lift)  # the shape's own placement is the object's
        obj.Volume = _qty(shape.Volume, "mm^3")


class DieProxy(_Proxy):
    """Die of a tablet: a cylinder with the bore (outer rim + clearance), centred on the band."""

    Type = "TabletcadDie"

    def __init__(self, obj, tablet=None):
        super().__init__(obj)
        self._setup(obj)
        obj.Tablet = tablet

    def _setup(self, obj):
        self._add(obj, "App::PropertyLink", "Tablet", "Die", "the tablet this die forms")
        self._add(
            obj,
            "App::PropertyLength",
            "Clearance",
            "Die",
            "radial clearance between bore and tablet outline",
            _qty(0.05, "mm"),
        )
        self._add(
            obj, "App::PropertyLength", "Height", "Die", "die height (TSM B die: 22.22 mm)", _qty(22.22, "mm")
        )
        self._add(
            obj,
            "App::PropertyLength",
            "OuterDiameter",
            "Die",
            "die outer diameter (TSM B die: 30.16 mm)",
            _qty(30.16, "mm"),
        )
        self._add(obj, "App::PropertyVolume", "Volume", "Results", "volume of the die", mode=_READONLY)

    def execute(self, obj):
        tab = _tablet_of(obj)
        rims = geometry.rims_from_json(tab.RimData)
        shape = geometry.die_shape(
            rims, float(obj.Clearance.Value), float(obj.Height.Value), float(obj.OuterDiameter.Value)
        )
        obj.Shape = shape
        obj.Placement = tab.Placement
        obj.Volume = _qty(shape.Volume, "mm^3")


# ============================================================================ view providers (GUI only)
_ICONS = {
    TabletProxy.Type: "Tablet",
    PunchProxy.Type: "Punch",
    DieProxy.Type: "Die",
}
_COLOURS = {
    TabletProxy.Type: (0.93, 0.93, 0.86),
    PunchProxy.Type: (0.62, 0.68, 0.78),
    DieProxy.Type: (0.55, 0.55, 0.58),
}


class ViewProviderTabletcad:
    """Icon and colour; attached only when ``FreeCAD.GuiUp``."""

    def __init__(self, vobj):
        vobj.Proxy = self
        t = getattr(getattr(vobj.Object, "Proxy", None), "Type", None)
        if t in _COLOURS:
            vobj.ShapeColor = _COLOURS[t]
        if t == DieProxy.Type:
            vobj.Transparency = 75

    def attach(self, vobj):
        self.Object = vobj.Object

    def getIcon(self):
        from . import icon

        t = getattr(getattr(getattr(self, "Object", None), "Proxy", None), "Type", TabletProxy.Type)
        if t == PunchProxy.Type and getattr(self.Object, "Which", "upper") == "lower":
            return icon("LowerPunch")
        if t == PunchProxy.Type:
            return icon("UpperPunch")
        return icon(_ICONS.get(t, "Tablet"))

    def __getstate__(self):
        return None

    def __setstate__(self, state):
        return None

    def dumps(self):
        return None

    def loads(self, state):
        return None


def attach_view_provider(obj) -> None:
    if FreeCAD.GuiUp and getattr(obj, "ViewObject", None) is not None:
        ViewProviderTabletcad(obj.ViewObject)


def design_is_parametric(path) -> tuple[str, dict, str] | None:
    """(family, params, name) if the design file is a plain family design, else None."""
    try:
        import tomllib
    except ImportError:  # Python < 3.11 (FreeCAD builds with an older Python)
        import tomli as tomllib

    try:
        data = tomllib.loads(open(os.fspath(path), encoding="utf-8").read())
    except Exception:
        return None
    if not {"tablet"} <= set(data) <= {"tablet", "report"} or not isinstance(data.get("tablet"), dict):
        return None
    tab = dict(data["tablet"])
    family = tab.pop("family", None)
    name = tab.pop("name", None)
    fam = _family(family)
    if fam is None or not set(tab) <= set(fam.params):
        return None
    if not all(isinstance(v, (int, float)) for v in tab.values()):
        return None
    return family, {k: float(v) for k, v in tab.items()}, name or ""
