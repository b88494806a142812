"""A punch-and-die maker's second trial (session 33): a lower punch whose barrel would hit the die at ejection, a
die outer diameter other than the standard's sent out as the standard, and a tablet too large for every TSM
die refused only after the CAD stage (49 s and 3 GB for a 1000 mm round), a batch that overwrote an edited file
and left an earlier batch's sizes, a 1 mm clearance unwarned, sheets without the lettering's, the head's and
a shaped outline's figures; and from a scripting user's trial, a tablet's writable profile arrays.

Each refusal: the one ``error: <parameter> = <value> is not allowed: <range>`` line, exit 2, nothing written.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from support.refusals import build_refused as _refused

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = (ROOT / "samples" / "tooling" / "tsm_b_round.toml").read_text(encoding="utf-8")


@pytest.mark.cad
@pytest.mark.parametrize("lower", ["19.0", "22.22"])
def test_a_lower_tip_no_longer_than_the_die_is_refused(capsys, tmp_path, lower):
    """At ejection the lower tip edge rises to the die's top face: with a 19 mm tip in the 22.22 mm die the
    barrel's shoulder stood 3.22 mm inside the bore (the sample's own figures until session 33)."""
    pytest.importorskip("OCP")
    design = SAMPLE.replace("lower_tip_length_mm = 25.4", f"lower_tip_length_mm = {lower}")
    assert design != SAMPLE
    name, value, why = _refused(capsys, tmp_path, design)
    assert name == "tooling.lower_tip_length_mm" and value == f"{float(lower):g} mm"
    assert why.startswith("must be > 22.22 mm, the die's height")


def test_a_die_other_than_the_standards_is_labelled_modified():
    from tabletcad.pipeline.design import Design

    spec = Design.from_dict(__import__("tomllib").loads(SAMPLE.replace(
        "die_height_mm = 22.22", "die_height_mm = 22.22\ndie_outer_diameter_mm = 27.0"))).tooling_spec
    assert spec.body.modified == {"die_outer_diameter_mm": {"given": 27.0, "standard": 30.16}}
    same = Design.from_dict(__import__("tomllib").loads(SAMPLE.replace(
        "die_height_mm = 22.22", "die_height_mm = 22.22\ndie_outer_diameter_mm = 30.16"))).tooling_spec
    assert same.body.modified == {}


@pytest.mark.cad
@pytest.mark.parametrize("design, shaped", [
    ('[tablet]\nfamily = "concave_round"\ndiameter = 1000.0\nband = 280\ncup_depth = 90\nland = 0.08\n', "round"),
    ('[tablet]\nfamily = "capsule"\nlength = 25.5\nwidth = 9.0\nband = 3.0\ncup_depth = 1.0\n', "shaped"),
])
def test_a_tablet_larger_than_every_tsm_die_is_refused_before_the_cad(capsys, tmp_path, monkeypatch, design, shaped):
    """No die outer diameter given: the TSM die is chosen from the tablet's size, and one larger than a 'D'
    takes (25 mm) is refused from the PDE tablet's extents, not after its solid (49 s for the 1000 mm round)."""
    pytest.importorskip("OCP")
    import tabletcad.cad.stage

    def no_cad(**kw):
        raise AssertionError("the CAD stage ran before the refusal")

    monkeypatch.setattr(tabletcad.cad.stage, "cad_stage", no_cad)
    name, value, why = _refused(capsys, tmp_path, design + "[tooling]\nclearance_mm = 0.02\ntip_length_mm = 8.0\n")
    assert name == "tooling.die_outer_diameter_mm" and value == "(not given)"
    size = "1000" if shaped == "round" else "25.5"
    assert why == f"give it for a {shaped} tablet {size} mm across (larger than a TSM 'D' die takes, 25 mm)"


