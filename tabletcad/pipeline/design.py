"""Design files: tablets described in TOML.

A design names a family and its dimensions (mm)::

    [tablet]
    family = "thesis.flat_faced_round"
    diameter = 10.0
    thickness = 6.0

or gives the tablet patch by patch (``family = "free_form"``)::

    [tablet]
    family = "free_form"
    name = "my_tablet"
    a = 1.0                       # smoothing parameter, or "auto"

    [[patch]]                      # four curves at u = 0, 1/3, 2/3, 1
    curves = [
      { type = "circle", radius = 0.0, z = 0.0 },
      { type = "circle", radius = 1.5, z = 0.0 },
      { type = "circle", radius = 3.0, z = 0.0 },
      { type = "circle", radius = 4.5, z = 0.0 },
    ]
    [[patch]]
    curves = [ "previous", { type = "stadium", length = 12, width = 6, z = 1 }, ... ]

Curve types: ``circle`` (radius), ``ellipse`` (rx, ry), ``stadium`` (length,
width), ``rounded_rectangle`` (length, width, corner_radius), ``points``
(points = [[x, y, z], ...] or [[x, y], ...]); each with ``z`` or
``center = [x, y, z]``.  ``"previous"`` repeats the previous patch's last curve.
Optional tables: ``[trim]`` (u, v, w ranges) and ``[reshape]`` (``spine`` =
one factor per patch, ``radius`` = one factor) — the thesis's section 4.4.
"""

from __future__ import annotations

import copy
import datetime
import decimal
import json
import math
import numbers
import re
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from tabletcad.geometry.curves import Circle, Curve, Ellipse, PointCurve, RoundedRectangle, Stadium
from tabletcad.errors import MISSING, DesignError, check_finite, is_number, one_token
from tabletcad.geometry.patch import PDEPatch
from tabletcad.families import FAMILIES, RENAMED
from tabletcad.families import family as lookup_family
from tabletcad.pipeline.designreport import ReportOptions
from tabletcad.tooling.spec import ToolingSpec, parse_tooling, printable_line
from tabletcad.geometry.tablet import Tablet, Trim
from tabletcad.tolerance import DEFAULT, Tolerances
from tabletcad.readonly import TableDict, TableList
from tabletcad.io.tomlfile import read_toml_file


__all__ = ["Design", "load_design", "read_design_file", "design_from_dict", "design_to_toml", "toml_text", "TOP_LEVEL_KEYS"]

TOP_LEVEL_KEYS = ("tablet", "patch", "trim", "reshape", "tooling", "report")
_CURVE_KEYS = {
    "circle": {"radius"},
    "ellipse": {"rx", "ry"},
    "stadium": {"length", "width"},
    "rounded_rectangle": {"length", "width", "corner_radius"},
    "points": {"points"},
}


def read_design_file(path: str | Path) -> dict[str, Any]:
    """The parsed TOML of a design file; any problem with the file is a :class:`DesignError`
    naming ``design_file`` (a folder, a missing or unreadable file, invalid or too deeply
    nested TOML, an integer literal longer than Python converts: :func:`tabletcad.io.tomlfile.read_toml_file`)."""
    return read_toml_file(path, "design_file")


def load_design(path: str | Path) -> Tablet:
    """Read a TOML design file and build its tablet: ``Design.from_toml(path).build()``."""
    return Design.from_toml(path).build()


def _number(where: str, value: Any, unit: str = "", *, tol: Tolerances = DEFAULT, coordinate: bool = False,
            least: bool = True) -> float:
    """A number read from a design: an int or float (never a boolean or a string), finite,
    and for lengths and coordinates (``unit == "mm"``) within ``±tol.max_length``; a length
    (not a ``coordinate``) is 0 or at least ``tol.min_length`` (not checked here with ``least``
    False: a family's constructor refuses it, knowing whether 0 builds,
    :func:`tabletcad.families.family.lengths_checked`)."""
    if isinstance(value, bool):
        raise DesignError(where, value, "must be a number (true and false are not numbers)", unit)
    if not is_number(value):  # an int, float, numpy scalar, Fraction or Decimal
        auto = where.split(".")[-1] == "a"  # the smoothing parameter also takes "auto"
        raise DesignError(where, value, 'must be a number or "auto"' if auto else "must be a number", unit)
    x = check_finite(where, value, unit)
    if unit == "mm" and abs(x) > tol.max_length:
        raise DesignError(where, value, f"must be within ±{tol.max_length:g} mm (size limit, Tolerances.max_length)", unit)
    if unit == "mm" and not coordinate and least and 0.0 < x < tol.min_length:
        raise DesignError(where, value, f"must be 0 or at least {tol.min_length:g} mm (Tolerances.min_length: a "
                          "smaller feature is below the tolerance the surface is certified to)", unit)
    return x


def _lengths(where: str, value: Any, *, tol: Tolerances = DEFAULT, kinds: bool = False) -> None:
    """Check every number inside nested lists (points, outline segments) with :func:`_number`
    as a length; with ``kinds`` the first entry of each item is a segment kind (text), left to the
    reader of the list.  Text anywhere else is refused (``"4.5"`` is not a coordinate)."""
    if isinstance(value, list):
        for i, item in enumerate(value):
            if kinds and isinstance(item, list) and item and isinstance(item[0], str):
                for k, part in enumerate(item[1:], start=1):
                    _lengths(f"{where}[{i}][{k}]", part, tol=tol)
            else:
                _lengths(f"{where}[{i}]", item, tol=tol)
    else:
        _number(where, value, "mm", tol=tol, coordinate=True)


