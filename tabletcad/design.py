"""Design files: tablets described in TOML.

A design names a family and its dimensions (mm)::

    [tablet]
    family = "flat_faced_round"
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

import math
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

from tabletcad.curves import Circle, Curve, Ellipse, PointCurve, RoundedRectangle, Stadium
from tabletcad.errors import DesignError, check_finite
from tabletcad.patch import PDEPatch
from tabletcad.shapes import FAMILIES
from tabletcad.tablet import Tablet, Trim

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

__all__ = ["load_design", "design_from_dict", "design_to_toml", "TOP_LEVEL_KEYS"]

TOP_LEVEL_KEYS = ("tablet", "patch", "trim", "reshape", "tooling", "report")
_CURVE_KEYS = {
    "circle": {"radius"},
    "ellipse": {"rx", "ry"},
    "stadium": {"length", "width"},
    "rounded_rectangle": {"length", "width", "corner_radius"},
    "points": {"points"},
}


def load_design(path: str | Path) -> Tablet:
    """Read a TOML design file and build its tablet."""
    path = Path(path)
    if not path.is_file():
        raise DesignError("design file", str(path), "must be an existing TOML file")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise DesignError("design file", path.name, f"must be valid TOML ({exc})") from None
    return design_from_dict(data, default_name=path.stem)


def _check_keys(where: str, table: dict, allowed: set[str]) -> None:
    for k in table:
        if k not in allowed:
            raise DesignError(f"{where} key {k!r}", table[k], f"allowed keys are {', '.join(sorted(allowed))}")


def _curve(spec: Any, where: str, previous: Curve | None) -> Curve:
    if spec == "previous":
        if previous is None:
            raise DesignError(where, "previous", "the first patch has no previous curve")
        return previous
    if not isinstance(spec, dict) or "type" not in spec:
        raise DesignError(where, spec, "must be a table with a 'type' or the string 'previous'")
    kind = spec["type"]
    if kind not in _CURVE_KEYS:
        raise DesignError(f"{where} type", kind, f"must be one of {', '.join(_CURVE_KEYS)}")
    _check_keys(where, spec, _CURVE_KEYS[kind] | {"type", "z", "center"})
    for k in _CURVE_KEYS[kind]:
        if k not in spec:
            raise DesignError(f"{where} {k}", "missing", f"a {kind} curve needs {', '.join(sorted(_CURVE_KEYS[kind]))}")
    if "center" in spec and "z" in spec:
        raise DesignError(f"{where} z", spec["z"], "give either z or center, not both")
    center = spec.get("center", (0.0, 0.0, spec.get("z", 0.0)))
    if not (isinstance(center, (list, tuple)) and len(center) == 3):
        raise DesignError(f"{where} center", center, "must be [x, y, z] in mm")
    center = tuple(check_finite(f"{where} center", c, "mm") for c in center)
    num = {k: check_finite(f"{where} {k}", spec[k], "mm") for k in _CURVE_KEYS[kind] if k != "points"}
    try:
        if kind == "circle":
            c: Curve = Circle(num["radius"], center)
            return c
        if kind == "ellipse":
            return Ellipse(num["rx"], num["ry"], center)
        if kind == "points":
            return PointCurve(spec["points"], z=center[2]).moved((center[0], center[1], 0.0))
        if kind == "stadium":
            base = Stadium(num["length"], num["width"])
        else:
            base = RoundedRectangle(num["length"], num["width"], num["corner_radius"])
        return base.moved(center)
    except DesignError as exc:
        raise DesignError(f"{where} {exc.parameter}", exc.value, exc.allowed, exc.unit) from None


def design_from_dict(data: dict, default_name: str = "tablet") -> Tablet:
    """Build a tablet from a parsed design (the TOML structure above)."""
    from tabletcad.shapes import _load_plugins

    _load_plugins()
    _check_keys("top-level", data, set(TOP_LEVEL_KEYS))
    if "tablet" not in data or not isinstance(data["tablet"], dict):
        raise DesignError("[tablet]", "missing", "a design needs a [tablet] table with a family")
    tab = dict(data["tablet"])
    family = tab.pop("family", None)
    name = tab.pop("name", None) or default_name
    if not isinstance(name, str) or not name.strip() or any(ch in name for ch in '/\\"\n'):
        raise DesignError("[tablet] name", name, "must be a plain non-empty name")
    a = tab.pop("a", None)
    if a is not None and a != "auto":
        a = check_finite("[tablet] a", a)
    if family is None:
        raise DesignError("[tablet] family", "missing", f"must be one of {', '.join(FAMILIES)}, custom_outline or free_form")
    if family == "free_form":
        _check_keys("[tablet]", tab, set())
        tablet = _free_form(data.get("patch"), name, 1.0 if a is None else a)
    elif family == "custom_outline":
        tablet = _custom_outline(tab, name)
    else:
        if family not in FAMILIES:
            raise DesignError("[tablet] family", family, f"must be one of {', '.join(FAMILIES)}, custom_outline or free_form")
        if "patch" in data:
            raise DesignError("[[patch]]", "given", f"patches are only read for family free_form, not {family!r}")
        fam = FAMILIES[family]
        kw = {}
        for k, v in tab.items():
            if k not in fam.params:
                raise DesignError(f"[tablet] key {k!r}", v, f"family {family!r} takes {', '.join(fam.params)}")
            kw[k] = check_finite(f"[tablet] {k}", v, fam.params[k])
        if a is not None:
            kw["a"] = a
        tablet = fam.build(**kw)
        tablet = replace(tablet, name=name)
    if "reshape" in data:
        tablet = _reshape(tablet, data["reshape"])
    if "trim" in data:
        tablet = _trim(tablet, data["trim"])
    extras = {k: data[k] for k in ("report", "tooling") if k in data}
    if extras:
        for k, v in extras.items():
            if not isinstance(v, dict):
                raise DesignError(f"[{k}]", v, "must be a table")
        tablet = replace(tablet, extras={**tablet.extras, **extras})
    return tablet


_CUSTOM_KEYS = {"outline", "segments", "band", "cup_depth", "land", "cup_width", "central_radius", "edge_radius"}


def _custom_outline(tab: dict, name: str) -> Tablet:
    """Any closed plan outline with a cup swept over it (:func:`tabletcad.families.outline_tablet`).

    ``outline = [[x, y], ...]`` (points, mm) or ``segments = [["line", [x0, y0], [x1, y1]],
    ["arc", [cx, cy], r, theta0, sweep], ...]`` (angles in rad), plus ``band``,
    ``cup_depth``, ``land``, ``cup_width``, ``central_radius``, ``edge_radius`` (mm).
    """
    from tabletcad.families import outline_tablet

    _check_keys("[tablet]", tab, _CUSTOM_KEYS)
    if ("outline" in tab) == ("segments" in tab):
        raise DesignError("[tablet] outline", "missing" if "outline" not in tab else "both",
                          "give either outline (points) or segments (lines and arcs)")
    shape = tab["outline"] if "outline" in tab else [tuple(item) for item in tab["segments"]]
    kw = {k: check_finite(f"[tablet] {k}", v, "mm") for k, v in tab.items() if k not in ("outline", "segments")}
    return outline_tablet(shape, name=name, **kw)


def _free_form(patches: Any, name: str, a) -> Tablet:
    if not isinstance(patches, list) or not patches:
        raise DesignError("[[patch]]", "missing", "a free_form design needs at least one [[patch]] with 4 curves")
    out = []
    prev: Curve | None = None
    for j, p in enumerate(patches):
        where = f"patch {j}"
        if not isinstance(p, dict):
            raise DesignError(where, p, "must be a table")
        _check_keys(f"[[patch]] {j}", p, {"curves", "form", "u_nodes", "a", "modes"})
        curves = p.get("curves")
        if not isinstance(curves, list) or len(curves) != 4:
            raise DesignError(f"{where} curves", curves if not isinstance(curves, list) else len(curves), "must be a list of 4 curves")
        cs = [_curve(c, f"{where} curve {k}", prev) for k, c in enumerate(curves)]
        kw: dict[str, Any] = dict(a=p.get("a", a), name=f"{name}[{j}]")
        if "form" in p:
            kw["form"] = p["form"]
        if "u_nodes" in p:
            kw["u_nodes"] = tuple(p["u_nodes"])
        if "modes" in p:
            kw["modes"] = p["modes"]
        if kw["a"] != "auto":
            kw["a"] = check_finite(f"{where} a", kw["a"])
        out.append(PDEPatch(tuple(cs), **kw))
        prev = cs[3]
    return Tablet(tuple(out), name=name, family="free_form")


def _pair(where: str, val: Any) -> tuple[float, float]:
    if not (isinstance(val, list) and len(val) == 2):
        raise DesignError(where, val, "must be a pair [lo, hi]")
    return (check_finite(where, val[0]), check_finite(where, val[1]))


def _trim(tablet: Tablet, t: Any) -> Tablet:
    if not isinstance(t, dict):
        raise DesignError("[trim]", t, "must be a table with u, v and/or w pairs")
    _check_keys("[trim]", t, {"u", "v", "w"})
    kw = {k: _pair(f"[trim] {k}", t[k]) for k in t}
    return replace(tablet, trim=Trim(**{**dict(u=tablet.trim.u, v=tablet.trim.v, w=tablet.trim.w), **kw}))


def _reshape(tablet: Tablet, r: Any) -> Tablet:
    from tabletcad import reshape

    if not isinstance(r, dict):
        raise DesignError("[reshape]", r, "must be a table with spine and/or radius")
    _check_keys("[reshape]", r, {"spine", "radius", "patches"})
    if "patches" in r:
        tablet = reshape.select_patches(tablet, r["patches"])
    if "spine" in r:
        if not isinstance(r["spine"], list):
            raise DesignError("[reshape] spine", r["spine"], "must be a list with one factor per patch")
        tablet = reshape.scale_heights(tablet, r["spine"])
    if "radius" in r:
        tablet = reshape.scale_radius(tablet, r["radius"])
    return tablet


def design_to_toml(family: str, params: dict[str, float], name: str | None = None, extra: str = "") -> str:
    """TOML text of a family design (used by the optimiser to write its optimum)."""
    lines = ["[tablet]"]
    if name:
        lines.append(f'name = "{name}"')
    lines.append(f'family = "{family}"')
    for k, v in params.items():
        if isinstance(v, str):
            lines.append(f'{k} = "{v}"')
        else:
            lines.append(f"{k} = {float(v)!r}" if math.isfinite(float(v)) else f"{k} = nan")
    return "\n".join(lines) + "\n" + extra
