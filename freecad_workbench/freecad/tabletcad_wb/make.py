"""Headless constructors (no GUI needed): ``make_tablet``, ``make_upper_punch``, ``make_lower_punch``,
``make_die``, ``make_tooling``.

Example (``freecadcmd``)::

    import FreeCAD
    from freecad.tabletcad_wb.make import make_tablet, make_tooling
    doc = FreeCAD.newDocument("tablet")
    t = make_tablet(doc, "concave_round", diameter=9.0, cup_depth=0.9)
    up, low, die = make_tooling(doc, t)
    doc.recompute()
"""

from __future__ import annotations

import os
from contextlib import contextmanager
from pathlib import Path

import FreeCAD

from . import objects

__all__ = ["design_tooling", "make_die", "make_lower_punch", "make_tablet", "make_tooling", "make_upper_punch"]


def _value(v, unit="mm", name=None):
    """Accept numbers (mm / deg), strings with units (``"9 mm"``, ``"0.4 in"``, FreeCAD's unit parser; a plain
    number in ``unit``) or Quantities; a ValueError naming ``name`` for text that is no quantity or one of
    another kind (``"10 kg"`` for a length)."""
    if isinstance(v, (int, float)):
        return FreeCAD.Units.Quantity(float(v), FreeCAD.Units.Unit(unit))
    kind = "an angle (deg, rad)" if unit == "deg" else "a length (mm, cm, in, ...)"
    try:
        q = FreeCAD.Units.Quantity(v)
    except Exception as exc:  # FreeCAD's parser: ValueError "syntax error", ArithmeticError ...
        raise ValueError(f"{name or 'value'} = {v!r} is not allowed: must be {kind} ({exc})") from None
    if q.Unit == FreeCAD.Units.Unit():  # a plain number in text: the property's unit
        return FreeCAD.Units.Quantity(float(q.Value), FreeCAD.Units.Unit(unit))
    if q.Unit != FreeCAD.Units.Unit(unit):
        raise ValueError(f"{name or 'value'} = {v!r} is not allowed: must be {kind}")
    return q


def _density(density) -> tuple[float, str | None]:
    """``make_tablet``'s ``density`` in mg/mm³, and the text it was given as (None for a number).

    Parameters
    ----------
    density : float, str or FreeCAD.Units.Quantity
        mg/mm³ (= g/cm³) as a number, or a density with units (``"1.2 g/cm^3"``, a Quantity).

    Returns
    -------
    tuple of (float, str or None)
        The density (mg/mm³) and what to quote when it is refused.

    Raises
    ------
    tabletcad.errors.DesignError
        Text that is no quantity, or a quantity that is no density, naming ``density``.
    """
    from tabletcad.errors import DesignError

    if not (isinstance(density, str) or (hasattr(density, "Unit") and hasattr(density, "Value"))):
        return float(density), None
    # a string with units or a FreeCAD Quantity (float() of one is its value in kg/mm^3: 1.2 g/cm^3 had been
    # stored as 1.2e-6 mg/mm^3)
    given = density if isinstance(density, str) else density.UserString
    kind = "a density: mg/mm³ as a number, or with units such as '1.2 g/cm^3'"
    try:
        q = FreeCAD.Units.Quantity(density)
    except Exception as exc:  # FreeCAD's parser: ValueError "syntax error", ArithmeticError ...
        raise DesignError("density", given, f"must be {kind} ({exc})") from None
    if q.Unit != FreeCAD.Units.Unit("kg/mm^3"):
        raise DesignError("density", given, f"must be {kind}")
    return float(q.Value) * 1e6, given  # kg/mm^3 -> mg/mm^3


