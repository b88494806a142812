"""The inverse calculation for every family sample and every dimension it can be solved for.

* For each design in ``samples/families/*.toml`` (industry families, custom outline) and
  ``samples/*.toml`` (the thesis's shapes) and each of its dimensions in
  :data:`tabletcad.families.inverse.VARY`, three targets inside the reachable volume range
  (2 %, 50 % and 98 % of the way from its least to its largest volume) are solved; the
  design is then rebuilt from its file with the solved value (``Design.build``, the
  ordinary route, not the solver's own build) and its volume must equal the target to
  1e-9 relative.  Why 1e-9: Brent's method stops within ``xtol`` = 1e-12 mm of the root,
  and the volume changes by at most the plan area (< 10³ mm²) per mm of band, thickness,
  cup depth, height or dome, so the residual is below 1e-9 mm³, under 1e-10 of any volume
  here (> 10 mm³); the volume is a deterministic function of the dimensions (the exact
  nominal volume, Gauss-Legendre to rounding, for the industry families; the PDE
  tablet's own ``Tablet.volume()`` for the thesis's shapes), so the rebuild gives the
  value the solver saw.
* Targets just outside the range are refused (Python: ``DesignError`` naming the target and
  the range; command line: exit 2, one line, the range in it, nothing written).
* The reviewer's four commands, which failed when the search always started at 0.001 mm,
  succeed from the command line.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from tabletcad.cli import main
from tabletcad.errors import DesignError, format_bound
from tabletcad.families.inverse import VARY, reachable, solvable, solve_for
from tabletcad.families.sweep import SweepNominal, nominal_volume
from tabletcad.pipeline.design import Design

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = sorted((ROOT / "samples" / "families").glob("*.toml")) + sorted((ROOT / "samples").glob("*.toml"))
FRACTIONS = (0.02, 0.5, 0.98)
REL = 1e-9


def _api_args(design: Design):
    """``(family, dims)`` for :func:`solve_for`, as ``tabletcad report --solve-for`` forms them."""
    import functools

    from tabletcad.families import outline_tablet

    given = {k: v for k, v in design.tablet.items() if k not in ("family", "name")}
    if design.family == "custom_outline":
        tablet = design.build()
        return functools.partial(outline_tablet, tablet.nominal.outline), \
            {k: v for k, v in tablet.params.items() if k in given}
    return design.family, given


def _cases():
    out = []
    for path in SAMPLES:
        d = Design.from_toml(path)
        if d.family == "free_form" or d.trim is not None or d.reshape is not None:
            continue  # refused by --solve-for (tested below)
        family, dims = _api_args(d)
        for vary in solvable(family):
            if vary in dims:
                out.append(pytest.param(path, vary, id=f"{path.stem}-{vary}"))
    return out


CASES = _cases()


def _volume(tablet) -> float:
    return nominal_volume(tablet.nominal) if isinstance(tablet.nominal, SweepNominal) else float(tablet.volume())


def test_every_sample_family_has_cases():
    names = {c.values[0].stem for c in CASES}
    assert {p.stem for p in SAMPLES} - names == {"free_form_stadium", "spherical", "cutaway_convex_round"}
    assert len(CASES) >= 40


@pytest.mark.slow
@pytest.mark.parametrize("path, vary", CASES)
def test_solved_design_rebuilds_to_the_target_volume(path, vary):
    design = Design.from_toml(path)
    family, dims = _api_args(design)
    reach = reachable(family, vary, **dims)
    assert reach.monotone and reach.lo_mm <= dims[vary] <= reach.hi_mm
    assert reach.exact_nominal == (not design.family.startswith("thesis."))
    for f in FRACTIONS:
        target = reach.volume_lo_mm3 + f * (reach.volume_hi_mm3 - reach.volume_lo_mm3)
        r = solve_for(family, target_volume_mm3=target, vary=vary, **dims)
        assert reach.lo_mm <= r.value <= reach.hi_mm
        assert r.volume_mm3 == pytest.approx(target, rel=REL)
        data = design.to_dict()
        data["tablet"][vary] = r.value
        rebuilt = Design.from_dict(data).build()
        assert _volume(rebuilt) == pytest.approx(target, rel=REL), (f, r.value)


@pytest.mark.parametrize("path, vary", [c for c in CASES if c.id in (
    "ffre-thickness", "capsule-cup_depth", "compound_cup-band", "custom_outline-cup_depth",
    "shallow_convex_round-thickness", "oblong-dome", "caplet-height")])
def test_targets_outside_the_range_are_refused_with_the_range(path, vary):
    design = Design.from_toml(path)
    family, dims = _api_args(design)
    reach = reachable(family, vary, **dims)
    for target in (reach.volume_lo_mm3 * (1 - 1e-4), reach.volume_hi_mm3 * (1 + 1e-4)):
        with pytest.raises(DesignError) as ei:
            solve_for(family, target_volume_mm3=target, vary=vary, **dims)
        assert ei.value.parameter == "target_volume_mm3"
        # (the ends rounded into the range, so that each is accepted)
        assert f"must be within {format_bound(reach.volume_lo_mm3, upper=False)} to " \
               f"{format_bound(reach.volume_hi_mm3, upper=True)} mm3 for {vary} in" in str(ei.value)
    with pytest.raises(DesignError, match=r"must be within .* mg for") as ei:
        solve_for(family, target_weight_mg=reach.volume_hi_mm3 * 2.0, vary=vary, solid_fraction=0.5,
                  true_density_mg_mm3=2.0, **dims)  # 1 mg per mm3: the weight range is the volume range
    assert ei.value.parameter == "target_weight_mg" and f"{format_bound(reach.volume_hi_mm3, upper=True)} mg" \
        in str(ei.value)
    # the stated ends are reached (a lower end at a flat face, 0 mm, is reached only there: the volumes just
    # above it need a length below Tolerances.min_length)
    ends = [format_bound(reach.volume_hi_mm3, upper=True)] + (
        [format_bound(reach.volume_lo_mm3, upper=False)] if reach.lo_mm > 0 else [])
    for end in ends:
        solve_for(family, target_volume_mm3=float(end), vary=vary, **dims)


def test_the_oblong_dome_lowers_the_volume_and_is_still_solved():
    """The one family here whose volume falls as the solved dimension grows."""
    reach = reachable("thesis.oblong", "dome", diameter=5.0, length=15.0)
    v_small = solve_for("thesis.oblong", target_volume_mm3=reach.volume_hi_mm3 * 0.999, vary="dome",
                        diameter=5.0, length=15.0)
    v_large = solve_for("thesis.oblong", target_volume_mm3=reach.volume_lo_mm3 * 1.001, vary="dome",
                        diameter=5.0, length=15.0)
    assert v_small.value < v_large.value


def test_a_family_without_the_dimension_names_what_it_can_solve_for():
    with pytest.raises(DesignError, match=r"thesis.oblate_spheroid can solve for height$") as ei:
        solve_for("thesis.oblate_spheroid", target_volume_mm3=100.0, vary="band")
    assert ei.value.parameter == "vary"
    with pytest.raises(DesignError, match="has none of the dimensions that can be solved for"):
        solve_for("thesis.spherical", target_volume_mm3=100.0, vary="thickness")
    assert solvable("capsule") == ("band", "cup_depth") and solvable("thesis.caplet") == ("band", "height")


def test_the_command_line_offers_every_dimension():
    from tabletcad.cli.report import _SOLVABLE

    assert _SOLVABLE == VARY


# ---------------------------------------------------------------------------- command line
REVIEWER = [
    ("families/ffre.toml", "thickness", 200.0),
    ("families/ffbe.toml", "thickness", 100.0),
    ("families/ffbe.toml", "thickness", 200.0),
    ("families/ffbe.toml", "thickness", 300.0),
    ("families/compound_cup.toml", "cup_depth", 380.0),
    ("families/capsule.toml", "cup_depth", 620.0),
    ("shallow_convex_round.toml", "thickness", 200.0),
]


@pytest.mark.parametrize("sample, vary, target", REVIEWER, ids=[f"{s}-{t:g}" for s, _, t in REVIEWER])
def test_reviewer_commands_succeed(tmp_path, capsys, monkeypatch, sample, vary, target):
    monkeypatch.chdir(tmp_path)
    path = ROOT / "samples" / sample
    assert main(["report", str(path), "--solve-for", vary, "--target-volume", str(target), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    inv = doc["inverse"]
    assert inv["solved_for"] == vary and inv["nominal_volume_mm3"] == pytest.approx(target, rel=REL)
    assert doc["design"]["params"].get(vary, inv["value_mm"]) == pytest.approx(inv["value_mm"], abs=1e-12)
    assert doc["design_report"]["volume_mm3"] == pytest.approx(target, rel=2e-6)  # the PDE surface's own volume
    assert list(tmp_path.iterdir()) == []
    assert main(["report", str(path), "--solve-for", vary, "--target-volume", str(target)]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.startswith(f"{path.stem}: {vary} = ") and f"gives {target:g} mm3" in first


@pytest.mark.parametrize("argv, parameter, text", [
    (["families/ffre.toml", "--solve-for", "thickness", "--target-volume", "5"], "--target-volume",
     r"must be within 73\.\d+ to 50258\.\d+ mm3 for thickness in \[1\.6, 1000\] mm"),
    (["families/capsule.toml", "--solve-for", "cup_depth", "--target-volume", "5000"], "--target-volume",
     r"must be within \S+ to \S+ mm3 for cup_depth in \["),
    (["families/concave_round.toml", "--solve-for", "band", "--target-weight", "1", "--solid-fraction", "0.8",
      "--true-density", "1.4"], "--target-weight", r"must be within \S+ to \S+ mg for band in \[0.001, 998\.2\] mm"),
    (["families/concave_round.toml", "--solve-for", "thickness", "--target-volume", "300"], "--solve-for",
     r"concave_round can solve for band, cup_depth$"),
    (["spherical.toml", "--solve-for", "band", "--target-volume", "300"], "--solve-for",
     "has none of the dimensions that can be solved for"),
    (["free_form_stadium.toml", "--solve-for", "thickness", "--target-volume", "300"], "--solve-for",
     "free_form designs have none"),
    (["cutaway_convex_round.toml", "--solve-for", "band", "--target-volume", "150"], "--solve-for",
     r"the design sets \[trim\]"),
    (["oblong.toml", "--solve-for", "height", "--target-volume", "300"], "--solve-for", r"thesis.oblong can solve for dome$"),
])
def test_bad_solve_requests_are_one_line_exit_2_nothing_written(tmp_path, capsys, monkeypatch, argv, parameter, text):
    monkeypatch.chdir(tmp_path)
    argv = [str(ROOT / "samples" / argv[0]), *argv[1:], "--json-file", str(tmp_path / "r.json"),
            "--csv", str(tmp_path / "r.csv")]
    assert main(["report", *argv]) == 2
    cap = capsys.readouterr()
    assert cap.out == "" and cap.err.splitlines() == [cap.err.strip()]
    assert cap.err.startswith(f"error: {parameter} = ") and "Traceback" not in cap.err
    assert re.search(text, cap.err.strip()), cap.err
    assert list(tmp_path.iterdir()) == []


def test_a_weight_range_is_the_volume_range_times_the_density(capsys):
    reach = reachable("concave_round", "band", diameter=10.0, cup_depth=0.9, land=0.08)
    assert main(["report", str(ROOT / "samples" / "families" / "concave_round.toml"), "--solve-for", "band",
                 "--target-weight", "1", "--solid-fraction", "0.8", "--true-density", "1.4"]) == 2
    err = capsys.readouterr().err
    lo, hi = (float(x) for x in re.search(r"within (\S+) to (\S+) mg", err).groups())
    assert lo == pytest.approx(reach.volume_lo_mm3 * 1.12, rel=1e-5) and hi == pytest.approx(reach.volume_hi_mm3 * 1.12, rel=1e-5)
    # band >= Tolerances.min_length, and the tablet (band and two 0.9 mm cups) at most 1000 mm tall, as a design
    # file allows (the band had reached 1000 mm: a tablet 1001.8 mm tall)
    assert reach.lo_mm == 1e-3 and reach.hi_mm == pytest.approx(1000.0 - 2 * 0.9, abs=1e-5)


def test_a_solved_tablet_keeps_the_size_limit_and_the_stated_ends_are_reached(capsys):
    """A trial: ``--solve-for band --target-weight 100200`` on the 10 mm concave round gave a band of 999.7 mm, a
    tablet 1001.5 mm tall that a design file refuses (exit 0), and the refusal's range "88.337 to 100227 mg"
    refused both its printed ends.  The band now stops where the tablet is 1000 mm tall, and each printed end
    is solved."""
    from tabletcad.pipeline.design import Design

    sample = str(ROOT / "samples" / "families" / "concave_round.toml")
    assert main(["report", sample, "--solve-for", "band", "--target-weight", "100200"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --target-weight = 100200 mg is not allowed: must be within ") and \
        "for band in [0.001, 998.2] mm" in err, err
    lo, hi = re.search(r"within (\S+) to (\S+) mg", err).groups()
    for end in (lo, hi):
        assert main(["report", sample, "--solve-for", "band", "--target-weight", end, "--json"]) == 0
        d = json.loads(capsys.readouterr().out)
        band = d["inverse"]["value_mm"]
        data = Design.from_toml(sample).to_dict()
        data["tablet"]["band"] = band
        t = Design.from_dict(data).build()  # a design file takes it: within the size limit
        b_lo, b_hi = t.bounds()
        assert b_hi[2] - b_lo[2] <= 1000.0 * (1 + 1e-9)


def test_a_solved_length_is_one_a_design_file_accepts(tmp_path):
    """The band of a concave round approaches 0 but a design file takes 0 or at least
    ``Tolerances.min_length`` (1 µm): a volume reached only by a thinner band is out of reach
    (it gave band = 1.393e-06 mm, which the written design could not build again); the least
    band's volume is reached exactly."""
    from tabletcad.errors import DesignError
    from tabletcad.families.inverse import solve_for
    from tabletcad.pipeline.design import Design

    dims = dict(diameter=10.0, cup_depth=0.9, land=0.08)
    reach = reachable("concave_round", "band", **dims)
    with pytest.raises(DesignError, match=r"\[0.001, 998\.2\] mm"):
        solve_for("concave_round", vary="band", target_volume_mm3=69.2055, **dims)
    band = solve_for("concave_round", vary="band", target_volume_mm3=reach.volume_lo_mm3 * (1 + 1e-6), **dims).value
    assert 1e-3 <= band < 2e-3
    p = tmp_path / "d.toml"
    p.write_text(f'[tablet]\nfamily = "concave_round"\ndiameter = 10.0\ncup_depth = 0.9\nland = 0.08\nband = {band!r}\n')
    assert Design.from_toml(p).build().params["band"] == band


def test_a_flat_face_stays_reachable_and_a_root_below_the_least_length_is_refused():
    """An oval's cup depth builds at 0 (a flat face) and from Tolerances.min_length up: its interval keeps 0,
    the flat design's volume is solved to 0 exactly, and a volume only reached between 0 and 1 µm is refused."""
    from tabletcad.errors import DesignError
    from tabletcad.families.inverse import solve_for

    dims = dict(length=14.0, width=8.0, end_radius=3.0, band=3.0)
    r = reachable("oval", vary="cup_depth", **dims)
    assert r.lo_mm == 0.0 and r.hi_mm == 3.0
    assert solve_for("oval", vary="cup_depth", target_volume_mm3=r.volume_lo_mm3, **dims).value == 0.0
    with pytest.raises(DesignError, match="reached only with cup_depth = .* mm, which a design file refuses"):
        solve_for("oval", vary="cup_depth", target_volume_mm3=r.volume_lo_mm3 + 1e-4, **dims)