def _check_keys(where: str, table: dict, allowed: set[str]) -> None:
    for k in table:
        if k not in allowed:
            raise DesignError(one_token(f"{where}.{k}" if where else k), table[k],
                              f"allowed keys{' of ' + where if where else ''} are {', '.join(sorted(allowed))}")


def _points_in_space(kind: str, spec: dict) -> bool:
    """Whether a curve table places itself without ``z`` or ``center``: a ``points`` curve whose every point
    is ``[x, y, z]`` (mm)."""
    pts = spec.get("points")
    return kind == "points" and isinstance(pts, list) and bool(pts) and all(
        isinstance(q, list) and len(q) == 3 for q in pts)


def _curve(spec: Any, where: str, previous: Curve | None) -> Curve:
    if spec == "previous":
        if previous is None:
            raise DesignError(where, "previous", "the first patch has no previous curve")
        return previous
    if not isinstance(spec, dict) or "type" not in spec:
        raise DesignError(where, spec, "must be a table with a 'type' or the string 'previous'")
    kind = spec["type"]
    if kind not in _CURVE_KEYS:
        raise DesignError(f"{where}.type", kind, f"must be one of {', '.join(_CURVE_KEYS)}")
    _check_keys(where, spec, _CURVE_KEYS[kind] | {"type", "z", "center"})
    for k in _CURVE_KEYS[kind]:
        if k not in spec:
            raise DesignError(f"{where}.{k}", MISSING, f"a {kind} curve needs {', '.join(sorted(_CURVE_KEYS[kind]))}")
    if "center" in spec and "z" in spec:
        raise DesignError(f"{where}.z", spec["z"], "give either z or center, not both")
    if "center" not in spec and "z" not in spec and not _points_in_space(kind, spec):  # not guessed (a curve
        # without either had been placed at z = 0, wherever its neighbours lie)
        raise DesignError(f"{where}.z", MISSING, f"a {kind} curve needs its height z (mm) or its center [x, y, z] (mm)"
                          + (" (or [x, y, z] points)" if kind == "points" else ""))
    if "center" in spec:
        center = spec["center"]
        if not (isinstance(center, (list, tuple)) and len(center) == 3):
            raise DesignError(f"{where}.center", center, "must be [x, y, z] in mm")
        center = tuple(_number(f"{where}.center", c, "mm", coordinate=True) for c in center)
    else:  # z alone: named as given (z = true had been refused as "center = true")
        center = (0.0, 0.0, _number(f"{where}.z", spec.get("z", 0.0), "mm", coordinate=True))
    num = {k: _number(f"{where}.{k}", spec[k], "mm") for k in _CURVE_KEYS[kind] if k != "points"}
    try:
        if kind == "circle":
            c: Curve = Circle(num["radius"], center)
            return c
        if kind == "ellipse":
            return Ellipse(num["rx"], num["ry"], center)
        if kind == "points":
            pts = spec["points"]
            if not isinstance(pts, list) or not all(isinstance(q, list) and len(q) in (2, 3) for q in pts):
                raise DesignError(f"{where}.points", pts, "must be a list of [x, y] or [x, y, z] points in mm")
            _lengths(f"{where}.points", pts)
            return PointCurve(pts, z=center[2]).moved((center[0], center[1], 0.0))
        if kind == "stadium":
            base = Stadium(num["length"], num["width"])
        else:
            base = RoundedRectangle(num["length"], num["width"], num["corner_radius"])
        return base.moved(center)
    except DesignError as exc:
        if exc.parameter.startswith(where):
            raise
        raise exc.renamed(one_token(f"{where}.{exc.parameter}")) from None


_TABLES = ("trim", "reshape", "report", "tooling")


def _table_hash(value: Any) -> int:
    """A hash of a table consistent with ``==`` on it: Python's own for scalars (``hash(10) ==
    hash(10.0)``, ``hash(0.0) == hash(-0.0)``), order-free for a table's keys, in order for a list."""
    if isinstance(value, dict):
        return hash(frozenset((k, _table_hash(v)) for k, v in value.items()))
    if isinstance(value, (list, tuple)):
        return hash(tuple(_table_hash(v) for v in value))
    try:
        return hash(value)
    except TypeError:  # (an array given to Design() directly)
        return hash(repr(value))


def _read_only(value: Any) -> Any:
    """``value`` with every dict and list in it read-only (:class:`TableDict`, :class:`TableList`)."""
    if isinstance(value, dict):
        return TableDict({k: _read_only(v) for k, v in value.items()})
    if isinstance(value, list):
        return TableList(_read_only(v) for v in value)
    return value


