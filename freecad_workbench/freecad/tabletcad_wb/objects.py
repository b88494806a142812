"""FeaturePython objects: Tablet, UpperPunch, LowerPunch, Die.

``execute()`` only calls the core (:mod:`tabletcad`) and :mod:`.geometry` and
assigns ``obj.Shape``.  When the core refuses the parameters (a
:class:`tabletcad.errors.TabletcadError`: zero or negative diameter, cup too
deep, ...) ``execute()`` raises: FreeCAD marks the object as failed with the
core's message (``obj.isValid()`` is False, ``obj.getStatusString()`` holds
the message) and the previous valid shape stays in ``obj.Shape``.  The Report view
then shows that message on one line; the traceback goes to FreeCAD's log only.

Units: the dimensions are FreeCAD lengths and angles (mm, °); the results (volumes,
areas, ``Weight``) and ``Density`` are plain numbers in mm, mm², mm³, mg and mg/mm³,
named in their property group and tooltip, because FreeCAD's unit schemas would show
345 mm² as 3.46 cm², a mass in kg and a density in kg/m³.
Labels follow the family (while the label is the family's name) and the tooling's
labels follow the tablet's label.
"""

from __future__ import annotations

import os
import sys
import time
import traceback

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
_HIDDEN = 2  # editor mode: hidden
_EDITOR_MODES = {0: [], _READONLY: ["ReadOnly"], _HIDDEN: ["Hidden"], _READONLY | _HIDDEN: ["ReadOnly", "Hidden"]}
DEFAULT_DENSITY = 1.2  # mg/mm^3
# results are plain numbers in the units a formulation scientist uses, named in the group:
# FreeCAD's unit schemas would show 345 mm² as 3.46 cm², a weight in kg, a density in kg/m³
RESULTS = "Results (mm, mm², mm³, mg)"
MATERIAL = "Material (mg/mm³)"


def log(text: str) -> None:
    """FreeCAD's log (not the Report view's messages)."""
    FreeCAD.Console.PrintLog(text if text.endswith("\n") else text + "\n")


def _tabletcad_error():
    from tabletcad.errors import TabletcadError

    return TabletcadError


def _fail(obj, exc):
    """Report a refused recompute: one line in the Report view, the traceback in the log.

    FreeCAD prints the traceback of an exception raised by ``execute()`` as an error;
    ``sys.tracebacklimit = 0`` shortens that to the exception's one line (it is reset by
    the next tabletcad call, see :func:`_restore_traceback`)."""
    log(f"tabletcad: {obj.Label}: " + traceback.format_exc())
    sys.tracebacklimit = 0
    if FreeCAD.GuiUp:
        try:
            from PySide import QtCore

            QtCore.QTimer.singleShot(0, _restore_traceback)
        except Exception:
            pass
    else:  # headless: restored once the recompute is over (a script's own tracebacks had been cut to one line)
        _RestoreAfterRecompute.arm()
    raise exc.with_traceback(None)


class _RestoreAfterRecompute:
    """A document observer that restores ``sys.tracebacklimit`` when a recompute ends, of the document or of one
    object (headless, where no event loop runs a timer), then removes itself."""

    _armed = None

    @classmethod
    def arm(cls):
        if cls._armed is None:
            cls._armed = cls()
            FreeCAD.addDocumentObserver(cls._armed)

    def slotRecomputedObject(self, obj):  # (``obj.recompute()`` alone: no document recompute follows)
        self.slotRecomputedDocument(obj.Document)

    def slotRecomputedDocument(self, doc):
        _restore_traceback()
        type(self)._armed = None
        try:
            FreeCAD.removeDocumentObserver(self)
        except Exception:
            pass


def _restore_traceback():
    if getattr(sys, "tracebacklimit", None) == 0:
        del sys.tracebacklimit


#: the B-spline fit tolerances (mm) a tablet takes (``make_tablet``'s 0: the core's default): below 1e-7 mm the fit runs
#: into the surfaces' own rounding, above 0.01 mm a face would be visibly off its PDE surface
MIN_FIT_TOLERANCE_MM, MAX_FIT_TOLERANCE_MM = 1e-7, 0.01
#: the apparent density a tablet takes, mg/mm³ (= g/cm³): from a very porous compact's to the largest true
#: density tabletcad takes (tabletcad.tolerance.MAX_TRUE_DENSITY_MG_MM3: a density in kg/m³ is refused);
#: the task panel offers the same range (the object had taken up to 1000)
DENSITY_LIMITS = (0.01, 25.0)