def _checked_core(spec: dict, given: str):
    """The core tablet of ``make_tablet``'s arguments, built before the object is made: what the core refuses
    is refused with the value as given, and no object is added.

    A value set into a property first could be another: a ``PropertyLength`` stores -5 mm as 0 mm and an
    angle 400° as 360°, and the refusal had quoted those, after an invalid object had been added (as it had
    for a missing design file).

    Parameters
    ----------
    spec : dict
        ``{family, params, design}`` as :meth:`objects.TabletProxy.spec` gives it (mm, deg; ``design``
        the resolved path of a design file, or None).
    given : str
        ``make_tablet``'s first argument as given (a design file's refusal quotes it).

    Returns
    -------
    tabletcad.geometry.tablet.Tablet
        The core's tablet (handed to the object: its first recompute does not build it again).

    Raises
    ------
    tabletcad.errors.DesignError
        The core's refusal (a missing or unreadable design file names ``design_file`` as given).
    """
    from tabletcad.errors import DesignError

    try:
        return objects.core_tablet_of(spec)  # (the recompute's and the task panel's one way in)
    except DesignError as exc:
        if exc.parameter == "design_file" and exc.value == spec["design"] and given != spec["design"]:
            raise DesignError("design_file", given, f"{exc.allowed} (read as {spec['design']})") from None
        raise


@contextmanager
def _new(doc, name):
    """A new scripted object, taken out of the document again when what is made of it fails (a misspelt
    argument or a refused value had left an unbuilt object behind)."""
    obj = doc.addObject("Part::FeaturePython", name)
    try:
        yield obj
    except BaseException:
        doc.removeObject(obj.Name)
        raise


def make_tablet(doc, design_or_family="thesis.flat_faced_round", name=None, recompute=True, **params):
    """A parametric Tablet.

    ``design_or_family``: a family name (see ``tabletcad shapes``) or the path
    of a design file (TOML).  A plain family design (a ``[tablet]`` table with a
    family and numbers, optionally a ``[report]`` table, which does not change
    the geometry) becomes a family Tablet with its dimensions as properties;
    any other design (free_form, trim, reshape, tooling tables) is kept as
    ``Family = design_file`` with ``DesignFile`` set.
    ``params``: dimensions by core name (``diameter=9.0``, ``cup_depth="0.8 mm"``),
    plus ``density`` (mg/mm³, or a string with units such as ``"1.2 g/cm^3"``) and
    ``fit_tolerance`` (mm, 1e-7 to 0.01; 0 for the core's default, 0.0001 mm, which ``FitTolerance``
    then holds).
    """
    density = params.pop("density", None)
    user_density = density is not None
    fit_tol = params.pop("fit_tolerance", None)
    design = None
    label = name
    family = str(design_or_family)
    if family.endswith(".toml") or os.path.sep in family or Path(family).is_file():
        design = Path(family).resolve()
        plain = objects.design_is_parametric(design)
        if density is None:  # the design's own [report] solid fraction x true density, as its report weighs it
            density = objects.design_density(design)
        if plain is not None:
            family, dims, design_name = plain
            params = {**dims, **params}
            design = None
            label = label or design_name or Path(design_or_family).stem
        else:
            family = objects.DESIGN_FILE
            label = label or Path(design_or_family).stem
    if family != objects.DESIGN_FILE:  # an old name of a renamed family: one warning, its new name
        from tabletcad.families import family as lookup_family

        family = lookup_family(family, parameter="family").name
    # every argument read before the object is made: a misspelt name or a value of the wrong kind leaves
    # nothing in the document (an unbuilt "Tablet" had stayed behind each time)
    fam = objects._family(family) if family != objects.DESIGN_FILE else None
    values = {}
    for k, v in params.items():
        if fam is None or k not in fam.params:
            raise ValueError(f"family {family!r} has no parameter {k!r}")
        values[objects.prop_name(k)] = _value(v, "deg" if fam.params[k] == "deg" else "mm", k)
    if user_density:  # mg/mm^3, or a string with units ("1.2 g/cm^3"); in range before any object
        density, given = _density(density)
        objects.check_density("density", density, given)
    if fit_tol is not None:
        fit_tol = _value(fit_tol, "mm", "fit_tolerance")
        objects.check_fit_tolerance("fit_tolerance", float(fit_tol.Value))  # (-1 mm had become 0, the default)
        if float(fit_tol.Value) == 0.0:  # the default, held by the property as the value used (it refuses 0)
            fit_tol = FreeCAD.Units.Quantity(objects._default_fit(), FreeCAD.Units.Unit("mm"))
    if fam is None and design is None:  # ("design_file" given as a family: a tablet of no file had been added)
        from tabletcad.errors import DesignError

        raise DesignError("design_or_family", family, "give the path of a design file (TOML) or a family name")
    if fam is None:
        spec = {"family": None, "params": {}, "design": str(design)}
    else:  # the values as the object's properties will hold them: given (mm, deg) or the family's defaults
        given_values = {k: float(values[objects.prop_name(k)].getValueAs("deg" if u == "deg" else "mm"))
                        for k, u in fam.params.items() if objects.prop_name(k) in values}
        spec = {"family": fam.name, "params": {k: given_values.get(k, float(fam.defaults[k])) for k in fam.params},
                "design": None}
    digest = objects._file_digest(spec["design"])
    core = _checked_core(spec, str(design_or_family))
    with _new(doc, "Tablet") as obj:
        objects.TabletProxy(obj, family)
        if design is not None:
            obj.DesignFile = str(design)
        for p, q in values.items():
            setattr(obj, p, q)
        if density is not None:
            obj.Density = density
        if fit_tol is not None:
            obj.FitTolerance = fit_tol
        obj.Label = label or family
        obj.Proxy.adopt_core(obj, core, spec, digest)
        objects.attach_view_provider(obj)
    if recompute:
        doc.recompute()
    return obj


