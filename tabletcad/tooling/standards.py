"""B and D punch and die body dimensions, TSM and EU, from ``tabletcad/data/tooling_standards.toml``.

Every number in the data file carries its public source; a dimension with no
citable public value is not in the file and must be given in the design's
``[tooling.punch]`` table (:func:`resolve_body` says which key is missing).
This module is plain Python (no OCP): the spec parser uses it to check a
design before any geometry is built.

Punch body, measured along the punch axis from the tip edge (mm)::

    tip edge ─ tip (tip_length_mm: straight part tip_straight_mm, then relieved by tip_relief_mm)
             ─ barrel (barrel_diameter_mm; length = overall − tip − neck − head; optional key)
             ─ neck (neck_diameter_mm, neck_length_mm)
             ─ head: underside cone at inside_head_angle_deg to the plane normal to the axis,
               cylindrical rim head_rim_mm, then the top: a cone at head_top_angle_deg (TSM,
               "angled") or a sphere of dome_radius_mm (EU, "domed") down to the head flat
               (head_flat_diameter_mm) ─ head flat at overall_length_mm from the tip edge.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

from tabletcad.errors import MISSING, DesignError, check_positive, check_range

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

__all__ = ["STANDARDS_FILE", "PunchBody", "load_standards", "standard_entry", "resolve_body", "BODY_KEYS"]

STANDARDS_FILE = Path(__file__).resolve().parent.parent / "data" / "tooling_standards.toml"

#: keys of ``[tooling.punch]`` (lengths mm, angles degrees)
BODY_KEYS = (
    "overall_length_mm", "barrel_diameter_mm", "head_diameter_mm", "head_flat_diameter_mm", "head_rim_mm",
    "inside_head_angle_deg", "head_top_angle_deg", "dome_radius_mm", "neck_diameter_mm", "neck_length_mm",
    "tip_straight_mm", "tip_relief_mm", "key", "key_width_mm", "key_length_mm", "key_height_mm", "key_offset_mm",
    "key_angle_deg", "head",
)
_KEY_KEYS = ("key_width_mm", "key_length_mm", "key_height_mm", "key_offset_mm")


@lru_cache(maxsize=1)
def load_standards() -> dict:
    """The parsed data file (``sources`` and ``TSM``/``EU`` → ``B``/``D`` entries)."""
    return tomllib.loads(STANDARDS_FILE.read_text(encoding="utf-8"))


def standard_entry(standard: str, kind: str) -> dict:
    """``{key: {"value", "source", ...}}`` and ``head`` for ``standard`` ("TSM"/"EU") and ``kind`` ("B"/"D")."""
    data = load_standards()
    if standard not in ("TSM", "EU"):
        raise DesignError("[tooling] standard", standard, "must be one of 'TSM', 'EU', 'custom'")
    if kind not in data[standard]:
        raise DesignError("[tooling] type", kind, f"must be one of {', '.join(repr(k) for k in data[standard])}")
    return data[standard][kind]


@dataclass(frozen=True)
class PunchBody:
    """The resolved punch body (mm, degrees); ``sources`` maps each key taken from the data file to
    its source keys, every other dimension was given by the user."""

    standard: str
    kind: str | None
    head: str
    overall_length_mm: float
    barrel_diameter_mm: float
    head_diameter_mm: float
    head_flat_diameter_mm: float
    head_rim_mm: float
    inside_head_angle_deg: float
    head_top_angle_deg: float | None
    dome_radius_mm: float | None
    neck_diameter_mm: float
    neck_length_mm: float
    tip_straight_mm: float
    tip_relief_mm: float
    key: bool = False
    key_width_mm: float = 0.0
    key_length_mm: float = 0.0
    key_height_mm: float = 0.0
    key_offset_mm: float = 0.0
    key_angle_deg: float = 0.0
    max_round_tablet_mm: float | None = None
    max_shaped_tablet_mm: float | None = None
    die_outer_diameter_mm: float | None = None
    sources: dict = field(default_factory=dict)
    #: the standard's dimensions the user changed: ``{key: {"given": x, "standard": y}}`` (such a set is
    #: the standard's modified, and its drawing and report say so)
    modified: dict = field(default_factory=dict)

    @property
    def head_under_mm(self) -> float:
        """Axial height of the head's underside cone."""
        return 0.5 * (self.head_diameter_mm - self.neck_diameter_mm) * math.tan(math.radians(self.inside_head_angle_deg))

    @property
    def head_top_mm(self) -> float:
        """Axial height of the head's top (cone or spherical zone) from the rim to the head flat."""
        rh, rf = 0.5 * self.head_diameter_mm, 0.5 * self.head_flat_diameter_mm
        if self.head == "angled":
            return (rh - rf) * math.tan(math.radians(self.head_top_angle_deg))
        rd = self.dome_radius_mm
        return math.sqrt(rd * rd - rf * rf) - math.sqrt(rd * rd - rh * rh)

    @property
    def head_height_mm(self) -> float:
        return self.head_under_mm + self.head_rim_mm + self.head_top_mm

    def barrel_length_mm(self, tip_length: float) -> float:
        """Barrel length for a tip ``tip_length`` long (overall − tip − neck − head)."""
        return self.overall_length_mm - tip_length - self.neck_length_mm - self.head_height_mm


