"""A refusal's stated range is one the tool accepts: a computed end is printed exactly when twelve
digits give it, else rounded into the range (``errors.format_bound``), so the printed end itself
builds.  Checked on the round cups' hemisphere limit at awkward sizes (before: ``{:.6g}``, rounded
either way)."""

from __future__ import annotations

import re

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tabletcad.errors import DesignError
from tabletcad.pipeline.design import design_from_dict


def _refusal(tablet: dict) -> str:
    with pytest.raises(DesignError) as err:
        design_from_dict({"tablet": tablet})
    return str(err.value)


@settings(max_examples=15, deadline=None, derandomize=True)
@given(diameter=st.floats(6.0, 14.0), land=st.one_of(st.just(0.0), st.floats(0.001, 0.3)))
def test_a_round_cups_hemisphere_limit_as_stated_builds(diameter, land):
    base = dict(family="concave_round", diameter=diameter, band=2.8, land=land)
    msg = _refusal(base | {"cup_depth": diameter})
    m = re.search(r"must be > 0 and <= (\S+) mm \(a hemisphere", msg)
    assert m, msg
    limit = float(m.group(1))
    assert limit <= diameter / 2.0 - land
    t = design_from_dict({"tablet": base | {"cup_depth": limit}})
    assert t.volume() > 0.0