def _default_fit() -> float:
    from tabletcad.tolerance import DEFAULT

    return DEFAULT.fit


def check_density(parameter: str, value: float, given=None) -> None:
    """Refuse an apparent density outside :data:`DENSITY_LIMITS` (or NaN) naming ``parameter``.

    Parameters
    ----------
    parameter : str
        The name refused: the property (``Density``) or ``make_tablet``'s argument (``density``).
    value : float
        The density, mg/mm³ (= g/cm³).
    given : str, optional
        What the user gave, when it was text or a quantity (``"2 g/mm^3"``): quoted instead of ``value``.

    Raises
    ------
    tabletcad.errors.DesignError
        Out of range; a value that is in range in kg/m³ says what it is in mg/mm³ (the usual slip).
    """
    from tabletcad.errors import DesignError

    lo, hi = DENSITY_LIMITS
    if lo <= value <= hi:  # (also refuses NaN)
        return
    allowed = f"must be >= {lo:g} and <= {hi:g} mg/mm³ (= g/cm³)"
    if 1000.0 * lo <= value <= 1000.0 * hi:
        allowed += f"; {value:g} kg/m³ would be {value / 1000.0:g} mg/mm³"
    raise DesignError(parameter, value if given is None else given, allowed, "mg/mm³")


def check_fit_tolerance(parameter: str, value: float, zero_is_default: bool = True) -> None:
    """Refuse a B-spline fit tolerance (mm) outside [:data:`MIN_FIT_TOLERANCE_MM`, :data:`MAX_FIT_TOLERANCE_MM`]
    (NaN included), naming ``parameter``.

    Parameters
    ----------
    parameter : str
        The name refused: ``make_tablet``'s argument (``fit_tolerance``) or the property (``FitTolerance``).
    value : float
        The tolerance, mm.
    zero_is_default : bool
        True for ``make_tablet``'s argument, where 0 asks for the core's default (which the property then
        holds); False for the property, which holds the tolerance used: a ``PropertyLength`` stores a value
        set below 0 mm as 0 mm, so a 0 there may have been set as -1 mm and is refused, saying so (it had
        been taken as the default, with no message).

    Raises
    ------
    tabletcad.errors.DesignError
        Out of range.
    """
    from tabletcad.errors import DesignError

    if zero_is_default and value == 0.0:
        return
    if MIN_FIT_TOLERANCE_MM <= value <= MAX_FIT_TOLERANCE_MM:  # (NaN had reached the core)
        return
    within = f"[{MIN_FIT_TOLERANCE_MM:g}, {MAX_FIT_TOLERANCE_MM:g}]"
    if zero_is_default:
        allowed = f"must be 0 (the default, {_default_fit():g} mm) or within {within}"
    else:
        allowed = f"must be within {within} mm (the default: {_default_fit():g} mm)"
        if value == 0.0:
            allowed += f"; {_STORED_FOR['App::PropertyLength'][1]}"
    raise DesignError(parameter, value, allowed, "mm")


#: what FreeCAD's quantity properties do to a value beyond their range, by the value they keep instead:
#: a length set below 0 is stored as 0, an angle beyond ±360° as ±360° (so the core never sees the value set)
_STORED_FOR = {
    "App::PropertyLength": (lambda v: v == 0.0, "FreeCAD's length properties hold no negative value: one set "
                                                "below 0 mm is stored as 0 mm"),
    "App::PropertyAngle": (lambda v: abs(v) == 360.0, "FreeCAD's angle properties hold -360° to 360°: one set "
                                                      "beyond is stored as ±360°"),
}


def _as_stored(obj, exc):
    """The core's refusal ``exc`` of a dimension, saying plainly that FreeCAD may have changed the value set
    when the property holds the value it stores for one out of its range (the value set is not known here:
    the property editor or a script set -5 mm and the core was asked about 0 mm).

    Parameters
    ----------
    obj : App.FeaturePython
        The tablet.
    exc : tabletcad.errors.DesignError
        The core's refusal of its dimensions.

    Returns
    -------
    tabletcad.errors.DesignError
        ``exc`` itself, or the same refusal with the note.
    """
    from tabletcad.errors import DesignError

    fam = _family(obj.Family)
    for k in fam.params if fam is not None else ():
        p = prop_name(k)
        if exc.parameter != f"tablet.{k}" or p not in obj.PropertiesList:
            continue
        stored, note = _STORED_FOR.get(obj.getTypeIdOfProperty(p), (None, ""))
        if stored is not None and stored(float(getattr(obj, p).Value)):
            return DesignError(exc.parameter, exc.value, f"{exc.allowed}; {note}", exc.unit)
    return exc


