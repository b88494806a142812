"""Mini-tablets (1-3 mm): OCCT 7.9's planar offset crashed the process (SIGSEGV) offsetting a circle of
1 mm radius or less inward, so a 2 mm round's tooling build died with exit 139.  Small wires are offset
as a similar copy 10 mm across and scaled back (exact for lines and arcs)."""

import math

import pytest

pytest.importorskip("OCP")
pytest.importorskip("manifold3d")

from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire  # noqa: E402
from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Pnt  # noqa: E402

from tabletcad.pipeline.design import Design  # noqa: E402
from tabletcad.tooling.outline import face_area, offset_wire, plan_face, wire_length  # noqa: E402
from tabletcad.tooling.toolset import make_tooling  # noqa: E402

pytestmark = pytest.mark.cad


@pytest.mark.parametrize("r, d, z", [(1.0, -0.02, 0.0), (0.5, -0.01, -0.4), (1.0, -0.05, 0.7), (1.0, 0.02, 1.3),
                                     (5.0, -0.02, 1.0)])
def test_small_circles_offset_exactly(r, d, z):
    edge = BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(gp_Pnt(0, 0, z), gp_Dir(0, 0, 1)), r)).Edge()
    out = offset_wire(BRepBuilderAPI_MakeWire(edge).Wire(), d)
    assert face_area(plan_face(out)) == pytest.approx(math.pi * (r + d) ** 2, rel=1e-12)
    assert wire_length(out) == pytest.approx(2 * math.pi * (r + d), rel=1e-12)


def test_a_two_millimetre_round_gets_its_tooling():
    d = Design.from_dict({"tablet": {"family": "concave_round", "diameter": 2.0, "band": 1.0, "cup_depth": 0.3,
                                     "land": 0.05},
                          "tooling": {"clearance_mm": 0.02, "die_outer_diameter_mm": 10.0, "die_height_mm": 8.0}})
    ts = make_tooling(d.build(), d.tooling_spec, check=False, interference_check=False)
    up = ts.report["upper_punch"]
    assert up["tip_diameter_mm"] == pytest.approx(2 * (1.0 - 0.02), abs=1e-12)
    assert up["tip_plan_area_mm2"] == pytest.approx(math.pi * 0.98**2, rel=1e-9)
    # the tip: its cylinder minus the cup within it (the quadrature of the plain tip)
    assert up["volume_mm3"] == pytest.approx(up["volume_quadrature_mm3"], rel=1e-7)


def test_a_figure_across_a_score_is_warned_of():
    """Letters across a bisect are cut in two when the tablet is split and pick at the groove's edge (a
    trade rule): a warning names the figure and the score; none for a figure clear of the groove or on
    the other face."""
    import warnings

    from tabletcad.cad.tablet_solid import tablet_solid
    from tabletcad.tooling.emboss import check_emboss
    from tabletcad.tooling.outline import tablet_frame
    from tabletcad.tooling.spec import EmbossSpec, ScoreSpec, ToolingSpec
    from tabletcad.tooling.toolset import _warn_crossings

    d = Design.from_dict({"tablet": {"family": "concave_round", "diameter": 10.0, "band": 2.8, "cup_depth": 0.9,
                                     "land": 0.08}})
    t = d.build()
    frame = tablet_frame(t, tablet_solid(t).shape)
    score = ScoreSpec(depth_mm=0.3, direction_deg=0.0)  # along x: the groove is |y| < 0.3 mm at the face

    def crossings(**kw):
        e = EmbossSpec(text="AB", height_mm=1.5, depth_mm=0.1, **kw)
        spec = ToolingSpec(clearance_mm=0.02, scores=(score,), emboss=(e,))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            _warn_crossings(frame, spec, [check_emboss(frame, e, 0.02, 0)])
        return [str(w.message) for w in caught]

    (msg,) = crossings()
    assert msg.startswith("emboss 0 ('AB') crosses score 0 on the top face")
    assert crossings(position_mm=(0.0, 2.5)) == []  # clear of the groove
    assert crossings(face="bottom") == []  # the score is on the top face
