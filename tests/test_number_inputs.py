"""Numbers of every numeric type a script may hold are numbers; a unit follows only a number.

A scripting user passes numpy scalars (an element of an array), ``Fraction`` or ``Decimal``: each is
the number it equals (the tablet is the same as with the float).  A value that is no number is
shown as given, without the unit (``None``, ``[10]``, text), in the one-line error.  Core only.
"""

from __future__ import annotations

import decimal
import fractions

import numpy as np
import pytest

from tabletcad.errors import DesignError, is_number
from tabletcad.pipeline.design import Design


def _design(diameter):
    return Design.from_dict({"tablet": {"family": "concave_round", "diameter": diameter, "band": 2.8,
                                        "cup_depth": 0.9}})


@pytest.mark.parametrize("value", [np.int64(10), np.int32(10), np.float64(10.0), np.float32(10.0), np.array(10.0),
                                   np.longdouble(10),
                                   fractions.Fraction(10), decimal.Decimal("10"), decimal.Decimal("10.000")])
def test_numeric_types_give_the_tablet_of_the_float(value):
    a = _design(value).build()
    b = _design(10.0).build()
    assert a.volume() == pytest.approx(b.volume(), rel=1e-15, abs=0.0)
    assert a.dimensions()["length_mm"] == b.dimensions()["length_mm"]


@pytest.mark.parametrize("value, message", [
    (None, "tablet.diameter = None is not allowed: must be a number"),
    ([10], "tablet.diameter = [10] is not allowed: must be a number"),
    ("ten", "tablet.diameter = 'ten' is not allowed: must be a number"),
    ({"v": 10}, "tablet.diameter = {'v': 10} is not allowed: must be a number"),
    (np.True_, "tablet.diameter = true is not allowed: must be a number (true and false are not numbers)"),
    (True, "tablet.diameter = true is not allowed: must be a number (true and false are not numbers)"),
    (float("nan"), "tablet.diameter = nan mm is not allowed: must be a finite number"),
    (decimal.Decimal("Infinity"), "tablet.diameter = Infinity mm is not allowed: must be a finite number"),
    (10**400, "tablet.diameter = an integer of 401 digits is not allowed: must be a finite number"),
    # an integer shown as given up to 40 digits (it was 1e+20)
    (99999999999999999999, "tablet.diameter = 99999999999999999999 mm is not allowed: must be within ±1000 mm "
                           "(size limit, Tolerances.max_length)"),
    (-1, "tablet.diameter = -1 mm is not allowed: must be > 0"),
])
def test_the_unit_follows_only_a_number(value, message):
    with pytest.raises(DesignError) as e:
        _design(value).build()
    assert str(e.value) == message


def test_is_number():
    assert all(map(is_number, [0, 1.5, np.float16(1), np.uint8(3), fractions.Fraction(1, 3), decimal.Decimal("2")]))
    assert not any(map(is_number, [True, np.bool_(False), "1", b"1", None, [1], np.array([1.0]), 1j]))


def test_a_long_value_is_shown_whole_up_to_200_characters():
    """A path of a nested or temporary folder is shown whole (it was cut at 80 characters, which made
    refusals naming pytest's temporary folders depend on its numbering); longer values keep their ends."""
    path = "/tmp/" + "a" * 180 + "/out"
    assert str(DesignError("--out", path, "must be a folder")) == f"--out = '{path}' is not allowed: must be a folder"
    huge = list(range(1000))
    shown = str(DesignError("x", huge, "must be short")).split(" is not allowed")[0]
    assert shown.startswith("x = [0, 1, 2") and "..." in shown and shown.endswith("997, 998, 999]") and len(shown) < 200


def test_an_outline_as_an_array_or_pairs_is_the_outline_as_lists():
    """A script's custom outline may be an (n, 2) array or a list of tuples: the same tablet as the
    lists TOML gives (an array had been refused as "must be a list of [x, y] points")."""
    th = np.linspace(0.0, 2.0 * np.pi, 40, endpoint=False)
    pts = np.column_stack([6.0 * np.cos(th), 4.0 * np.sin(th)])

    def volume(outline):
        return Design.from_dict({"tablet": {"family": "custom_outline", "outline": outline, "band": 2.0,
                                            "cup_depth": 0.8}}).build().volume()

    ref = volume(pts.tolist())
    assert volume(pts) == ref and volume([tuple(p) for p in pts.tolist()]) == ref
    with pytest.raises(DesignError, match=r"^tablet.diameter = \[10.0, 3.0\] is not allowed: must be a number$"):
        _design(np.array([10.0, 3.0])).build()


def test_a_design_that_contains_itself_is_refused():
    data = {"tablet": {"family": "concave_round", "diameter": 10.0, "band": 2.8, "cup_depth": 0.9}}
    data["tablet"]["again"] = data
    with pytest.raises(DesignError, match=r"^design = 'dict' is not allowed: must not contain itself$"):
        Design.from_dict(data)


def test_a_decimal_or_a_fraction_is_kept_as_the_float_toml_would_give():
    """``make(diameter=Decimal("10.1"), band=Fraction(5, 2))`` built, then ``design.to_toml()`` refused the design
    ("must hold numbers, text, ..."): the design holds the floats TOML would, and round-trips through its text."""
    import tomllib

    d = Design.from_dict({"tablet": {"family": "concave_round", "diameter": decimal.Decimal("10.1"),
                                     "band": fractions.Fraction(5, 2), "cup_depth": 1}})
    assert d.tablet["diameter"] == 10.1 and d.tablet["band"] == 2.5 and type(d.tablet["cup_depth"]) is int
    assert tomllib.loads(d.to_toml())["tablet"] == dict(d.tablet)


@pytest.mark.parametrize("value, shown", [(decimal.Decimal("1e400"), "1E+400"), (decimal.Decimal("-1e400"), "-1E+400"),
                                          (fractions.Fraction(10**400), "1000000")])
def test_a_decimal_or_a_fraction_no_float_holds_is_refused_as_given(value, shown):
    """``Fraction(10**400)`` had raised a bare OverflowError, ``Decimal("1e400")`` been quoted as ``inf``."""
    with pytest.raises(DesignError) as e:
        _design(value).build()
    assert str(e.value).startswith(f"tablet.diameter = {shown}") and str(e.value).endswith("must be a finite number")