def _num(where: str, t: dict, key: str, entry: dict, sources: dict, lo: float | None = None, hi: float | None = None,
         unit: str = "mm", *, zero_ok: bool = False) -> float:
    """``t[key]`` (the user's), else the standard's value (its source recorded), else a DesignError."""
    if key in t:
        v = t[key]
    elif key in entry:
        v = entry[key]["value"]
        sources[key] = list(entry[key]["source"])
    else:
        raise DesignError(f"{where} {key}", MISSING, "required: no citable public value is bundled for it "
                          "(tabletcad/data/tooling_standards.toml); give the toolmaker's figure", unit)
    if lo is None and hi is None and not zero_ok:
        return check_positive(f"{where} {key}", v, unit)
    return check_range(f"{where} {key}", v, 0.0 if lo is None else lo, hi, unit, lo_open=not zero_ok, hi_open=True)


#: the head top's dimension of each head style, which the other style has no use for
_HEAD_TOP_KEYS = {"angled": "head_top_angle_deg", "domed": "dome_radius_mm"}


def _refuse_other_head(where: str, table: dict, head: str, standard: str) -> None:
    """A :class:`DesignError` naming a head-top key of the other head style (a trial: ``dome_radius_mm = 40``
    on a TSM angled head, ``head_top_angle_deg`` on an EU domed one, were ignored in silence)."""
    for style, key in _HEAD_TOP_KEYS.items():
        if style != head and key in table:
            raise DesignError(f"{where} {key}", table[key], f"not used by the {standard} punches' {head} head, which "
                              f"takes {_HEAD_TOP_KEYS[head]}: remove it, or set head = '{style}'",
                              "deg" if key.endswith("_deg") else "mm")


