"""What ``[trim] v`` means on a shaped outline (README, "cut-away"): not a plan angle but the arc length
along the outline scaled to [0, 2π], counter-clockwise from the family's first outline point.

Checked on a 15 x 7 mm rounded rectangle with 2.5 mm corners: its perimeter is
``P = 2 (L - 2r) + 2 (W - 2r) + 2π r``; the band, at every ``v``, lies on the outline point a fraction
``v / 2π`` of ``P`` along it from ``(L/2 - r, -W/2)``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from tabletcad.pipeline.design import design_from_dict

L, W, R = 15.0, 7.0, 2.5


def _outline_point(s: float) -> tuple[float, float]:
    """The rounded rectangle's outline point at arc length ``s`` (mm) from ``(L/2 - r, -W/2)``, counter-clockwise."""
    a, b = L / 2 - R, W / 2 - R  # the corner centres' coordinates
    quarter = math.pi * R / 2
    pieces = [("arc", (a, -b), -math.pi / 2), ("line", (L / 2, -b), (0.0, 1.0), 2 * b),
              ("arc", (a, b), 0.0), ("line", (a, W / 2), (-1.0, 0.0), 2 * a),
              ("arc", (-a, b), math.pi / 2), ("line", (-L / 2, b), (0.0, -1.0), 2 * b),
              ("arc", (-a, -b), math.pi), ("line", (-a, -W / 2), (1.0, 0.0), 2 * a)]
    for piece in pieces:
        length = quarter if piece[0] == "arc" else piece[3]
        if s <= length:
            if piece[0] == "arc":
                (cx, cy), t0 = piece[1], piece[2] + s / R
                return cx + R * math.cos(t0), cy + R * math.sin(t0)
            (x0, y0), (dx, dy) = piece[1], piece[2]
            return x0 + s * dx, y0 + s * dy
        s -= length
    raise AssertionError("beyond the perimeter")


def test_trim_v_on_a_shaped_outline_is_arc_length_from_its_first_point():
    t = design_from_dict({"tablet": dict(family="rounded_rectangle", length=L, width=W, corner_radius=R, band=3.0,
                                         cup_depth=0.8, land=0.05)})
    perimeter = 2 * (L - 2 * R) + 2 * (W - 2 * R) + 2 * math.pi * R
    v = np.linspace(0.0, 2 * math.pi, 41)[:-1]
    # the family's outline itself, exactly; and the band of PDE patches on it (within its 1e-6 mm of the nominal)
    want = np.array([_outline_point(perimeter * x / (2 * math.pi)) for x in v])
    assert t.nominal.outline.perimeter == pytest.approx(perimeter, rel=1e-12)
    assert t.nominal.outline.point(v) == pytest.approx(want, abs=1e-12)
    band = max(t.patches, key=lambda p: float(np.max(np.hypot(*p.evaluate(np.full(3, 0.5), v[:3])[:, :2].T))))
    assert band.evaluate(np.full_like(v, 0.5), v)[:, :2] == pytest.approx(want, abs=1e-6)
    # a quarter of 2π is a quarter of the perimeter, not the plan's 90° (which is the point (0, W/2))
    q = band.evaluate(np.array([0.5]), np.array([math.pi / 2]))[0, :2]
    assert q == pytest.approx(_outline_point(perimeter / 4), abs=1e-6)
    assert abs(q[0]) > 1.0
