"""Tooling for a free-form tablet (``family = "free_form"``): its band's plan outline, exactly from its
curve where the curve is lines and arcs, else the section of the solid through the band.

Both paths had failed with an internal error (OCP's ``ConnectEdgesToWires`` takes its wires as an
out-argument; the moved section was no ``TopoDS_Wire``), and the stadium's section could not be
offset by the clearance."""

import math
from pathlib import Path

import pytest

pytest.importorskip("OCP")
pytest.importorskip("manifold3d")

from tabletcad.cad.tablet_solid import tablet_solid  # noqa: E402
from tabletcad.pipeline.design import Design  # noqa: E402
from tabletcad.tooling import make_tooling  # noqa: E402
from tabletcad.tooling.outline import _section_wire, face_area, plan_face, tablet_frame, wire_length  # noqa: E402

pytestmark = pytest.mark.cad

STADIUM = Path(__file__).resolve().parents[1] / "samples" / "free_form_stadium.toml"
L, W = 12.0, 6.0  # the sample's band: a 12 x 6 mm stadium from z = 0 to 3
AREA, PERIMETER = (L - W) * W + math.pi * (W / 2) ** 2, 2 * (L - W) + math.pi * W


@pytest.fixture(scope="module")
def stadium():
    d = Design.from_toml(STADIUM)
    return d, d.build()


def test_the_band_of_lines_and_arcs_is_the_outline_itself(stadium):
    _, t = stadium
    fr = tablet_frame(t)
    assert face_area(plan_face(fr.outline)) == pytest.approx(AREA, rel=1e-12)
    assert wire_length(fr.outline) == pytest.approx(PERIMETER, rel=1e-12)


def test_the_section_through_the_band_is_one_wire_of_the_stadium(stadium):
    _, t = stadium
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    wire = _section_wire(tablet_solid(t).shape, 1.5)
    props = GProp_GProps()  # adaptive: OCC's fixed rule is 2e-3 off on the section's many-span edges
    BRepGProp.SurfaceProperties_s(plan_face(wire), props, 1e-10)
    # the band's fitted surface lies within the fit tolerance (0.1 um) of the stadium, the PDE band
    # bulging by 85 nm: the area within P x 0.1 um (measured 5.0e-4 mm2), the length within 1e-5
    assert abs(props.Mass()) == pytest.approx(AREA, abs=PERIMETER * 1e-4)
    assert wire_length(wire) == pytest.approx(PERIMETER, rel=1e-5)


def test_a_free_form_stadium_gets_tooling_that_fits(stadium):
    d, t = stadium
    ts = make_tooling(t, d.tooling_spec)  # the sample's defaults: clearance, tips, die
    r = ts.report
    assert r["interference_mm3"] <= 1e-6 and r["interference"]["gap_within_clearance"]
    assert 0.0 < r["max_gap_mm"] <= ts.spec.clearance_mm