@dataclass(frozen=True)
class Design:
    """A design as data: the tables of a design file, checked, before any geometry is built.

    Separate from the :class:`~tabletcad.geometry.tablet.Tablet` it builds (:meth:`build`), it reads from
    and writes to TOML (:meth:`from_toml`, :meth:`to_toml`) and plain dictionaries
    (:meth:`from_dict`, :meth:`to_dict`: what sweeps vary and send to their workers).  Family
    names are current: an old name is replaced by its new one when the design is read.

    Attributes
    ----------
    tablet : dict
        The ``[tablet]`` table: ``family``, ``name`` and the family's dimensions (mm, deg).
    patch : list or None
        The ``[[patch]]`` tables of a ``free_form`` design.
    trim, reshape, report, tooling : dict or None
        The optional tables of the same names.
    comment : str
        Lines written as ``#`` comments at the top of :meth:`to_toml` (not part of the value).
    folder : Path or None
        The folder relative file names in the design (an emboss ``svg``) start in: the design
        file's (:meth:`from_toml`), else the current folder (not part of the value).
    report_options : ReportOptions
        The ``[report]`` table, checked (derived; not an argument).
    tooling_spec : ToolingSpec or None
        The ``[tooling]`` table, checked (derived; not an argument), or None without one.

    The tables are the design's own read-only copies (a change raises ``TypeError``: change
    :meth:`to_dict`'s copy and make a new design); designs with equal tables are equal and hash
    alike.  A bad ``[report]`` or ``[tooling]`` value is refused when the design is made, the
    ``[tablet]`` dimensions when it builds (:meth:`build`), both before any geometry.
    """

    tablet: dict
    patch: Any = None
    trim: dict | None = None
    reshape: dict | None = None
    report: dict | None = None
    tooling: dict | None = None
    comment: str = field(default="", compare=False, repr=False)
    folder: Path | None = field(default=None, compare=False, repr=False)
    report_options: ReportOptions = field(init=False, compare=False, repr=False)
    tooling_spec: ToolingSpec | None = field(init=False, compare=False, repr=False)

    def __post_init__(self) -> None:
        for table in ("tablet", "patch", *_TABLES):  # the design's own read-only copies (new dicts and lists)
            object.__setattr__(self, table, _read_only(getattr(self, table)))
        object.__setattr__(self, "report_options", ReportOptions.from_table(self.report))
        object.__setattr__(self, "tooling_spec",
                           None if self.tooling is None else parse_tooling(self.tooling, base=self.folder))

    def __hash__(self) -> int:  # of the tables, as == compares them: 10 and 10.0, 0.0 and -0.0 hash alike
        return hash(tuple(_table_hash(getattr(self, t)) for t in ("tablet", "patch", *_TABLES)))

    def __copy__(self) -> Design:  # a value: its tables are read-only, so a copy is itself
        return self

    def __deepcopy__(self, memo) -> Design:  # (a deep copy had made the tables plain, changeable dicts)
        return self

    @property
    def name(self) -> str:
        return self.tablet["name"]

    @property
    def family(self) -> str:
        return self.tablet["family"]

    @classmethod
    def from_dict(cls, data: Any, default_name: str = "tablet", *, comment: str = "",
                  folder: str | Path | None = None) -> Design:
        """A design from its dictionary (the TOML structure above); the name defaults to ``default_name``.

        Checks what needs no geometry: the top-level tables, the name, the family.  The
        dimensions are checked by :meth:`build`, before any geometry is built.
        """
        return cls._from_dict(data, default_name, comment, None if folder is None else Path(folder))

    @classmethod
    def _from_dict(cls, data: Any, default_name: str, comment: str, folder: Path | None) -> Design:
        if not isinstance(data, dict):
            raise DesignError("design", type(data).__name__, "must be a TOML table")
        _check_keys("", data, set(TOP_LEVEL_KEYS))
        if "tablet" not in data or not isinstance(data["tablet"], dict):
            raise DesignError("tablet", MISSING if "tablet" not in data else data["tablet"],
                              "a design needs a [tablet] table with a family")
        data = _as_toml(data)
        tab = data["tablet"]
        name = tab.get("name", default_name)  # given empty, it is refused (not replaced by the default)
        if not isinstance(name, str) or not name.strip() or any(ch in name for ch in '/\\"') or len(name) > 200 or \
                not printable_line(name):  # (a NUL had reached stdout, the picture's title and the STEP product, cut)
            allowed = ('must be a plain non-empty name (no / \\ " or control character such as a line break or NUL, at '
                       'most 200 characters)')
            if "name" not in tab and folder is not None:  # the file's name stands for it (a trial: a key not in the file)
                raise DesignError("tablet.name", name, f"{allowed}: the design file's name is the tablet's when its "
                                  "[tablet] table gives none; give name = ... there, or rename the file")
            raise DesignError("tablet.name", name, allowed)
        family = tab.get("family")
        families = ", ".join(FAMILIES) + ", custom_outline or free_form"
        if family is None:
            raise DesignError("tablet.family", MISSING, f"must be one of {families}")
        if not isinstance(family, str):
            raise DesignError("tablet.family", family, f"must be one of {families}")
        for table in _TABLES:
            if table in data and not isinstance(data[table], dict):
                raise DesignError(table, data[table], "must be a table")
        if family not in ("free_form", "custom_outline"):
            if family not in FAMILIES and family not in RENAMED:
                raise DesignError("tablet.family", family, f"must be one of {families}")
            family = lookup_family(family).name  # an old name: one warning, then its new family
        tablet = {"family": family, "name": name, **{k: v for k, v in tab.items() if k not in ("family", "name")}}
        return cls(tablet, data.get("patch"), **{t: data.get(t) for t in _TABLES}, comment=comment, folder=folder)

    @classmethod
    def from_toml(cls, path: str | Path) -> Design:
        """The design of a TOML file; its name defaults to the file's stem."""
        path = Path(path)
        return cls.from_dict(read_design_file(path), default_name=path.stem, folder=path.parent)

    def to_dict(self) -> dict[str, Any]:
        """The design as a plain dictionary (a copy; :meth:`from_dict` reads it back)."""
        out: dict[str, Any] = {"tablet": copy.deepcopy(self.tablet)}
        if self.patch is not None:
            out["patch"] = copy.deepcopy(self.patch)
        for t in _TABLES:
            if getattr(self, t) is not None:
                out[t] = copy.deepcopy(getattr(self, t))
        return out

    def to_toml(self) -> str:
        """The design as TOML text (:meth:`from_toml` reads it back to an equal design)."""
        return toml_text(self.to_dict(), comment=self.comment)

    def build(self) -> Tablet:
        """The tablet of this design (geometry only: :attr:`report_options` and
        :attr:`tooling_spec` stay with the design).

        Everything is validated before geometry is built where it can be: unknown
        and missing keys, booleans or strings given for numbers, lengths beyond
        ``Tolerances.max_length``.  Errors name the parameter as one token
        (``tablet.diameter``, ``patch[0].curves[1].radius``).
        """
        return self._build()  # (every DesignError names its parameter as one token)

    def _build(self) -> Tablet:
        if not isinstance(self.tablet, dict):
            raise DesignError("tablet", self.tablet, "a design needs a [tablet] table with a family")
        tab = dict(self.tablet)
        family, name = tab.pop("family", None), tab.pop("name", None) or "tablet"
        a = tab.pop("a", None)
        if a is not None and a != "auto":
            a = _number("tablet.a", a)
        if family == "free_form":  # (family, name and a were taken above: the only keys it has)
            if tab:
                k = next(iter(tab))
                raise DesignError(f"tablet.{k}", tab[k], "allowed keys of tablet for free_form are a, family, name "
                                  "(the shape is in the [[patch]] tables)")
            tablet = _free_form(self.patch, name, 1.0 if a is None else a)
            _check_plan(tablet, "patch")
            _check_height(tablet, {}, "patch")
        elif family == "custom_outline":
            tablet = _custom_outline(tab, name)
            _check_plan(tablet, "tablet.outline" if "outline" in tab else "tablet.segments")
            _check_height(tablet, tab)
        else:
            fam = lookup_family(family)  # a Design made directly may hold an old or unknown name
            family = fam.name
            if self.patch is not None:
                raise DesignError("patch", "given", f"[[patch]] tables are only read for family free_form, not {family!r}")
            kw = {}
            for k, v in tab.items():
                if k not in fam.params:
                    raise DesignError(one_token(f"tablet.{k}"), v, f"family {family!r} takes {', '.join(fam.params)}")
                kw[k] = _number(f"tablet.{k}", v, fam.params[k], least=False)  # (the family's: 0 or not)
            kw.update(fam.left_out(kw))  # (a ffbe's bevel_width, when its bevel_depth is given)
            missing = [k for k in fam.params if k in fam.required and k not in kw]
            if missing:
                optional = [k for k in fam.params if k not in fam.required]
                raise DesignError(f"tablet.{missing[0]}", MISSING,
                                  f"family {family!r} needs {fam.needs()}"
                                  + (f" (optional: {', '.join(optional)})" if optional else ""))
            if a is not None:
                kw["a"] = a
            try:
                built = fam.build(**kw)
            except DesignError as exc:  # the constructor names its parameter: the design file says tablet.<name>
                if exc.parameter in fam.params and exc.parameter not in tab:  # its default: said as such
                    raise DesignError(f"tablet.{exc.parameter}", exc.value, f"{exc.allowed} ({exc.parameter} is not "
                                      "given: the value it takes by default)", exc.unit) from None
                if exc.parameter in fam.params or exc.parameter == "a":
                    raise exc.renamed(f"tablet.{exc.parameter}") from None
                if a is not None and exc.parameter.endswith("smoothing.parameter.a"):  # a patch's: the file's a
                    raise exc.renamed("tablet.a") from None
                raise
            _check_left_lengths(built, family, kw)
            tablet = replace(built, name=name)
            _check_height(tablet, kw)  # (its bounds kept for the report: on the tablet returned)
        if self.reshape is not None:
            tablet = _reshape(tablet, self.reshape)
            _check_size(tablet, what=self.reshape)
        if self.trim is not None:
            tablet = _trim(tablet, self.trim)
        return tablet


