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


def test_a_model_with_one_dimension_changed():
    """``make(family, **m.tablet.params)`` with one value changed refused derived values (a capsule's cup
    width); ``replace`` changes the design itself and keeps its other tables."""
    from tabletcad import make
    from tabletcad.pipeline.design import Design
    from tabletcad.pipeline.model import TabletModel

    m = make("capsule", length=16.0, width=7.0, band=3.0, cup_depth=1.0)
    longer = m.replace(length=18.0)
    assert longer.tablet.dimensions()["length_mm"] == pytest.approx(18.0, abs=1e-6)
    assert longer.tablet.dimensions()["width_mm"] == pytest.approx(7.0, abs=1e-6)
    assert m.tablet.dimensions()["length_mm"] == pytest.approx(16.0, abs=1e-6)  # the model itself unchanged
    # a stadium's volume grows by its straight section: 2 mm more of the 7 mm wide band's cross-section and cups
    assert longer.volume > m.volume
    d = Design.from_dict({"tablet": {"family": "concave_round", "diameter": 10.0, "band": 3.0, "cup_depth": 1.0},
                          "report": {"solid_fraction": 0.85, "true_density_mg_mm3": 1.5}})
    kept = TabletModel(d.build(), d).replace(diameter=11.0)
    assert kept.design.report == {"solid_fraction": 0.85, "true_density_mg_mm3": 1.5}
    assert kept.design.tablet["diameter"] == 11.0 and d.tablet["diameter"] == 10.0
    with pytest.raises(DesignError) as err:
        m.replace(length=-1.0)
    assert err.value.parameter == "tablet.length"


def test_make_takes_the_report_table_for_a_weight():
    """``make`` had no way to a weight: ``solid_fraction=`` was refused as a dimension."""
    from tabletcad import make

    m = make("concave_round", diameter=10.0, band=3.0, cup_depth=1.0,
             report=dict(solid_fraction=0.85, true_density_mg_mm3=1.5))
    assert m.report()["design_report"]["weight_mg"] == pytest.approx(m.volume * 0.85 * 1.5, rel=1e-12)
    with pytest.raises(DesignError) as err:
        make("concave_round", diameter=10.0, band=3.0, cup_depth=1.0, report=dict(solid_fraction=1.5))
    assert "solid_fraction" in err.value.parameter