@pytest.mark.cad
@pytest.mark.parametrize("side, kind", [(13.0, "B"), (15.0, "D")])
def test_a_shaped_tablets_die_is_chosen_by_its_extent_across_its_corners(side, kind):
    """A rounded square 15 mm on the axes is 20.4 mm across its corners: a TSM D die (a B takes shaped tablets
    up to 19 mm; it had been given a B, its size read along the axes), and 13 mm (17.6 mm across) keeps its B."""
    pytest.importorskip("OCP")
    import math

    from tabletcad.pipeline.design import Design
    from tabletcad.tooling.die import default_die_size
    from tabletcad.tooling.outline import tablet_frame

    t = Design.from_dict({"tablet": {"family": "rounded_square", "side": side, "corner_radius": 1.0, "band": 3.0,
                                     "cup_depth": 0.5}}).build()
    frame = tablet_frame(t)
    assert frame.plan_diameter == pytest.approx(side * math.sqrt(2.0) - 2.0 * (math.sqrt(2.0) - 1.0), rel=1e-12)
    assert default_die_size(frame)[2] == kind


def test_a_tablets_profile_arrays_are_read_only():
    """A tablet is immutable: writing into its profile's arrays had changed its report (length 154 mm) and
    not its solid (a scripting user's trial, session 33)."""
    import numpy as np

    import tabletcad

    m = tabletcad.make("concave_round", diameter=10, band=2, cup_depth=1)
    rev = m.tablet.revolution
    for prof in (rev[0], rev[0].section(), m.tablet.section[0]):
        for name in ("radius", "height") + (("plan",) if hasattr(prof, "plan") else ()):
            with pytest.raises(ValueError, match="read-only"):
                getattr(prof, name)[0] = 99.0
    assert m.report()["length_mm"] == pytest.approx(10.0, abs=1e-6)
    import copy
    import pickle

    for again in (pickle.loads(pickle.dumps(m.tablet)), copy.deepcopy(m.tablet)):  # (came back writeable)
        for prof in (again.revolution[0], again.section[0]):
            with pytest.raises(ValueError, match="read-only"):
                prof.radius[0] = 99.0
    radius = np.array([1.0, 2.0, 3.0, 4.0])
    from tabletcad.geometry.revolution import Revolution

    r = Revolution(0.0, 1, radius, np.zeros(4), 1.0, (0.0, 1 / 3, 2 / 3, 1.0), "curves")
    radius[0] = 7.0  # the caller's array is not the profile's
    assert r.radius[0] == 1.0


@pytest.mark.cad
def test_a_batch_owns_its_folder(tmp_path):
    """A second, smaller batch into the same folder had left the first one's other sizes (stale 10-14 mm
    folders beside new 7-9 mm ones) and overwritten a file the user had edited."""
    pytest.importorskip("OCP")
    import json

    from tabletcad.errors import DesignError
    from tabletcad.tooling import tooling_batch

    fam = "thesis.shallow_convex_round"
    kw = dict(progress=False, check=False, drawing=False)
    out = tmp_path / "b"
    sizes = [dict(diameter=d, thickness=0.3 * d, band=0.2 * d) for d in (6.0, 7.0, 8.0)]
    tooling_batch(fam, sizes, {"clearance_mm": 0.02}, out_dir=out, **kw)
    index = json.loads((out / "batch.json").read_text())
    assert [r["folder"] for r in index] == [f"{fam}_{k:03d}" for k in range(3)]
    assert [r["params"] for r in index] == sizes
    tooling_batch(fam, sizes[:1], {"clearance_mm": 0.02}, out_dir=out, **kw)
    assert sorted(p.name for p in out.iterdir()) == [".tabletcad-build.json", "batch.json", f"{fam}_000"]
    step = out / f"{fam}_000" / "assembly.step"
    step.write_text(step.read_text() + "\n/* edited */\n")
    with pytest.raises(DesignError, match="edited since"):
        tooling_batch(fam, sizes[:1], {"clearance_mm": 0.02}, out_dir=out, **kw)
    assert step.read_text().endswith("/* edited */\n")