#: the parameter that leaves a part of a family's profile: (family, part) -> parameter(s), the first given
_LEFT_BY = {("ffbe", "band"): ("bevel_depth", "bevel_width"), ("ffbe", "flat face"): ("bevel_width", "bevel_depth"),
            ("ffre", "band"): ("edge_radius",), ("ffre", "flat face"): ("edge_radius",),
            ("concave_bevel", "cup"): ("bevel_width",)}
#: who leaves a part where the family has no entry in :data:`_LEFT_BY` (a flat-face round 0.001 mm
#: across leaves a face 0.0005 mm wide: its diameter, not the family, had been named)
_OUTLINE_DIMS = ("cup_width", "corner_radius", "end_radius", "side_radius")  # a shaped face's default cup width
_LEFT_BY_PART = {"flat face": ("diameter",) + _OUTLINE_DIMS, "cup": ("land",) + _OUTLINE_DIMS, "land": ("land",),
                 "band": ("band", "thickness")}


def _check_left_lengths(tablet: Tablet, family: str, kw: dict, tol: Tolerances = DEFAULT) -> None:
    """Refuse a family tablet whose dimensions leave a band or a part of its face profile shorter than
    ``tol.min_length`` but not 0 (a ffbe whose bevel takes the whole thickness but for 2e-16 mm of
    rounding in ``tan 45°``): every length a design file gives is 0 or at least that, and so is every
    length they leave, or the B-rep's sewing fails ("sewn shell has 4 faces, expected 5") where the
    report had passed.  Named by the parameter that leaves it (:data:`_LEFT_BY`), else ``tablet``."""
    from tabletcad.families.sweep import SweepNominal

    nom = tablet.nominal
    if not isinstance(nom, SweepNominal):
        return
    m = tol.min_length
    parts = [("band", nom.band_z[1] - nom.band_z[0])] + [(e.label or e.kind, e.length) for e in nom.top]
    for what, length in parts:
        if 0.0 < length < m * (1.0 - 1e-9):  # (3.001 - 2 x 1.5 is 0.000999999999999889: at the least length)
            names = [k for k in _LEFT_BY.get((family, what), ()) + _LEFT_BY_PART.get(what, ()) if kw.get(k)]
            left = f"leaves a {what} of {length:.3g} mm: a part the dimensions leave must be at least {m:g} mm " \
                   "(Tolerances.min_length, the least length a design takes) or, where the family allows it, none"
            if names:
                raise DesignError(f"tablet.{names[0]}", kw[names[0]], left, "mm")
            raise DesignError("tablet", family, left)


