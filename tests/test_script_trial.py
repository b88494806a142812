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


def test_a_default_cup_width_at_a_narrow_plateau_builds():
    """rounded_triangle 10 mm, corner 2.7 mm: the cup width left out is the corner radius, whose plateau is
    narrow; it was refused (naming the default), and now builds (its plateau split closer to the centre), as
    does a cup width below it."""
    from tabletcad import make

    t = make("rounded_triangle", side=10.0, corner_radius=2.7, band=3.0, cup_depth=1.0)
    assert t.tablet.nominal.info["cup_width_mm"] == pytest.approx(2.7, abs=1e-12)
    narrower = make("rounded_triangle", side=10.0, corner_radius=2.7, band=3.0, cup_depth=1.0, cup_width=2.6)
    assert narrower.volume > t.volume > 0.0  # the same depth reached sooner: a wider plateau


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
