"""Tablet shapes that industry presses, as families with exact nominal geometry, and the
catalogue of every family.

:data:`FAMILIES` is the static mapping from a family's name to its
:class:`~tabletcad.family.Family`: the thesis's shapes
(:data:`tabletcad.shapes.THESIS_SHAPES`) and the industry families below.  Design
files, ``tabletcad shapes``, sweeps and the optimiser read it.

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

from types import MappingProxyType
from typing import Mapping

from tabletcad.families.elongated import capsule, modified_capsule, oval
from tabletcad.families.round import compound_cup, concave_bevel, concave_round, ffbe, ffre, flat_face_round
from tabletcad.families.shaped import almond, outline_tablet, rounded_rectangle, rounded_square, rounded_triangle
from tabletcad.families.sweep import certify, nominal_volume, sweep_properties
from tabletcad.family import Family
from tabletcad.shapes import THESIS_SHAPES

__all__ = [
    "FAMILIES",
    "FAMILY_FUNCTIONS",
    "INDUSTRY_FAMILIES",
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

FAMILY_FUNCTIONS = (
    flat_face_round, ffbe, ffre, concave_round, compound_cup, concave_bevel,
    capsule, modified_capsule, oval, almond,
    rounded_triangle, rounded_square, rounded_rectangle,
)

#: The industry families' names, in the order of the table above.
INDUSTRY_FAMILIES: tuple[str, ...] = tuple(f.__name__ for f in FAMILY_FUNCTIONS)

#: Every family by name: the thesis's shapes, then the industry families (static).
FAMILIES: Mapping[str, Family] = MappingProxyType(
    {**THESIS_SHAPES, **{f.__name__: Family.of(f, _UNITS) for f in FAMILY_FUNCTIONS}}
)