def design_from_dict(data: dict, default_name: str = "tablet") -> Tablet:
    """Build a tablet from a parsed design (the TOML structure above): ``Design.from_dict(...).build()``."""
    return Design.from_dict(data, default_name).build()


def _check_size(tablet: Tablet, tol: Tolerances = DEFAULT, *, what: dict | None = None) -> None:
    """Refuse a reshaped tablet that leaves ``±tol.max_length``, whose length, width or height exceeds
    ``tol.max_length`` (an overall dimension, as a family's diameter or length: ``Tolerances``) or is
    below ``tol.min_length`` (``what``: the ``[reshape]`` table, named in the refusal)."""
    lo, hi = tablet.bounds()
    big = float(max(np.max(np.abs(lo)), np.max(np.abs(hi))))
    if not big <= tol.max_length:
        raise DesignError("reshape", what if what is not None else "factors",
                          f"must keep the tablet within ±{tol.max_length:g} mm "
                          f"(size limit, Tolerances.max_length; it reaches {big:.6g} mm)")
    size = float(np.max(hi - lo))
    # an overall dimension, as a diameter (a 10 mm round at radius = 150 was 1501 mm); the bounds' rounding
    # aside (a 1000 mm round measures 1000.0000000000003 across)
    if not size <= tol.max_length * (1.0 + 1e-9):
        raise DesignError("reshape", what if what is not None else "factors",
                          f"must keep the tablet's length, width and height at most {tol.max_length:g} mm "
                          f"(size limit, Tolerances.max_length, as a diameter or length; the largest is {size:.6g} mm)")
    small = float(np.min(hi - lo))
    if not small >= tol.min_length:  # (a radius of 1e-5 mm had made a tablet 1e-4 mm across)
        raise DesignError("reshape", what if what is not None else "factors",
                          f"must leave the tablet's length, width and height at least {tol.min_length:g} mm "
                          f"(Tolerances.min_length, the least length a design takes; the smallest is {small:.6g} mm)")


#: a family's parameters that add to its height, the largest given named where the height is too large
_HEIGHT_BY = ("thickness", "height", "band", "cup_depth", "dome")


def _check_height(tablet: Tablet, given: dict, where: str = "tablet", tol: Tolerances = DEFAULT) -> None:
    """Refuse a tablet taller than ``tol.max_length``, the size limit a family's diameter or length keeps:
    each of its lengths lies within the limit, but not what they add up to (a concave round's 999 mm band
    with 400 mm cups had made a tablet 1799 mm thick).  Named by the largest of :data:`_HEIGHT_BY` the
    design gives (``given``: the ``[tablet]`` table's numbers), else ``where`` with the height."""
    lo, hi = tablet.bounds()
    height = float(hi[2] - lo[2])
    if height <= tol.max_length * (1.0 + 1e-9):  # (the bounds' rounding aside, as _check_size)
        return
    allowed = (f"must keep the tablet's height at most {tol.max_length:g} mm (size limit, Tolerances.max_length, "
               "as a diameter or length")
    names = [k for k in _HEIGHT_BY if k in given]
    if names:
        k = max(names, key=lambda n: abs(float(given[n])))
        raise DesignError(f"tablet.{k}", given[k], f"{allowed}; the tablet is {height:.6g} mm tall)", "mm")
    raise DesignError(where, f"a tablet {height:.9g} mm tall", allowed + ")")


