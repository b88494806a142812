"""Tablet shapes that industry presses, as families with exact nominal geometry.

Importing this package registers every family with
:func:`tabletcad.shapes.register_family` (so design files, ``tabletcad shapes``
and the optimiser see them) and the design report with
:func:`tabletcad.report.register_report_section`.

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

from tabletcad.families.elongated import capsule, modified_capsule, oval
from tabletcad.families.round import compound_cup, concave_bevel, concave_round, ffbe, ffre, flat_face_round
from tabletcad.families.shaped import almond, outline_tablet, rounded_rectangle, rounded_square, rounded_triangle
from tabletcad.families.sweep import certify, nominal_volume, sweep_properties

__all__ = [
    "FAMILY_FUNCTIONS",
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


def _register() -> None:
    import inspect

    from tabletcad.report import register_report_section
    from tabletcad.shapes import Family, register_family

    from tabletcad.families.designreport import report_section

    for f in FAMILY_FUNCTIONS:
        sig = inspect.signature(f)
        params = {k: _UNITS.get(k, "mm") for k, p in sig.parameters.items() if p.kind is p.POSITIONAL_OR_KEYWORD}
        register_family(Family(f.__name__, f, params, (f.__doc__ or "").strip().splitlines()[0]))
    register_report_section(report_section)


_register()
