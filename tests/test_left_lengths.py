"""What the dimensions leave is 0 or at least the least length (``Tolerances.min_length``), as every
length a design file gives is.

A ffbe whose 45° bevel takes the whole thickness but for ``tan 45° = 0.9999999999999999`` had passed the
report with a band of 1e-16 mm and then failed the build with ``sewn shell has 4 faces, expected 5``
(exit 2, but not the one-line form); likewise a band or flat face of 1e-9 mm a radius edge leaves.
Now ``report`` and ``build`` refuse them alike, naming the parameter that leaves the sliver; what they
accept builds (a band of exactly 0: the radius-edge pill; see ``test_cad_tablets.py``).  Core only.
"""

from __future__ import annotations

import re

import pytest
from hypothesis import given, settings, strategies as st

from tabletcad.cli import main
from tabletcad.errors import DesignError
from tabletcad.pipeline.design import Design

ONE_LINE = re.compile(r"^error: (\S+) = (.+) is not allowed: (.+)$")

SLIVERS = [
    (dict(family="ffbe", diameter=10.0, thickness=2.0, bevel_angle=45, bevel_width=1.0),
     "tablet.bevel_width = 1 mm is not allowed: leaves a band of 1.11e-16 mm"),
    (dict(family="ffbe", diameter=10.0, thickness=2.0, bevel_angle=30, bevel_width=1.7320508075688772),
     "tablet.bevel_width = 1.73205 mm is not allowed: leaves a band of 1.11e-16 mm"),
    (dict(family="ffbe", diameter=10.0, thickness=2.000000001, bevel_angle=45, bevel_width=1.0),
     "tablet.bevel_width = 1 mm is not allowed: leaves a band of 1e-09 mm"),
    (dict(family="ffbe", diameter=10.0, thickness=2.0001, bevel_angle=45, bevel_width=0.0, bevel_depth=1.0),
     "tablet.bevel_depth = 1 mm is not allowed: leaves a band of 0.0001 mm"),
    (dict(family="ffbe", diameter=10.0, thickness=4.0, bevel_angle=10, bevel_width=4.999999999),
     "tablet.bevel_width = 4.999999999 mm is not allowed: leaves a flat face of 1e-09 mm"),  # as given
    (dict(family="ffre", diameter=10.0, thickness=3.000000001, edge_radius=1.5),
     "tablet.edge_radius = 1.5 mm is not allowed: leaves a band of 1e-09 mm"),
    (dict(family="ffre", diameter=3.000000001, thickness=4.0, edge_radius=1.5),
     "tablet.edge_radius = 1.5 mm is not allowed: leaves a flat face of 5e-10 mm"),
]


@pytest.mark.parametrize("tablet, start", SLIVERS)
def test_a_sliver_the_dimensions_leave_is_refused_by_report_and_build(tmp_path, capsys, tablet, start):
    with pytest.raises(DesignError) as e:
        Design.from_dict({"tablet": tablet}).build()
    assert str(e.value).startswith(start)
    assert str(e.value).endswith("a part the dimensions leave must be at least 0.001 mm (Tolerances.min_length, "
                                 "the least length a design takes) or, where the family allows it, none")
    p = tmp_path / "d.toml"
    p.write_text("[tablet]\n" + "".join(f"{k} = {v!r}\n".replace("'", '"') for k, v in tablet.items()), encoding="utf-8")
    for cmd in (["report", str(p)], ["build", str(p), "--out", str(tmp_path / "out")]):
        assert main(cmd) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and ONE_LINE.match(err[0]) and err[0] == "error: " + str(e.value), err
    assert sorted(q.name for q in tmp_path.iterdir()) == ["d.toml"]


@settings(max_examples=60, deadline=None)
@given(T=st.floats(1.0, 6.0), frac=st.floats(0.9990, 1.0), angle=st.sampled_from([15.0, 30.0, 45.0, 60.0]))
def test_a_bevel_near_the_whole_thickness_leaves_a_band_of_at_least_the_least_length_or_is_refused(T, frac, angle):
    """Whatever a design file's ffbe is accepted with, its band is at least the least length."""
    import math

    width = frac * (T / 2) / math.tan(math.radians(angle))
    try:
        t = Design.from_dict({"tablet": dict(family="ffbe", diameter=2 * width + 1.0, thickness=T,
                                             bevel_angle=angle, bevel_width=width)}).build()
    except DesignError as e:
        assert e.parameter == "tablet.bevel_width"
        return
    lo, hi = t.nominal.band_z
    assert hi - lo >= 0.001 * (1 - 1e-9)


@pytest.mark.parametrize("tablet", [dict(family="ffre", diameter=10.0, thickness=3.001, edge_radius=1.5),
                                    dict(family="ffbe", diameter=10.0, thickness=2.001, bevel_angle=45, bevel_width=1.0)])
def test_a_part_left_at_the_least_length_is_accepted(tablet):
    """3.001 - 2 x 1.5 is 0.000999999999999889 in floating point: the least length, not below it."""
    t = Design.from_dict({"tablet": tablet}).build()
    assert t.nominal.band_z[1] - t.nominal.band_z[0] == pytest.approx(0.001, rel=1e-9)