@pytest.mark.cad
@pytest.mark.parametrize("clearance, warned", [(0.05, False), (0.1, False), (0.11, True), (1.0, True)])
def test_a_clearance_wider_than_presses_use_is_warned_of(clearance, warned):
    """1 mm a side had been built without a word, where 0 is warned of."""
    pytest.importorskip("OCP")
    import warnings

    from tabletcad.families.thesis import shallow_convex_round
    from tabletcad.tooling.outline import tablet_frame
    from tabletcad.tooling.spec import parse_tooling
    from tabletcad.tooling.toolset import check_on_frame

    frame = tablet_frame(shallow_convex_round())
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        check_on_frame(frame, parse_tooling({"clearance_mm": clearance}))
    wide = [w for w in got if "powder flashes into the gap" in str(w.message)]
    assert len(wide) == int(warned)
    if warned:
        assert str(wide[0].message).startswith(f"clearance_mm = {clearance:g}: wider than 0.1 mm a side")


@pytest.mark.cad
def test_a_shaped_sheet_gives_the_outline_radius_and_the_plateau():
    """The oval sample: end radius 3 mm; its cup runs 3 mm in (the smallest convex radius) where the 8 mm
    width leaves 4, so a flat plateau 2 mm wide finishes the face (its 16 pieces are planes in the solid)."""
    pytest.importorskip("OCP")
    from tabletcad.pipeline.design import Design
    from tabletcad.tooling import make_tooling
    from tabletcad.tooling.drawing import drawing_model
    from tabletcad.tooling.spec import parse_tooling

    t = Design.from_toml(ROOT / "samples" / "families" / "oval.toml").build()
    assert t.nominal.outline.inscribed_radius() == pytest.approx(4.0, abs=1e-9)
    ts = make_tooling(t, parse_tooling({"clearance_mm": 0.02}), check=False, interference_check=False)
    notes = drawing_model(ts).notes
    assert "outline end radius R3.00 ±0.076 mm" in notes
    assert ("cup swept over the outline's offsets: it runs 3.00 mm in from the outline (land included), a flat "
            "plateau inside (the outline offset inwards by it)") in notes


@pytest.mark.cad
def test_tooling_of_an_outline_through_points_is_made_from_its_exact_offsets(capsys, tmp_path):
    """A custom outline given as points is a spline through them, whose band section OpenCascade could not
    offset for the tips and the bore: an internal IndexError had ended the build (a reviewer's trial), then a
    one-line refusal; the tips and the bore are now B-splines of the outline's exact offsets (the tooling
    itself: tests/test_tooling_spline_outline.py), so the design is reported with its tooling, and the frame's
    tip outline lies within 1e-6 mm of the exact offset by the clearance."""
    design = """[tablet]
family = "custom_outline"
outline = [[5.4, 0.0], [5.102834, 0.905867], [4.330127, 1.75], [3.335534, 2.474874], [2.3, 3.031089], [1.22089, 3.38074], [0.0, 3.5], [-1.3673, 3.38074], [-2.7, 3.031089], [-3.735534, 2.474874], [-4.330127, 1.75], [-4.556424, 0.905867], [-4.6, 0.0], [-4.556424, -0.905867], [-4.330127, -1.75], [-3.735534, -2.474874], [-2.7, -3.031089], [-1.3673, -3.38074], [-0.0, -3.5], [1.22089, -3.38074], [2.3, -3.031089], [3.335534, -2.474874], [4.330127, -1.75], [5.102834, -0.905867]]
band = 2.5
cup_depth = 0.5
land = 0.05

[tooling]
clearance_mm = 0.02
tip_length_mm = 8.0
"""
    import math
    import tomllib

    from tabletcad.cli import main
    from tabletcad.pipeline.design import Design
    from tabletcad.tooling.outline import SPLINE_OFFSET_TOL_MM, face_area, plan_face, tablet_frame

    src = tmp_path / "d.toml"
    src.write_text(design, encoding="utf-8")
    assert main(["report", str(src)]) == 0
    assert capsys.readouterr().err == ""
    t = Design.from_dict(tomllib.loads(design)).build()
    frame, outline = tablet_frame(t), t.nominal.outline
    assert frame.offset_deviation(-0.02) <= SPLINE_OFFSET_TOL_MM
    # the tips' plan area is Steiner's for the convex outline shrunk by the clearance
    area = outline.area - outline.perimeter * 0.02 + math.pi * 0.02 ** 2
    assert face_area(plan_face(frame.offset(-0.02))) == pytest.approx(area, rel=1e-6)
