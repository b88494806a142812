"""Units of press-data columns: the factor table and the header parser.

Press exports label their columns ``Upper Punch Force (kN)``, ``Force [daN]``,
``Time [ms]``, ``displacement_mm``...  :func:`header_unit` finds the unit in a
header and :func:`unit_factor` gives the factor to tabletcad's units (force N,
length mm, time s; for tables of tablets also pressure MPa and fractions).  The table is small and explicit on purpose: the mechanics
core must import with numpy and scipy alone (it runs inside FreeCAD's Python),
and these linear factors are all a press record and a table of tablets need
(README, "Libraries and why").

Power-of-ten factors (kN, daN, MN, mN, µm, cm, m, ms, µs) are stored as their
decimal exponent, so that :mod:`tabletcad.mechanics.pressdata` can convert a
printed value by shifting its exponent in the text: ``"0,003891"`` kN is read
as the correctly rounded double of 3.891 N, bit for bit the value read from
``"3.891"`` N.  The others (lbf, kgf, in, min, h) are multiplied after reading.
"""

from __future__ import annotations

import re

from tabletcad.errors import DesignError

__all__ = ["DIMENSIONS", "UNITS", "header_unit", "strip_unit", "unit_factor"]

#: Quantity each column role is measured in.
DIMENSIONS = {"force": "force", "displacement": "length", "thickness": "length", "time": "time"}

#: unit symbol -> (dimension, factor to N / mm / s, decimal exponent of the factor or None).
UNITS: dict[str, tuple[str, float, int | None]] = {
    "N": ("force", 1.0, 0),
    "mN": ("force", 1e-3, -3),
    "daN": ("force", 10.0, 1),
    "kN": ("force", 1e3, 3),
    "KN": ("force", 1e3, 3),
    "MN": ("force", 1e6, 6),
    "kgf": ("force", 9.80665, None),  # standard gravity, exact by definition
    "kp": ("force", 9.80665, None),
    "lbf": ("force", 4.4482216152605, None),  # 0.45359237 kg x 9.80665 m/s², exact
    "mm": ("length", 1.0, 0),
    "µm": ("length", 1e-3, -3),
    "um": ("length", 1e-3, -3),
    "cm": ("length", 10.0, 1),
    "m": ("length", 1e3, 3),
    "in": ("length", 25.4, None),  # exact by definition
    "inch": ("length", 25.4, None),
    "s": ("time", 1.0, 0),
    "sec": ("time", 1.0, 0),
    "ms": ("time", 1e-3, -3),
    "µs": ("time", 1e-6, -6),
    "us": ("time", 1e-6, -6),
    "min": ("time", 60.0, None),
    "h": ("time", 3600.0, None),
    # pressures and strengths (MPa = N/mm²) and fractions, for tables of tablets (kawakita, walker, profiles)
    "MPa": ("pressure", 1.0, 0),
    "N/mm²": ("pressure", 1.0, 0),
    "N/mm2": ("pressure", 1.0, 0),
    "kPa": ("pressure", 1e-3, -3),
    "Pa": ("pressure", 1e-6, -6),
    "GPa": ("pressure", 1e3, 3),
    "bar": ("pressure", 0.1, -1),
    "psi": ("pressure", 0.0068947572931683625, None),  # lbf/in², exact by definition
    "%": ("fraction", 0.01, -2),
}

_BRACKET = re.compile(r"[\(\[]\s*([^\)\]]*?)\s*[\)\]]\s*$")
_TRAILING = re.compile(r"([_\s])([A-Za-zµμ]+|%)\s*$")
#: words that are units only after an underscore (``time_h``), not after a space (``position in``)
_NOT_AFTER_SPACE = {"in", "m", "h", "s"}
#: what a bracket may hold that says "no unit" (``solid_fraction (-)``, ``Ratio [1]``)
_NO_UNIT = {"", "-", "–", "1", "dimensionless", "unitless", "fraction"}


def _normalise(symbol: str) -> str:
    # Greek small mu (U+03BC) and the micro sign (U+00B5) both occur in exports
    return symbol.strip().replace("\u03bc", "µ")


def header_unit(header: str) -> str | None:
    """The unit written in a column header, or ``None`` when it names none.

    A unit in round or square brackets at the end (``Force (kN)``,
    ``Time [ms]``) is returned whatever it is, so an unknown one can be
    refused; otherwise a trailing ``_unit`` or `` unit`` token is returned only
    when it is a known unit (``force_N``, ``displacement_mm``), so ordinary
    words are not mistaken for units.
    """
    m = _BRACKET.search(header)
    if m:
        unit = _normalise(m.group(1))
        return None if unit.lower() in _NO_UNIT else unit
    m = _trailing(header)
    if m is not None:
        return _normalise(m.group(2))
    _refuse_misplaced_unit(header)
    return None


#: a bracket anywhere in a header, and its words (a unit may stand inside a longer name)
_ANY_BRACKET = re.compile(r"[\(\[]\s*([^\)\]]*?)\s*[\)\]]")
_WORD = re.compile(r"[A-Za-zµμ%²]+(?:/[A-Za-z²]+)?")
#: unit symbols that are also words of column names (``position in``, ``max force``): never a unit inside a name
_ALSO_WORDS = {"in", "inch", "m", "h", "s", "sec", "min"}


def _refuse_misplaced_unit(header: str) -> None:
    """Refuse a header that states a unit where :func:`header_unit` does not read one (``Force/kN``,
    ``Force [kN] upper``): read as no unit, the column would take the default (N, mm) and a record in
    kN be read 1000 times too small."""
    found = [g for g in _ANY_BRACKET.findall(header) if _normalise(g).lower() not in _NO_UNIT]
    words = [w for part in re.split(r"[/\s_,;:|\-]+", header) for w in _WORD.findall(part)]
    found += [w for w in words if _normalise(w) in UNITS and _normalise(w) not in _ALSO_WORDS]
    if found:
        raise DesignError("column", header, f"states the unit {found[0]!r} where tabletcad does not read one: write "
                          "it at the end of the header, in brackets ('Force [kN]') or after an underscore ('force_kN'), or give it as "
                          "an option where the command takes one (--force-unit)")


def strip_unit(header: str) -> str:
    """``header`` without its unit (for recognising the column's role)."""
    m = _BRACKET.search(header)
    if m:
        return header[: m.start()].strip()
    m = _trailing(header)
    return header.strip() if m is None else header[: m.start()].strip()


def _trailing(header: str) -> re.Match[str] | None:
    m = _TRAILING.search(header)
    if m is None:
        return None
    unit = _normalise(m.group(2))
    if unit not in UNITS or (m.group(1) != "_" and unit in _NOT_AFTER_SPACE):
        return None
    return m


def unit_factor(symbol: str, dimension: str, parameter: str, hint: str = "") -> tuple[float, int | None]:
    """Factor (and its decimal exponent, or None) converting ``symbol`` to N, mm or s.

    Raises
    ------
    DesignError
        ``symbol`` is not a known unit of ``dimension``; ``parameter`` names
        the header or option the unit came from; ``hint`` is appended to what is allowed.
    """
    entry = UNITS.get(_normalise(symbol))
    if entry is None or entry[0] != dimension:
        known = ", ".join(k for k, v in UNITS.items() if v[0] == dimension)
        raise DesignError(parameter, symbol, f"is not a known {dimension} unit ({known}){hint}")
    return entry[1], entry[2]