def _check_plan(tablet: Tablet, where: str, tol: Tolerances = DEFAULT) -> None:
    """Refuse a free-form or custom-outline tablet whose plan leaves ``±tol.max_length`` or is longer or wider
    than ``tol.max_length`` along x or y, the size limit a family's diameter or length keeps (``where``: the
    design's patches or outline).  Its numbers each lie within the limit, but not what they make: a circle
    of radius 1000 mm had built a tablet 2000 mm across (2001 mm for a free form, whose surface bulges past
    its curves), and an arc of radius 400 mm about (900, 0) reached x = 1300 mm."""
    lo, hi = tablet.bounds()
    reach = float(max(abs(lo[0]), abs(lo[1]), abs(hi[0]), abs(hi[1])))
    length, width = float(hi[0] - lo[0]), float(hi[1] - lo[1])
    limit = tol.max_length * (1.0 + 1e-9)  # (the bounds' rounding aside, as _check_size)
    if not (reach <= limit and length <= limit and width <= limit):
        raise DesignError(where, f"a plan {length:.9g} x {width:.9g} mm reaching {reach:.9g} mm",
                          f"must keep the tablet's plan within ±{tol.max_length:g} mm and its length and width "
                          f"(along x and y) at most {tol.max_length:g} mm (size limit, Tolerances.max_length, "
                          "as a family's diameter or length)")


_CUSTOM_KEYS = {"outline", "segments", "band", "cup_depth", "land", "cup_width", "central_radius", "edge_radius"}


def _as_toml(value: Any, _open: frozenset = frozenset()) -> Any:
    """A copy of a design's data as TOML would give it: numpy arrays as (nested) lists, numpy scalars
    as Python ones, Decimals and Fractions as floats and tuples as lists (a Python caller's outline may be an
    (n, 2) array or pairs)."""
    if isinstance(value, (dict, list, tuple)):
        if id(value) in _open:  # TOML has no cycles
            raise DesignError("design", type(value).__name__, "must not contain itself")
        inner = _open | {id(value)}
        if isinstance(value, dict):
            return {k: _as_toml(v, inner) for k, v in value.items()}
        return [_as_toml(v, inner) for v in value]
    if type(value).__module__ == "numpy" and hasattr(value, "tolist"):  # an array or a numpy scalar
        plain = value.tolist()
        if type(plain).__module__ != "numpy":
            return _as_toml(plain, _open)
        # no Python type holds it (np.longdouble): the float it rounds to, else as given
        return float(plain) if isinstance(plain, numbers.Real) else copy.deepcopy(plain)
    if (isinstance(value, numbers.Rational) and not isinstance(value, int)) or \
            (isinstance(value, decimal.Decimal) and value.is_finite()):
        # a Decimal or a Fraction: TOML's float (the design had kept it and to_toml refused it); one no float
        # holds (Decimal("1e400"), Fraction(10**400)) is kept as given, for its refusal to quote it
        try:
            x = float(value)
        except OverflowError:
            return copy.deepcopy(value)
        return x if math.isfinite(x) else copy.deepcopy(value)
    return copy.deepcopy(value)


def _custom_outline(tab: dict, name: str) -> Tablet:
    """Any closed plan outline with a cup swept over it (:func:`tabletcad.families.outline_tablet`).

    ``outline = [[x, y], ...]`` (points, mm) or ``segments = [["line", [x0, y0], [x1, y1]],
    ["arc", [cx, cy], r, theta0, sweep], ...]`` (angles in rad), plus ``band``,
    ``cup_depth``, ``land``, ``cup_width``, ``central_radius``, ``edge_radius`` (mm).
    """
    from tabletcad.families import outline_tablet

    _check_keys("tablet", tab, _CUSTOM_KEYS)
    if ("outline" in tab) == ("segments" in tab):
        raise DesignError("tablet.outline", MISSING if "outline" not in tab else "both",
                          "give either outline (points) or segments (lines and arcs)")
    for k in ("band", "cup_depth"):
        if k not in tab:
            raise DesignError(f"tablet.{k}", MISSING, "a custom_outline design needs outline or segments, band and cup_depth "
                              "(optional: land, cup_width, central_radius, edge_radius)")
    key = "outline" if "outline" in tab else "segments"
    shape = tab[key]
    if key == "outline" and not (isinstance(shape, list) and all(isinstance(q, list) and len(q) == 2 for q in shape)):
        raise DesignError("tablet.outline", shape, "must be a list of [x, y] points in mm")
    if key == "segments" and not (isinstance(shape, list) and all(isinstance(q, list) and q and isinstance(q[0], str) for q in shape)):
        raise DesignError("tablet.segments", shape, 'must be a list of ["line", [x0, y0], [x1, y1]] or ["arc", [cx, cy], r, theta0, sweep] items')
    _lengths(f"tablet.{key}", shape, kinds=key == "segments")
    if key == "segments":
        shape = [tuple(item) for item in shape]
    kw = {k: _number(f"tablet.{k}", v, "mm", least=False) for k, v in tab.items() if k not in ("outline", "segments")}
    try:
        return outline_tablet(shape, name=name, **kw)
    except DesignError as exc:  # the constructor names "outline[...]", "cup_depth": the design's keys are tablet.<key>
        if exc.parameter == "outline" or exc.parameter.startswith(("outline[", "outline.")):
            raise exc.renamed(f"tablet.{key}{exc.parameter[len('outline'):]}") from None
        if exc.parameter in _CUSTOM_KEYS:
            raise exc.renamed(f"tablet.{exc.parameter}") from None
        raise


