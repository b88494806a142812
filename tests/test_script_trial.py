"""Scripting inputs a CAD user gave (session 26's trial) that were refused under the wrong name."""

from __future__ import annotations

import pytest

from tabletcad.errors import DesignError
from tabletcad.families.inverse import solve_for


@pytest.mark.parametrize("given, missing", [({}, "solid_fraction"), ({"solid_fraction": 0.85}, "true_density_mg_mm3"),
                                            ({"true_density_mg_mm3": 1.4}, "solid_fraction")])
def test_a_weight_target_names_the_density_figure_left_out(given, missing):
    """The error had named ``solid_fraction,.true_density_mg_mm3`` (two names read as one token)."""
    with pytest.raises(DesignError) as err:
        solve_for("concave_round", target_weight_mg=300.0, vary="band", diameter=10.0, cup_depth=1.0, **given)
    assert err.value.parameter == missing and "\n" not in str(err.value)


def test_a_default_cup_width_too_wide_for_the_plateau_says_it_is_the_default():
    """rounded_triangle 10 mm, corner 2.7 mm: the cup width left out is the corner radius, whose plateau is too
    narrow; the error says so and a cup width below it builds."""
    from tabletcad import make

    with pytest.raises(DesignError) as err:
        make("rounded_triangle", side=10.0, corner_radius=2.7, band=3.0, cup_depth=1.0)
    assert err.value.parameter == "tablet.cup_width" and "a cup_width left out is that radius" in str(err.value)
    t = make("rounded_triangle", side=10.0, corner_radius=2.7, band=3.0, cup_depth=1.0, cup_width=2.6)
    assert t.volume > 0