def _punch(doc, tablet, which, length, clearance, recompute):
    if length is None or clearance is None:  # the design file's [tooling] table, as build reads it
        values = design_tooling(tablet)[0]
        if length is None:
            length = values.get("lower_length", values.get("length")) if which == "lower" else values.get("length")
        clearance = values.get("clearance") if clearance is None else clearance
    # read before the object is made: a bad one leaves nothing behind
    length = None if length is None else _value(length, "mm", "length" if which == "upper" else "lower_length")
    clearance = None if clearance is None else _value(clearance, "mm", "clearance")
    with _new(doc, "UpperPunch" if which == "upper" else "LowerPunch") as obj:
        objects.PunchProxy(obj, tablet, which)
        if length is not None:
            obj.Length = length
        if clearance is not None:
            obj.Clearance = clearance
        obj.Label = f"{tablet.Label} {which} punch"
        objects.attach_view_provider(obj)
    if recompute:
        doc.recompute()
    return obj


def make_upper_punch(doc, tablet, length=None, recompute=True, clearance=None):
    """Upper punch tip linked to ``tablet``: the prism above the upper band edge, inside the outline
    by ``clearance``, minus the tablet.  ``length`` and ``clearance`` not given come from the
    ``[tooling]`` table of the tablet's design file, else the defaults (10 mm, 0.025 mm)."""
    return _punch(doc, tablet, "upper", length, clearance, recompute)


def make_lower_punch(doc, tablet, length=None, recompute=True, clearance=None):
    """Lower punch tip linked to ``tablet`` (as :func:`make_upper_punch`, below the lower band edge)."""
    return _punch(doc, tablet, "lower", length, clearance, recompute)