def resolve_body(standard: str, kind: str | None, table: Any, tip_length: float, lower_tip_length: float) -> PunchBody:
    """Check ``[tooling.punch]`` against the standard and return the :class:`PunchBody` (raises DesignError).

    ``tip_length``/``lower_tip_length``: the upper and lower punch tip lengths (mm), checked against the
    room the overall length leaves (a tip longer than the punch allows is an error)."""
    w = "[tooling.punch]"
    t = {} if table is None else table
    if not isinstance(t, dict):
        raise DesignError(w, t, "must be a table")
    for k in t:
        if k not in BODY_KEYS:
            raise DesignError(f"{w} key {k!r}", t[k], f"allowed keys are {', '.join(BODY_KEYS)}")
    entry: dict = {} if standard == "custom" else standard_entry(standard, kind)
    src: dict = {}
    head = t.get("head", entry.get("head"))
    if head not in ("angled", "domed"):
        raise DesignError(f"{w} head", head if head is not None else MISSING,
                          "must be 'angled' (TSM) or 'domed' (EU); required with standard = 'custom'")
    _refuse_other_head(w, t, head, standard)
    L = _num(w, t, "overall_length_mm", entry, src)
    Db = _num(w, t, "barrel_diameter_mm", entry, src)
    Dh = _num(w, t, "head_diameter_mm", entry, src)
    Df = _num(w, t, "head_flat_diameter_mm", entry, src)
    rim = _num(w, t, "head_rim_mm", entry, src, zero_ok=True)
    a_in = _num(w, t, "inside_head_angle_deg", entry, src, 0.0, 90.0, "deg")
    a_top = _num(w, t, "head_top_angle_deg", entry, src, 0.0, 90.0, "deg") if head == "angled" else None
    Rd = _num(w, t, "dome_radius_mm", entry, src) if head == "domed" else None
    Dn = _num(w, t, "neck_diameter_mm", entry, src)
    Ln = _num(w, t, "neck_length_mm", entry, src)
    straight = _num(w, t, "tip_straight_mm", entry, src)
    relief = _num(w, t, "tip_relief_mm", entry, src, zero_ok=True)
    if Dn >= Db:
        raise DesignError(f"{w} neck_diameter_mm", Dn, f"must be < barrel_diameter_mm {Db:.4g} mm", "mm")
    if Dn < 0.5 * Db:  # (a 0.5 mm neck on a 19 mm barrel had been built)
        raise DesignError(f"{w} neck_diameter_mm", Dn, f"must be >= half the barrel diameter, {0.5 * Db:.4g} mm: the "
                          "neck carries the punch's pull-down and ejection loads", "mm")
    if Dh <= Db:  # (a 15 mm head on a 19 mm barrel had been built)
        raise DesignError(f"{w} head_diameter_mm", Dh, f"must be > barrel_diameter_mm {Db:.4g} mm: the head runs on the "
                          "press's cams and pressure rolls outside the barrel's guide", "mm")
    if Dh <= Dn:
        raise DesignError(f"{w} head_diameter_mm", Dh, f"must be > neck_diameter_mm {Dn:.4g} mm", "mm")
    if Df >= Dh:
        raise DesignError(f"{w} head_flat_diameter_mm", Df, f"must be < head_diameter_mm {Dh:.4g} mm", "mm")
    if Rd is not None and Rd <= 0.5 * Dh:
        raise DesignError(f"{w} dome_radius_mm", Rd, f"must be > half the head diameter, {0.5 * Dh:.4g} mm", "mm")
    key = t.get("key", False)
    if not isinstance(key, bool):
        raise DesignError(f"{w} key", key, "must be true or false")
    kv = {k: 0.0 for k in _KEY_KEYS}
    if key:
        for k in _KEY_KEYS:
            kv[k] = _num(w, t, k, {}, src, zero_ok=k == "key_offset_mm")
    if key and not kv["key_width_mm"] < Db:  # a key sits in a slot of the barrel
        raise DesignError(f"{w} key_width_mm", kv["key_width_mm"], f"must be < barrel_diameter_mm {Db:.4g} mm", "mm")
    if key and not kv["key_height_mm"] < 0.5 * Db:  # and stands out of it by less than the barrel's radius
        raise DesignError(f"{w} key_height_mm", kv["key_height_mm"], f"must be < half barrel_diameter_mm, "
                          f"{0.5 * Db:.4g} mm (the key stands out of a slot in the barrel)", "mm")
    key_angle = float(check_range(f"{w} key_angle_deg", t.get("key_angle_deg", 0.0), -360.0, 360.0, "deg"))
    ext = {k: entry[k]["value"] for k in ("max_round_tablet_mm", "max_shaped_tablet_mm", "die_outer_diameter_mm")
           if k in entry}
    for k in ext:
        src[k] = list(entry[k]["source"])
    modified = {k: {"given": float(t[k]), "standard": float(entry[k]["value"])} for k in t
                if isinstance(entry.get(k), dict) and "value" in entry[k] and not isinstance(t[k], bool)
                and float(t[k]) != float(entry[k]["value"])}
    body = PunchBody(standard, kind, head, L, Db, Dh, Df, rim, a_in, a_top, Rd, Dn, Ln, straight, relief, key,
                     kv["key_width_mm"], kv["key_length_mm"], kv["key_height_mm"], kv["key_offset_mm"], key_angle,
                     ext.get("max_round_tablet_mm"), ext.get("max_shaped_tablet_mm"), ext.get("die_outer_diameter_mm"),
                     src, modified)
    parts = {"neck_length_mm": Ln, "inside_head_angle_deg": body.head_under_mm, "head_rim_mm": rim,
             ("head_top_angle_deg" if head == "angled" else "dome_radius_mm"): body.head_top_mm}
    if Ln + body.head_height_mm >= L:  # no barrel left: name the longest of neck and head's parts
        k = max(parts, key=parts.get)
        rest = L - (Ln + body.head_height_mm - parts[k])  # what the named part may take at most
        run = {"inside_head_angle_deg": 0.5 * (Dh - Dn), "head_top_angle_deg": 0.5 * (Dh - Df)}.get(k)
        bound = (f"must be < {math.degrees(math.atan(rest / run)):.4g} deg: " if run and rest > 0
                 else f"must be < {rest:.4g} mm: " if k in ("neck_length_mm", "head_rim_mm") and rest > 0 else "")
        raise DesignError(f"{w} {k}", t.get(k, entry.get(k, {}).get("value")),
                          f"{bound}leaves no barrel: the neck and head ({parts[k]:.4g} mm of it from {k}) take "
                          f"{Ln + body.head_height_mm:.4g} mm of the {L:.6g} mm punch",
                          "deg" if k.endswith("_deg") else "mm")
    for name, tl in (("tip_length_mm", tip_length), ("lower_tip_length_mm", lower_tip_length)):
        room = L - Ln - body.head_height_mm
        if tl >= room:
            raise DesignError(f"[tooling] {name}", tl, f"must be < {room:.4g} mm: the punch is {L:.6g} mm long and "
                              f"its neck and head take {Ln + body.head_height_mm:.4g} mm", "mm")
        if straight > tl:
            raise DesignError(f"{w} tip_straight_mm", straight, f"must be <= the tip length {tl:.4g} mm", "mm")
        if key and kv["key_offset_mm"] + kv["key_length_mm"] > body.barrel_length_mm(tl):
            raise DesignError(f"{w} key_offset_mm", kv["key_offset_mm"],
                              f"the key must end on the barrel: offset + length <= {body.barrel_length_mm(tl):.4g} mm "
                              f"({name} {tl:.4g} mm)", "mm")
    return body