#: the largest punch lift off the tablet (mm) of an exploded view
MAX_GAP_MM = 1000.0


def _file_digest(path) -> str | None:
    """A digest of a design file's bytes (None without one, or when it cannot be read): a tablet from a
    file is rebuilt when the file changes, not only when another file is named."""
    if not path:
        return None
    import hashlib

    try:
        with open(os.fspath(path), "rb") as f:
            return hashlib.sha256(f.read()).hexdigest()
    except OSError:
        return None


def family_names() -> list[str]:
    from tabletcad import families

    return sorted(families.FAMILIES)


def prop_name(param: str) -> str:
    """Core parameter name -> FreeCAD property name (``cup_depth`` -> ``CupDepth``)."""
    return "".join(w[:1].upper() + w[1:] for w in param.split("_"))


def standard_die(size: float, shaped: bool, current=None) -> tuple[float, float, str]:
    """``(outer diameter, height, TSM type)`` of the standard die for a tablet ``size`` mm across
    (:func:`tabletcad.tooling.spec.standard_die_size`); one larger than a D die takes is refused naming the
    die's ``OuterDiameter`` (``current``: its value now, when the die exists) and ``StandardSize``, the
    properties that take a die of another size."""
    from tabletcad.errors import MISSING, DesignError
    from tabletcad.tooling.spec import standard_die_size, tsm_die_limits

    try:
        return standard_die_size(size, shaped=shaped)
    except DesignError:
        kind = "shaped" if shaped else "round"
        raise DesignError("OuterDiameter", MISSING if current is None else current,
                          f"give it and the die's Height (StandardSize false) for a {kind} tablet {size:.4g} mm across: "
                          f"the largest TSM die, D, takes {kind} tablets up to {tsm_die_limits('D')[1 if shaped else 0]:g} mm",
                          "" if current is None else "mm") from None


def is_tablet(obj) -> bool:
    return getattr(getattr(obj, "Proxy", None), "Type", None) == TabletProxy.Type


def _family(name):
    """The family of a Family property value (an old name of a renamed family gives the new one)."""
    from tabletcad import families

    return families.FAMILIES.get(families.RENAMED.get(name, name))


def _qty(value, unit):
    return FreeCAD.Units.Quantity(float(value), FreeCAD.Units.Unit(unit))


class _Proxy:
    """Common proxy plumbing: persistence for FreeCAD 0.20 (__getstate__) and 1.x (dumps)."""

    Type = "Tabletcad"

    def __init__(self, obj):
        obj.Proxy = self
        self._ready = True

    def execute(self, obj):
        _restore_traceback()
        try:
            self.build(obj)
        except _tabletcad_error() as exc:
            _fail(obj, exc)

    def build(self, obj):
        """Compute ``obj.Shape`` and the results (subclasses)."""

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
        if name in obj.PropertiesList and (
            obj.getTypeIdOfProperty(name) != kind or obj.getGroupOfProperty(name) != group
        ):
            obj.removeProperty(name)  # a document of an earlier version (e.g. Quantity results)
        if name not in obj.PropertiesList:
            obj.addProperty(kind, name, group, doc, _OUTPUT if mode else 0, False, hidden)
            if default is not None:
                setattr(obj, name, default)
        if mode:
            obj.setEditorMode(name, _EDITOR_MODES[mode])