def make_die(doc, tablet, *, height=None, outer_diameter=None, recompute=True):
    """Die linked to ``tablet``: cylinder minus the bore (the tablet's outline); keywords only (the
    clearance that came third is the punches' now: an old positional call is a TypeError).  Without
    ``outer_diameter``, the TSM die for the tablet's size, as ``tabletcad build`` takes it (B,
    30.16 x 22.22 mm, round tablets up to 16 mm and shaped ones up to 19 mm; D, 38.10 x 23.81 mm, up to 25
    mm); neither given, the design file's ``[tooling]`` table first."""
    if outer_diameter is None and height is None:  # the design file's [tooling] table, as build reads it
        values = design_tooling(tablet)[0]
        height, outer_diameter = values.get("die_height"), values.get("die_outer_diameter")
    standard = outer_diameter is None and height is None  # the TSM die, followed when the tablet changes
    if outer_diameter is None:  # (an outer diameter given alone keeps the 22.22 mm height, as build does)
        core = tablet.Proxy.current_core_tablet(tablet)  # (the one its recompute built, when current)
        dims = core.dimensions()
        outer_diameter, h, _ = objects.standard_die(max(dims["length_mm"], dims["width_mm"]), core.revolution is None)
        height = h if height is None else height
    sizes = {prop: _value(v, "mm", name) for prop, name, v in (("Height", "die_height", height),
                                                                ("OuterDiameter", "die_outer_diameter", outer_diameter))
             if v is not None}  # read before the object is made: a bad one leaves nothing behind
    with _new(doc, "Die") as obj:
        objects.DieProxy(obj, tablet)
        for prop, q in sizes.items():
            setattr(obj, prop, q)
        obj.StandardSize = standard  # (after the sizes: a size set while it is true makes the die a custom one)
        obj.Label = f"{tablet.Label} die"
        objects.attach_view_provider(obj)
    if recompute:
        doc.recompute()
    return obj


def design_tooling(tablet):
    """What the workbench takes from the ``[tooling]`` table of the tablet's design file: ``(values,
    left)``, the keyword arguments of :func:`make_tooling` (clearance, tip lengths, die height and outer
    diameter) and the names of what it does not build (scores, embossing, complete punch bodies: those
    are made by ``tabletcad build``).  ``({}, [])`` for a tablet without a design file or table."""
    path = getattr(tablet, "DesignFile", "") or ""
    if not path:
        return {}, []
    from tabletcad.pipeline.design import Design

    spec = Design.from_toml(path).tooling_spec
    if spec is None:
        return {}, []
    values = dict(clearance=spec.clearance_mm, length=spec.tip_length_mm, lower_length=spec.lower_tip_length_mm,
                  die_height=spec.die_height_mm, die_outer_diameter=spec.die_outer_diameter_mm)
    left = [name for name, given in (("[[tooling.score]]", spec.scores), ("[[tooling.emboss]]", spec.emboss),
                                     ("complete punches ([tooling] standard)", spec.body)) if given]
    return {k: v for k, v in values.items() if v is not None}, left


def make_tooling(doc, tablet, recompute=True, **kw):
    """Upper punch, lower punch and die of ``tablet``.

    Keywords (mm): ``clearance``, ``length`` (upper tip), ``lower_length``, ``die_height``,
    ``die_outer_diameter``; those not given come from the ``[tooling]`` table of the tablet's design
    file, as ``tabletcad build`` reads it, else the objects' defaults.  What the table asks for that the
    workbench does not build (scores, embossing, complete punch bodies) is named in a warning."""
    allowed = {"clearance", "length", "lower_length", "die_height", "die_outer_diameter"}
    unknown = sorted(set(kw) - allowed)
    if unknown:
        raise TypeError(f"make_tooling() got unexpected keyword arguments {unknown}; allowed: {sorted(allowed)}")
    values, left = design_tooling(tablet)
    values.update({k: v for k, v in kw.items() if v is not None})
    if left:
        FreeCAD.Console.PrintWarning(
            f"tabletcad: {tablet.Label}: the workbench makes plain punch tips and a die; {', '.join(left)} of "
            f"{Path(tablet.DesignFile).name} are built by `tabletcad build` only\n")
    made = []  # nothing of it is left when a part cannot be made (the punches had stayed without their die)
    try:
        made.append(make_upper_punch(doc, tablet, values.get("length"), False, values.get("clearance")))
        made.append(make_lower_punch(doc, tablet, values.get("lower_length", values.get("length")), False,
                                     values.get("clearance")))
        made.append(make_die(doc, tablet, height=values.get("die_height"),
                             outer_diameter=values.get("die_outer_diameter"), recompute=False))
    except BaseException:
        for o in made:
            doc.removeObject(o.Name)
        raise
    up, low, die = made
    if recompute:
        doc.recompute()
    return up, low, die
