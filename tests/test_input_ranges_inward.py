"""A refusal's stated range is one the tool accepts: a computed end is printed exactly when twelve
digits give it, else rounded into the range (``errors.format_bound``), so the printed end itself
builds.  Checked on the round cups' hemisphere limit at awkward sizes (before: ``{:.6g}``, rounded
either way)."""

from __future__ import annotations

import math
import re

import numpy as np
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


# --- compound cups: the stated range is where the cup builds, not only where its radii are tangent -----

def _between(msg: str, name: str) -> tuple[float, float]:
    m = re.search(rf"tablet\.{name} = .* must be between (\S+) and (\S+) mm", msg)
    assert m, msg
    return float(m.group(1)), float(m.group(2))


def _arcs(t) -> dict:
    return {e.label: e.length for e in t.nominal.top if e.label.startswith("cup ")}


# each config's tangency range had been stated: at its shallow end the edge arc is shorter than
# 0.001 mm (0.000701, 0.000608, 0.000426 mm), at the deep end of the last the central arc (1.2e-5 mm),
# and the design stated in range was refused as "tablet = 'compound_cup' ... leaves a cup edge radius"
@pytest.mark.parametrize("dims", [
    dict(diameter=8.0, band=2.0, central_radius=12.0, edge_radius=0.5, land=0.0),
    dict(diameter=12.0, band=3.0, central_radius=20.0, edge_radius=3.0, land=0.1),
    dict(diameter=6.0, band=2.0, central_radius=7.0, edge_radius=0.3, land=0.0),
    dict(diameter=10.0, band=2.0, central_radius=6.0, edge_radius=5.5, land=0.0),
    dict(diameter=9.8, band=2.0, central_radius=5.2, edge_radius=4.9, land=0.1),
])
def test_a_compound_cups_depth_range_as_stated_builds(dims):
    base = dict(family="compound_cup", **dims)
    lo, hi = _between(_refusal(base | {"cup_depth": 50.0}), "cup_depth")
    for end in (lo, hi):
        arcs = _arcs(design_from_dict({"tablet": base | {"cup_depth": end}}))
        assert set(arcs) == {"cup edge radius", "cup central radius"}
        assert min(arcs.values()) >= 1e-3, (end, arcs)
    # the range is not needlessly narrow: just outside an end (beyond its rounding inward to six
    # digits) one arc is too short or the radii are not tangent, and the refusal names cup_depth
    for out in (lo * (1 - 2e-5), hi * (1 + 2e-5)):
        assert _between(_refusal(base | {"cup_depth": out}), "cup_depth") == (lo, hi)


def test_a_shaped_compound_cups_depth_range_as_stated_builds():
    base = dict(family="capsule", length=18.0, width=8.0, band=3.2, land=0.08, central_radius=12.0, edge_radius=0.3)
    lo, hi = _between(_refusal(base | {"cup_depth": 50.0}), "cup_depth")
    for end in (lo, hi):
        assert min(_arcs(design_from_dict({"tablet": base | {"cup_depth": end}})).values()) >= 1e-3


@pytest.mark.parametrize("dims", [
    dict(diameter=11.0, band=2.6, central_radius=16.0, edge_radius=2.5, land=0.05),
    dict(diameter=12.0, band=2.6, central_radius=20.0, edge_radius=4.0, land=0.1),
    dict(diameter=10.0, band=2.0, central_radius=6.0, edge_radius=5.5, land=0.0),
])
def test_a_compound_cups_blend_diameter_range_as_stated_builds(dims):
    """The blend diameter's range had been stated as ``> 0 and < 2 w``: near ``2 w`` the edge arc
    vanishes (a 10.8999 mm blend in a 10.9 mm cup left 5.3e-5 mm), and a small blend was refused
    naming the edge radius."""
    base = dict(family="compound_cup", cup_depth=0.0, **dims)
    w = dims["diameter"] / 2 - dims["land"]
    lo, hi = _between(_refusal(base | {"blend_diameter": 2 * w - 1e-4}), "blend_diameter")
    assert (lo, hi) == _between(_refusal(base | {"blend_diameter": 0.01 if lo > 0.01 else 2 * w}), "blend_diameter")
    for end in (lo, hi):
        t = design_from_dict({"tablet": base | {"blend_diameter": end}})
        assert min(_arcs(t).values()) >= 1e-3
        assert t.nominal.info["blend_diameter_mm"] == pytest.approx(end, rel=1e-12)
    # the reach limit in closed form: the edge arc's centre lies on the line from the central arc's
    # centre to the blend, (Rc - Re)/Rc of the way out, and at most Re from the cup edge
    Rc, Re = dims["central_radius"], dims["edge_radius"]
    reach = 2 * (w - Re) * Rc / (Rc - Re)
    if reach > 0.002:
        assert lo == pytest.approx(reach, abs=1e-5)


@pytest.mark.parametrize("w, Rc, Re", [(5.45, 16.0, 2.5), (3.0, 10.0, 1.0), (5.0, 8.0, 4.0), (4.0, 20.0, 0.5)])
def test_the_deepest_compound_cups_edge_arc_turns_the_short_way(w, Rc, Re):
    """At the deepest cup the radii allow the edge arc's centre is level with the cup edge
    (``h = Rc - sqrt((Rc - Re)^2 - (w - Re)^2)``); its rounding put the centre 1e-16 mm above the
    edge, atan2 gave -pi for pi, and the arc went the long way round (4.94 for 1.35 mm at w = 3)."""
    from tabletcad.families.cups import CompoundCup

    h = Rc - ((Rc - Re) ** 2 - (w - Re) ** 2) ** 0.5
    for depth in (h, float(np.nextafter(h, 0.0)), float(np.nextafter(h, 10.0))):
        edge, central = CompoundCup(w, Rc, Re, depth).elements(0.0)
        assert edge.length == pytest.approx(Re * math.atan2(Rc - h, w - Re), rel=1e-12)
        assert central.length == pytest.approx(Rc * math.atan2(w - Re, Rc - h), rel=1e-12)