def core_tablet_of(spec: dict):
    """The core tablet of a Tablet's inputs: what its recompute builds, and what the task panel checks its
    fields with (the panel had called the family's constructor alone, which skips the design's own checks:
    a ffbe whose bevel leaves a band of 0.0005 mm was "valid" in the panel and refused on OK).

    Parameters
    ----------
    spec : dict
        ``{family, params, design}`` as :meth:`TabletProxy.spec` gives it (mm, deg; ``design`` the design
        file's path, or None for a family's tablet).

    Returns
    -------
    tabletcad.geometry.tablet.Tablet
        The core's tablet (dimensions in mm).

    Raises
    ------
    tabletcad.errors.DesignError
        What ``tabletcad build`` refuses (:func:`geometry.tablet_from_spec`), or no design file given.
    """
    if spec["design"] is not None and not spec["design"]:
        from tabletcad.errors import DesignError

        raise DesignError("DesignFile", "", "set a tabletcad design file (TOML) when Family is design_file")
    return geometry.tablet_from_spec(spec["family"], spec["params"], spec["design"])


# ============================================================================ Tablet
class TabletProxy(_Proxy):
    """A tablet of a tabletcad family (dimensions as properties) or from a design file."""

    Type = "TabletcadTablet"

    def __init__(self, obj, family: str = "thesis.flat_faced_round"):
        self._ready = False
        obj.Proxy = self
        self._setup(obj)
        fam = _family(family)
        obj.Family = fam.name if fam is not None else family  # the catalogue's name for an old one
        self._family_label, self._label = obj.Family, obj.Label
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
        else:  # keep the list current with the installed families (a document saved with a
            from tabletcad.families import RENAMED  # family's old name opens with its new one)

            cur = RENAMED.get(obj.Family, obj.Family)
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
            "largest distance between the B-spline faces and the PDE surfaces (mm; 1e-07 to 0.01, default 0.0001)",
            _qty(_default_fit(), "mm"),
        )
        if "Density" in obj.PropertiesList and obj.getTypeIdOfProperty("Density") == "App::PropertyQuantity":
            # documents of the first workbench version: a Quantity in kg/m^3 (internally kg/mm^3)
            old = float(obj.Density.Value) * 1e6 or DEFAULT_DENSITY
            obj.removeProperty("Density")
            self._add(obj, "App::PropertyFloat", "Density", MATERIAL, "apparent density, mg/mm³ (= g/cm³)", old)
        self._add(
            obj, "App::PropertyFloat", "Density", MATERIAL, "apparent density, mg/mm³ (= g/cm³)", DEFAULT_DENSITY
        )
        self._add(
            obj,
            "App::PropertyFloat",
            "Volume",
            RESULTS,
            "volume of the PDE tablet, mm³ (tabletcad quadrature)",
            mode=_READONLY,
        )
        self._add(
            obj,
            "App::PropertyFloat",
            "SolidVolume",
            RESULTS,
            "exact volume of the B-spline solid in Shape, mm³ (Gauss quadrature of its faces)",
            mode=_READONLY,
        )
        self._add(
            obj,
            "App::PropertyFloat",
            "Area",
            RESULTS,
            "surface area of the PDE tablet, mm² (tabletcad quadrature)",
            mode=_READONLY,
        )
        self._add(
            obj,
            "App::PropertyFloat",
            "PlanArea",
            RESULTS,
            "area of the silhouette seen along z, mm²",
            mode=_READONLY,
        )
        self._add(obj, "App::PropertyFloat", "Weight", RESULTS, "tablet weight, mg (Volume x Density)", mode=_READONLY)
        self._add(
            obj,
            "App::PropertyFloat",
            "FitDeviation",
            RESULTS,
            "largest measured B-spline fit deviation, mm",
            mode=_READONLY,
        )
        self._add(
            obj,
            "App::PropertyFloat",
            "RecomputeTime",
            RESULTS,
            "seconds of the last recompute (s)",
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
        self._family_label = obj.Family
        self._label = obj.Label

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
        if not getattr(self, "_ready", False):
            return
        if prop == "Family":
            old = getattr(self, "_family_label", None)
            self._family_label = obj.Family
            if getattr(obj.Document, "Transacting", False):
                # undo or redo: the transaction restores the family's own dimension properties and values
                # (resetting them to the family's defaults had lost the user's)
                return
            suffix = obj.Label[len(old):] if old and obj.Label.startswith(old) else None
            if suffix is not None and (suffix == "" or suffix.isdigit()):
                obj.Label = obj.Family  # the label was the family's name (FreeCAD numbers it if taken)
            self._sync_dimensions(obj, reset=True)
        elif prop == "Label":
            old, self._label = getattr(self, "_label", None), obj.Label
            if old and old != obj.Label:  # tooling labelled "<tablet> upper punch" follows
                for o in obj.InList:
                    if getattr(getattr(o, "Proxy", None), "Type", "") in (PunchProxy.Type, DieProxy.Type):
                        if o.Label.startswith(old + " "):
                            o.Label = obj.Label + o.Label[len(old):]

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
        return core_tablet_of(self.spec(obj))

    def _geometry_key(self, obj, fit: float) -> str:
        """What the solid is made of: the spec, the fit tolerance ``fit`` (mm) and the design file's digest.

        Parameters
        ----------
        obj : App.FeaturePython
            The tablet.
        fit : float
            Its ``FitTolerance`` (mm).

        Returns
        -------
        str
            A key equal for equal inputs (the solid is rebuilt only when it changes)."""
        s = self.spec(obj)
        return repr((s, fit, _file_digest(s["design"])))

    def adopt_core(self, obj, tablet, spec: dict, digest: str | None) -> None:
        """Keep the core tablet ``make_tablet`` built from ``spec`` (:meth:`spec`) to check its arguments, for
        the object's first recompute, when the object's inputs are still those (the design file's bytes had
        the digest ``digest`` before it was read): it is not built twice.

        Parameters
        ----------
        obj : App.FeaturePython
            The tablet.
        tablet : tabletcad.geometry.tablet.Tablet
            The core's tablet of ``spec``.
        spec : dict
            ``{family, params, design}`` it was built from (mm, deg).
        digest : str or None
            The design file's digest read before it was built (None without one).
        """
        if self.spec(obj) == spec and _file_digest(spec["design"]) == digest:
            self._core = (self._geometry_key(obj, float(obj.FitTolerance.Value)), tablet)

    def current_core_tablet(self, obj):
        """The core tablet of the object's inputs as they are now: the one its last recompute built when they
        have not changed since (``make_die`` sizes its standard die from it: it had built the same tablet again,
        0.4 s for a free-form design), else :meth:`core_tablet`.

        Parameters
        ----------
        obj : App.FeaturePython
            The tablet.

        Returns
        -------
        tabletcad.geometry.tablet.Tablet
            The core's tablet (dimensions in mm)."""
        built = getattr(self, "_core", None)
        if built is not None and built[0] == self._geometry_key(obj, float(obj.FitTolerance.Value)):
            return built[1]
        return self.core_tablet(obj)

    def build(self, obj):
        from tabletcad.errors import DesignError

        t0 = time.perf_counter()
        density = float(obj.Density)
        check_density("Density", density)
        fit = float(obj.FitTolerance.Value)
        check_fit_tolerance("FitTolerance", fit, zero_is_default=False)
        key = self._geometry_key(obj, fit)
        if key != getattr(self, "_built", None) or obj.Shape.isNull() or not obj.RimData:
            # rebuild only when the geometry's inputs changed (not for Density, Label, Placement)
            core = getattr(self, "_core", None)  # (make_tablet's check of its arguments built it)
            try:
                tablet = core[1] if core is not None and core[0] == key else self.core_tablet(obj)
            except DesignError as exc:
                raise _as_stored(obj, exc) from None
            geo = geometry.build_tablet(tablet, tol=fit)
            pl = obj.Placement
            obj.Shape = geo.solid
            obj.Placement = pl
            obj.Volume = float(geo.volume)
            obj.SolidVolume = float(geo.props["solid_volume_mm3"])
            obj.Area = float(geo.area)
            obj.PlanArea = float(geo.props["plan_area_mm2"])
            obj.FitDeviation = float(geo.max_fit_deviation)
            rims = geo.rims_json()
            if rims != obj.RimData:
                obj.RimData = rims
            self._built = key
            self._core = (key, tablet)  # (not saved with the document: rebuilt on its first recompute)
            self.builds = getattr(self, "builds", 0) + 1  # solids built by this proxy (this session)
        obj.Weight = float(obj.Volume) * density
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
            "App::PropertyLength",
            "Clearance",
            "Punch",
            "radial clearance between the punch tip and the die bore (the tablet's outline): the tip is the "
            "outline offset inward by it",
            _qty(0.025, "mm"),
        )
        self._add(
            obj,
            "App::PropertyDistance",
            "Gap",
            "Punch",
            "lift-off from the tablet (exploded view)",
            _qty(0.0, "mm"),
        )
        self._add(obj, "App::PropertyFloat", "Volume", "Results (mm³)", "volume of the punch tip, mm³", mode=_READONLY)

    def build(self, obj):
        tab = _tablet_of(obj)
        shape = self._tip(obj, tab)
        gap = float(obj.Gap.Value)
        if not 0.0 <= gap <= MAX_GAP_MM:  # (a NaN gap had placed the punch at NaN; a negative one pushed it into the tablet)
            from tabletcad.errors import DesignError

            raise DesignError("Gap", gap, f"must be >= 0 and <= {MAX_GAP_MM:g} (the lift off the tablet)", "mm")
        lift = FreeCAD.Placement(
            FreeCAD.Vector(0, 0, gap if obj.Which == "upper" else -gap), FreeCAD.Rotation()
        )
        obj.Shape = shape
        obj.Placement = tab.Placement.multiply(lift)  # the shape's own placement is the object's
        obj.Volume = float(shape.Volume)

    def _tip(self, obj, tab):
        """The punch tip's shape (:func:`geometry.punch_shape`), cut again only when what it is made of
        changed: the tablet's solid and rims, ``Which``, ``Length`` or ``Clearance``.

        A recompute of the punch for anything else (its ``Gap``; the tablet's ``Density``, whose recompute
        recomputes the linked tools) had cut the tip from the tablet again.  ``cuts`` counts the cuts made
        (this session; tests/test_freecad_workbench.py checks both cases).

        Parameters
        ----------
        obj : App.FeaturePython
            The punch.
        tab : App.FeaturePython
            Its tablet (:func:`_tablet_of`).

        Returns
        -------
        Part.Shape
            The tip, in the tablet's own frame.
        """
        key = (tab.RimData, obj.Which, float(obj.Length.Value), float(obj.Clearance.Value))
        made = getattr(self, "_made", None)
        if made is not None and made[0] == key and made[1].isPartner(tab.Shape):  # (same solid, wherever placed)
            return made[2]
        shape = geometry.punch_shape(_local_shape(tab), geometry.rims_from_json(tab.RimData), obj.Which,
                                     float(obj.Length.Value), float(obj.Clearance.Value))
        self._made = (key, tab.Shape, shape)
        self.cuts = getattr(self, "cuts", 0) + 1
        return shape