def _free_form(patches: Any, name: str, a) -> Tablet:
    if isinstance(patches, dict):  # [patch] written for [[patch]]: a table, not the list of them
        raise DesignError("patch", patches, "must be an array of tables, [[patch]] (double brackets), one for each patch "
                          "with its 4 curves; [patch] is a single table")
    if not isinstance(patches, list) or not patches:
        raise DesignError("patch", MISSING if patches is None else patches,
                          "a free_form design needs at least one [[patch]] with 4 curves")
    out = []
    prev: Curve | None = None
    for j, p in enumerate(patches):
        where = f"patch[{j}]"
        if not isinstance(p, dict):
            raise DesignError(where, p, "must be a table")
        _check_keys(where, p, {"curves", "form", "u_nodes", "a", "modes"})
        curves = p.get("curves")
        if not isinstance(curves, list) or len(curves) != 4:
            raise DesignError(f"{where}.curves", curves if not isinstance(curves, list) else len(curves), "must be a list of 4 curves")
        cs = [_curve(c, f"{where}.curves[{k}]", prev) for k, c in enumerate(curves)]
        kw: dict[str, Any] = dict(a=p.get("a", a), name=f"{name}[{j}]")
        if "form" in p:
            kw["form"] = p["form"]
        if "u_nodes" in p:
            un = p["u_nodes"]
            if not (isinstance(un, list) and len(un) == 4):
                raise DesignError(f"{where}.u_nodes", un, "must be [0, u1, u2, 1] with 0 < u1 < u2 < 1")
            kw["u_nodes"] = tuple(_number(f"{where}.u_nodes", x) for x in un)
        if "modes" in p:
            m = p["modes"]
            if isinstance(m, bool) or not isinstance(m, int):
                raise DesignError(f"{where}.modes", m, "must be an integer from 0 to 512")
            kw["modes"] = m
        if kw["a"] != "auto":
            kw["a"] = _number(f"{where}.a", kw["a"])
        try:
            out.append(PDEPatch(tuple(cs), **kw))
        except DesignError as exc:  # "patch.NAME.smoothing.parameter.a" -> "patch[j].a"
            last = exc.parameter.rsplit(".", 1)[-1]
            key = last if last in ("a", "modes", "u_nodes", "form", "curves") else exc.parameter
            raise exc.renamed(one_token(f"{where}.{key}")) from None
        prev = cs[3]
    return _check_closed(_check_joined(Tablet(tuple(out), name=name, family="free_form")))


def _check_joined(tablet: Tablet) -> Tablet:
    """``tablet`` if each patch of its free-form chain starts where the previous one ends (the report's
    seam gaps, :meth:`Tablet.seams`, within ``seam_gap`` mm), else :class:`DesignError` for the patch's
    first curve: a gap is no solid."""
    tol = tablet.tol.seam_gap
    for seam in tablet.seams():
        i, j = seam["patches"]
        if not seam["max_gap_mm"] <= tol:
            raise DesignError(f"patch[{j}].curves[0]", f"a gap of {seam['max_gap_mm']:.4g} mm to patch[{i}]'s end",
                              f"must start where patch[{i}] ends (within {tol:g} mm; \"previous\" repeats its "
                              "last curve)")
    return tablet


def _check_closed(tablet: Tablet) -> Tablet:
    """``tablet`` if its free-form chain encloses a volume (closed by the solid map's end faces where
    it does not end at a point) of at least ``min_length**3``, else :class:`DesignError` (one flat
    patch, a disc, had reached the report's division by its zero volume)."""
    volume = tablet.properties()["volume_mm3"]
    if not volume >= tablet.tol.min_length ** 3:
        raise DesignError("patch", f"an enclosed volume of {volume:.4g} mm^3",
                          f"the patches must enclose a solid (volume >= {tablet.tol.min_length ** 3:g} mm^3)")
    return tablet


def _pair(where: str, val: Any) -> tuple[float, float]:
    if not (isinstance(val, list) and len(val) == 2):
        raise DesignError(where, val, "must be a pair [lo, hi]")
    return (_number(f"{where}[0]", val[0]), _number(f"{where}[1]", val[1]))  # (each named by its place)


def _trim(tablet: Tablet, t: dict) -> Tablet:
    _check_keys("trim", t, {"u", "v", "w"})
    kw = {k: _pair(f"trim.{k}", t[k]) for k in t}
    return replace(tablet, trim=Trim(**{**dict(u=tablet.trim.u, v=tablet.trim.v, w=tablet.trim.w), **kw}))


