"""Tablet shapes that industry presses, as families with exact nominal geometry, and the
catalogue of every family.

:data:`FAMILIES` is the static mapping from a family's name to its
:class:`~tabletcad.families.family.Family`: the industry families below, then the
thesis's shapes (:data:`tabletcad.families.thesis.THESIS_SHAPES`) named ``thesis.<name>``.
Design files, ``tabletcad shapes``, sweeps, tooling batches, the optimiser and the
FreeCAD workbench look names up with :func:`family`, which still accepts the
thesis's shapes under their old plain names (:data:`RENAMED`) with a warning.

Each family builds a nominal description (a face profile of lines and arcs
revolved about the axis or swept along inward offsets of a plan outline, see
:mod:`tabletcad.families.sweep`) and a PDE representation generated from it
(Hermite-form patches, certified to ``tol.nominal``, 1 µm by default).

=====================  =============================================================
family                 parameters (mm unless stated)
=====================  =============================================================
flat_face_round        diameter, thickness
ffbe                   diameter, thickness, bevel_angle (deg), bevel_width, bevel_depth
ffre                   diameter, thickness, edge_radius
concave_round          diameter, band, cup_depth, land
compound_cup           diameter, band, cup_depth, central_radius, edge_radius, land, blend_diameter
concave_bevel          diameter, band, cup_depth, bevel_angle (deg), bevel_width
capsule                length, width, band, cup_depth, land, central_radius, edge_radius
modified_capsule       length, width, side_radius, band, cup_depth, land, cup_width
oval                   length, width, end_radius, band, cup_depth, land, cup_width
almond                 length, width, end_radius, band, cup_depth, land, cup_width
rounded_triangle       side, corner_radius, band, cup_depth, land, cup_width
rounded_square         side, corner_radius, band, cup_depth, land, cup_width
rounded_rectangle      length, width, corner_radius, band, cup_depth, land, cup_width
=====================  =============================================================

Any other plan outline (points or lines and arcs): :func:`outline_tablet`.
"""

from __future__ import annotations

import os
import sys
import warnings
from dataclasses import replace
from types import MappingProxyType
from typing import Mapping

from tabletcad.families.elongated import capsule, modified_capsule, oval
from tabletcad.families.round import compound_cup, concave_bevel, concave_round, ffbe, ffre, flat_face_round
from tabletcad.families.shaped import almond, outline_tablet, rounded_rectangle, rounded_square, rounded_triangle
from tabletcad.errors import DesignError
from tabletcad.families.sweep import certify, nominal_volume, sweep_properties
from tabletcad.families.family import Family
from tabletcad.families.thesis import THESIS_SHAPES

__all__ = [
    "FAMILIES",
    "FAMILY_FUNCTIONS",
    "INDUSTRY_FAMILIES",
    "RENAMED",
    "THESIS_FAMILIES",
    "family",
    "almond",
    "capsule",
    "certify",
    "compound_cup",
    "concave_bevel",
    "concave_round",
    "ffbe",
    "ffre",
    "flat_face_round",
    "modified_capsule",
    "nominal_volume",
    "outline_tablet",
    "oval",
    "rounded_rectangle",
    "rounded_square",
    "rounded_triangle",
    "sweep_properties",
]

_UNITS = {"bevel_angle": "deg"}
#: a required dimension that another may replace: a ffbe's bevel is given by its width or its depth
_ALTERNATIVES = {"ffbe": {"bevel_width": "bevel_depth"}}

FAMILY_FUNCTIONS = (
    flat_face_round, ffbe, ffre, concave_round, compound_cup, concave_bevel,
    capsule, modified_capsule, oval, almond,
    rounded_triangle, rounded_square, rounded_rectangle,
)

#: The industry families' names, in the order of the table above.
INDUSTRY_FAMILIES: tuple[str, ...] = tuple(f.__name__ for f in FAMILY_FUNCTIONS)

#: The catalogue names of the thesis's shapes (Tables 4.1 and 4.5): ``thesis.<name>``.
THESIS_FAMILIES: tuple[str, ...] = tuple(f"thesis.{n}" for n in THESIS_SHAPES)

#: Every family by name: the industry families, then the thesis's shapes (static, read-only).
FAMILIES: Mapping[str, Family] = MappingProxyType({
    **{f.__name__: Family.of(f, _UNITS, alternatives=_ALTERNATIVES.get(f.__name__)) for f in FAMILY_FUNCTIONS},
    **{f"thesis.{n}": replace(f, name=f"thesis.{n}") for n, f in THESIS_SHAPES.items()},
})

#: Names of earlier releases, still accepted with a one-line :class:`FutureWarning`: the thesis's
#: shapes before they moved under ``thesis.`` (``flat_faced_round`` is now
#: ``thesis.flat_faced_round``; the industry ``flat_face_round`` keeps its name).
RENAMED: Mapping[str, str] = MappingProxyType({n: f"thesis.{n}" for n in THESIS_SHAPES})

#: The release after which the old names are refused.
RENAMED_UNTIL = "0.3"


_PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _outside_stacklevel() -> int:
    """The ``stacklevel`` of the first frame outside the tabletcad package, seen from the caller."""
    level, frame = 1, sys._getframe(1)
    while frame is not None and frame.f_code.co_filename.startswith(_PACKAGE_DIR + os.sep):
        frame = frame.f_back
        level += 1
    return level


def family(name: str, *, parameter: str = "tablet.family") -> Family:
    """The family called ``name`` in :data:`FAMILIES`; a name of :data:`RENAMED` gives its new
    family with a one-line :class:`FutureWarning`.

    Raises :class:`~tabletcad.errors.DesignError` naming ``parameter`` for any other name.
    The warning is attributed to the first caller outside tabletcad (a user's script, a test).
    """
    if isinstance(name, str) and name in RENAMED:
        new = RENAMED[name]
        warnings.warn(f"family {name!r} is now {new!r}; the old name is accepted until tabletcad {RENAMED_UNTIL}",
                      FutureWarning, stacklevel=_outside_stacklevel())
        name = new
    if not isinstance(name, str) or name not in FAMILIES:
        raise DesignError(parameter, name, f"must be one of {', '.join(FAMILIES)}")
    return FAMILIES[name]