class DieProxy(_Proxy):
    """Die of a tablet: a cylinder with the bore (the tablet's outline), centred on the band."""

    Type = "TabletcadDie"

    def __init__(self, obj, tablet=None):
        super().__init__(obj)
        self._setup(obj)
        obj.Tablet = tablet  # (StandardSize false until the maker has set the sizes: see onChanged)

    def _setup(self, obj):
        self._add(obj, "App::PropertyLink", "Tablet", "Die", "the tablet this die forms")
        self._add(obj, "App::PropertyBool", "StandardSize", "Die",
                  "the TSM die for the tablet's size, as tabletcad build takes it (B 30.16 x 22.22 mm up to 16 mm "
                  "round and 19 mm shaped, D 38.10 x 23.81 mm up to 25 mm), followed when the tablet changes; false "
                  "(also once OuterDiameter or Height is set): OuterDiameter and Height as given")
        if "Clearance" in obj.PropertiesList:  # a document of an earlier version: the punches take it now
            self._hand_clearance_to_punches(obj)
            obj.removeProperty("Clearance")
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
        self._add(obj, "App::PropertyFloat", "Volume", "Results (mm³)", "volume of the die, mm³", mode=_READONLY)

    def set_size(self, obj, outer_diameter: float, height: float) -> None:
        """Set the die's size as the standard's (``StandardSize`` stays as it is)."""
        self._sizing = True
        try:
            obj.OuterDiameter, obj.Height = _qty(outer_diameter, "mm"), _qty(height, "mm")
        finally:
            self._sizing = False

    def onChanged(self, obj, prop):
        # a size the user sets is kept: the die stops following the standard (it had been set back to the
        # standard's at the next recompute, without a word)
        if (prop in ("Height", "OuterDiameter") and getattr(self, "_ready", False) and not getattr(self, "_sizing", False)
                and getattr(obj, "StandardSize", False) and not getattr(obj.Document, "Transacting", False)):
            obj.StandardSize = False

    @staticmethod
    def _hand_clearance_to_punches(obj):
        """A document of an earlier version kept the radial clearance on the die (its bore the outline
        widened by it, the punch tips the outline): its value goes to the punches of the same tablet
        (their tips now the outline inset by it, the bore the outline: the same clearance), which
        restored before or after the die and had none of their own then."""
        value = obj.Clearance
        for o in obj.Document.Objects:
            proxy = getattr(o, "Proxy", None)
            if getattr(proxy, "Type", None) == PunchProxy.Type and o.Tablet == obj.Tablet and obj.Tablet is not None:
                proxy._setup(o)  # (adds Clearance if the punch has not been restored yet)
                o.Clearance = value

    def build(self, obj):
        tab = _tablet_of(obj)
        rims = geometry.rims_from_json(tab.RimData)
        if getattr(obj, "StandardSize", False):  # the die follows the tablet's size (a 10 mm die had stayed on 28 mm)
            outer = [r for r in rims if not r["inner"]]
            shaped = any(r.get("shaped", False) for r in outer)  # (not in a document of before)
            sizes = [r["plan_size"] for r in outer if "plan_size" in r]
            size = max(sizes) if sizes else geometry.plan_size(tab.Shape)
            od, height, _ = standard_die(size, shaped, float(obj.OuterDiameter.Value))
            if abs(float(obj.OuterDiameter.Value) - od) > 1e-12 or abs(float(obj.Height.Value) - height) > 1e-12:
                self.set_size(obj, od, height)
        shape = self._body(tab, rims, float(obj.Height.Value), float(obj.OuterDiameter.Value))
        obj.Shape = shape
        obj.Placement = tab.Placement
        obj.Volume = float(shape.Volume)

    def _body(self, tab, rims: list, height: float, outer_diameter: float):
        """The die's shape (:func:`geometry.die_shape`), cut again only when what it is made of changed: the
        tablet's rims, ``height`` and ``outer_diameter`` (mm).

        A recompute of the die for anything else (the tablet's ``Density`` or ``Label``, whose recompute
        recomputes the linked tools) had cut the bore again, as the punches' tips had been (``cuts`` counts
        the cuts made, this session).

        Parameters
        ----------
        tab : App.FeaturePython
            The die's tablet (:func:`_tablet_of`).
        rims : list of dict
            Its rims (:func:`geometry.rims_from_json` of ``tab.RimData``).
        height, outer_diameter : float
            The die's size (mm).

        Returns
        -------
        Part.Shape
            The die, in the tablet's own frame.
        """
        key = (tab.RimData, height, outer_diameter)
        made = getattr(self, "_made", None)
        if made is not None and made[0] == key:
            return made[1]
        shape = geometry.die_shape(rims, height, outer_diameter)
        self._made = (key, shape)
        self.cuts = getattr(self, "cuts", 0) + 1
        return shape


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

    def setEdit(self, vobj, mode=0):
        """Double click / Edit: the tablet's task panel (tooling: FreeCAD's default)."""
        if mode != 0 or not is_tablet(vobj.Object):
            return None
        from .taskpanel import edit_tablet

        if edit_tablet(vobj.Object) is None:  # a design file's tablet: a message, no panel, edit mode left at once
            from PySide import QtCore
            import FreeCADGui

            QtCore.QTimer.singleShot(0, lambda: FreeCADGui.ActiveDocument and FreeCADGui.ActiveDocument.resetEdit())
        return True  # (False would start FreeCAD's own Transform edit)

    def unsetEdit(self, vobj, mode=0):
        if mode != 0 or not is_tablet(vobj.Object):
            return None
        import FreeCADGui

        FreeCADGui.Control.closeDialog()
        return True

    def doubleClicked(self, vobj):
        if not is_tablet(vobj.Object):
            return False
        import FreeCADGui

        FreeCADGui.ActiveDocument.setEdit(vobj.Object.Name, 0)
        return True

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


def design_density(path) -> float | None:
    """The compact's density (mg/mm³) a design file's ``[report]`` table gives (its solid fraction times
    its true density), or None when it gives neither or the file cannot be read."""
    try:
        import tomllib
    except ImportError:  # Python < 3.11
        import tomli as tomllib
    try:
        rep = tomllib.loads(open(os.fspath(path), encoding="utf-8").read()).get("report", {})
        sf, rho = rep.get("solid_fraction"), rep.get("true_density_mg_mm3")
        return None if sf is None or rho is None else float(sf) * float(rho)
    except Exception:
        return None


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