def _factor(where: str, value: Any, tol: Tolerances = DEFAULT) -> float:
    """A reshaping factor: > 0 and at most ``tol.max_length`` (a larger one takes any 1 mm
    dimension past the size limit; the reshaped tablet's size is checked afterwards too)."""
    x = _number(where, value)
    if not 0.0 < x <= tol.max_length:
        raise DesignError(where, value, f"must be > 0 and <= {tol.max_length:g}")
    return x


def _reshape(tablet: Tablet, r: dict) -> Tablet:
    from tabletcad.families import reshape

    _check_keys("reshape", r, {"spine", "radius", "patches"})
    if "patches" in r:
        idx = r["patches"]
        if not (isinstance(idx, list) and all(isinstance(i, int) and not isinstance(i, bool) for i in idx)):
            raise DesignError("reshape.patches", idx, "must be a list of patch indices (integers)")
        tablet = reshape.select_patches(tablet, idx)
    if "spine" in r:
        if not isinstance(r["spine"], list):
            raise DesignError("reshape.spine", r["spine"], "must be a list with one factor per patch")
        factors = [_factor(f"reshape.spine[{j}]", f) for j, f in enumerate(r["spine"])]
        try:
            tablet = reshape.scale_heights(tablet, factors)
        except DesignError as exc:  # the function's own name for it: the file's key
            raise DesignError("reshape.spine", r["spine"], exc.allowed) from None
    if "radius" in r:
        tablet = reshape.scale_radius(tablet, _factor("reshape.radius", r["radius"]))
    return tablet


def design_to_toml(family: str, params: dict[str, float], name: str | None = None, extra: str = "") -> str:
    """TOML text of a family design (used by the optimiser to write its optimum); ``extra`` is appended."""
    tablet = {**({"name": name} if name else {}), "family": family, **params}
    return toml_text({"tablet": tablet}) + extra


_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def _toml_key(key: Any) -> str:
    if not isinstance(key, str):
        raise DesignError("design", repr(key), "keys must be text")
    return key if _BARE_KEY.fullmatch(key) else _toml_string(key)


def _toml_string(text: str) -> str:
    if any(0xD800 <= ord(ch) <= 0xDFFF for ch in text):
        raise DesignError("design", text, "must be text TOML can hold (no lone surrogates)")
    # TOML basic strings take JSON's escapes; DEL is a control character to TOML, not to JSON
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):  # also numpy.float64, whose repr is "np.float64(...)"
        value = float(value)
        return repr(value) if math.isfinite(value) else ("nan" if math.isnan(value) else "inf" if value > 0 else "-inf")
    if isinstance(value, str):
        return _toml_string(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{_toml_key(k)} = {_toml_value(v)}" for k, v in value.items()) + " }" if value else "{}"
    if isinstance(value, np.generic):
        return _toml_value(value.item())
    if isinstance(value, datetime.date) or (isinstance(value, datetime.time) and value.tzinfo is None):
        # TOML's own dates and times, as read (a drawing's unquoted date = 2026-12-01), written back alike
        return value.isoformat()
    raise DesignError("design", repr(value), "must hold numbers, text, booleans, lists, tables and dates only")


def _toml_table(lines: list[str], path: str, table: dict) -> None:
    """Append ``table`` at ``path``: its keys (lists holding lists or tables one item per line),
    then its non-empty sub-tables as ``[path.key]`` sections."""
    subs = [(k, v) for k, v in table.items() if isinstance(v, dict) and v]
    for k, v in table.items():
        if isinstance(v, dict) and v:
            continue
        if isinstance(v, list) and len(v) > 1 and any(isinstance(x, (dict, list)) for x in v):
            lines.append(f"{_toml_key(k)} = [")  # curves, points, segments
            lines += [f"  {_toml_value(x)}," for x in v]
            lines.append("]")
        else:
            lines.append(f"{_toml_key(k)} = {_toml_value(v)}")
    for k, v in subs:
        sub = f"{path}.{_toml_key(k)}" if path else _toml_key(k)
        lines += ["", f"[{sub}]"]
        _toml_table(lines, sub, v)


def _is_table_array(v: Any) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


def toml_text(data: dict[str, Any], comment: str = "") -> str:
    """TOML text of a design dictionary: ``tomllib.loads(toml_text(d)) == d``.

    Top-level tables become ``[table]`` sections (their sub-tables ``[table.key]``), top-level
    lists of tables ``[[table]]`` (``[[patch]]``); lists holding lists or tables are written one
    item per line; ``comment`` lines come first as ``#`` comments.
    """
    comment = "".join(ch if ch == "\t" or (ord(ch) >= 0x20 and ord(ch) != 0x7F) or ch == "\n" else " " for ch in comment)
    lines = [f"# {c}" if c else "#" for c in comment.strip().splitlines()]
    top = [k for k, v in data.items() if not (isinstance(v, dict) and v) and not _is_table_array(v)]
    _toml_table(lines, "", {k: data[k] for k in top})
    for k, v in data.items():
        if k in top:
            continue
        if isinstance(v, dict):
            lines += ["", f"[{_toml_key(k)}]"]
            _toml_table(lines, _toml_key(k), v)
        else:
            for item in v:
                lines += ["", f"[[{_toml_key(k)}]]"]
                _toml_table(lines, _toml_key(k), item)
    return "\n".join(lines).lstrip("\n") + "\n"
