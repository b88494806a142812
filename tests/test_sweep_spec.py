"""Sweep files: sampling (grid order, Latin hypercube strata), design hashes, and bad files.

Bad sweep files and options end with one ``error:`` line and exit status 2
before any design is built: no output folder is created.
"""

from __future__ import annotations

import itertools
import socket
import textwrap

import numpy as np
import pytest

pytestmark = pytest.mark.sweep
pytest.importorskip("distributed")
pytest.importorskip("pandas")

from tabletcad.cli import main  # noqa: E402
from tabletcad.errors import DesignError  # noqa: E402
from tabletcad.sweep import design_hash, parse_sweep  # noqa: E402
from tabletcad.sweep.engine import flatten_report  # noqa: E402

BASE = {"tablet": {"family": "concave_round", "diameter": 10.0, "band": 2.8, "cup_depth": 0.9, "land": 0.08}}


def test_grid_is_the_product_in_file_order_with_inclusive_ranges():
    spec = parse_sweep({"design": BASE, "sweep": {"vary": {
        "tablet.cup_depth": {"min": 0.5, "max": 1.1, "num": 4}, "tablet.band": [3.0, 2.0, 2.5]}}})
    assert spec.keys == ("tablet.cup_depth", "tablet.band")
    depths = [0.5, 0.7, 0.9, 1.1]  # linspace rounded to 12 digits (not 0.7000000000000001)
    assert spec.points() == list(itertools.product(depths, [3.0, 2.0, 2.5]))
    assert spec.points()[0][0] == 0.5 and spec.points()[-1][0] == 1.1
    designs = spec.designs()
    assert len(designs) == 12
    assert designs[5]["tablet"] == {**BASE["tablet"], "cup_depth": depths[1], "band": 2.5}
    assert BASE["tablet"]["cup_depth"] == 0.9  # the base design is not modified
    assert spec.outputs == ("report",)


@pytest.mark.parametrize("n", [1, 7, 50])
def test_latin_hypercube_fills_every_stratum_once_and_repeats_with_its_seed(n):
    sw = {"method": "lhs", "samples": n, "seed": 3,
          "vary": {"tablet.cup_depth": {"min": 0.5, "max": 1.5}, "tablet.band": {"min": 2.0, "max": 4.0},
                   "tablet.diameter": [8.0, 9.0, 10.0, 11.0, 12.0]}}
    spec = parse_sweep({"design": BASE, "sweep": sw})
    pts = np.array(spec.points())
    assert pts.shape == (n, 3)
    for j, (lo, hi) in enumerate([(0.5, 1.5), (2.0, 4.0)]):
        strata = np.floor((pts[:, j] - lo) / (hi - lo) * n).astype(int)
        assert sorted(strata) == list(range(n))  # the Latin property: one sample per stratum
    assert set(pts[:, 2]) <= {8.0, 9.0, 10.0, 11.0, 12.0}
    assert spec.points() == parse_sweep({"design": BASE, "sweep": sw}).points()
    other = parse_sweep({"design": BASE, "sweep": {**sw, "seed": 4}}).points()
    assert (other != spec.points()) or n == 1


def test_design_hash_is_stable_and_tells_designs_apart():
    a = {"tablet": {"family": "concave_round", "cup_depth": 0.9, "band": 2.8}}
    b = {"tablet": {"band": 2.8, "cup_depth": 0.9, "family": "concave_round"}}
    assert design_hash(a) == design_hash(b)  # key order does not matter
    assert design_hash(a) != design_hash({"tablet": {**a["tablet"], "cup_depth": 0.9000000000000001}})
    assert len(design_hash(a)) == 16 and int(design_hash(a), 16) >= 0


def test_flatten_report_keeps_scalars_under_dotted_names():
    rep = {"v": 1.5, "ok": True, "name": "x", "none": None, "list": [1, 2],
           "sec": {"w": np.float64(2.0), "deep": {"n": np.int64(3)}, "pts": [[0, 1]]}}
    flat = flatten_report(rep)
    assert flat == {"v": 1.5, "ok": True, "name": "x", "none": None, "sec.w": 2.0, "sec.deep.n": 3}
    assert type(flat["sec.w"]) is float and type(flat["sec.deep.n"]) is int


def _write(tmp_path, body: str):
    p = tmp_path / "s.toml"
    p.write_text(textwrap.dedent("""
        [design.tablet]
        family = "concave_round"
        diameter = 10.0
        band = 2.8
        cup_depth = 0.9
        """) + textwrap.dedent(body), encoding="utf-8")
    return p


BAD = {
    "unknown key": ('[sweep.vary]\n"tablet.cup_dept" = [0.8, 0.9]\n', "sweep.vary.key = 'tablet.cup_dept'"),
    "unknown table": ('[sweep.vary]\n"tooling.clearance_mm" = [0.01]\n', "'tooling.clearance_mm'"),
    "empty list": ('[sweep.vary]\n"tablet.cup_depth" = []\n', "an empty list sweeps nothing"),
    "empty range": ('[sweep.vary]\n"tablet.cup_depth" = { min = 1.0, max = 0.5, num = 3 }\n', "the range is empty"),
    "num zero": ('[sweep.vary]\n"tablet.cup_depth" = { min = 0.5, max = 1.0, num = 0 }\n', "num = 0 is not allowed"),
    "num negative": ('[sweep.vary]\n"tablet.cup_depth" = { min = 0.5, max = 1.0, num = -2 }\n', "num = -2 is not allowed"),
    "num missing": ('[sweep.vary]\n"tablet.cup_depth" = { min = 0.5, max = 1.0 }\n', "num = (not given)"),
    "samples without seed": ('[sweep]\nmethod = "lhs"\nsamples = 10\n[sweep.vary]\n"tablet.cup_depth" = { min = 0.5, max = 1.0 }\n',
                             "sweep.seed = (not given)"),
    "samples zero": ('[sweep]\nmethod = "lhs"\nsamples = 0\nseed = 1\n[sweep.vary]\n"tablet.cup_depth" = { min = 0.5, max = 1.0 }\n',
                     "sweep.samples = 0"),
    "unknown method": ('[sweep]\nmethod = "random"\n[sweep.vary]\n"tablet.cup_depth" = [0.8]\n', "sweep.method = 'random'"),
    "unknown output": ('[sweep]\noutputs = ["iges"]\n[sweep.vary]\n"tablet.cup_depth" = [0.8]\n', "sweep.outputs = 'iges'"),
    "no vary": ("[sweep]\n", "sweep.vary = (not given)"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_sweep_file_is_one_line_exit_2_and_writes_nothing(tmp_path, capsys, case):
    body, expected = BAD[case]
    p = _write(tmp_path, body)
    out = tmp_path / "out"
    assert main(["sweep", str(p), "--out", str(out), "--workers", "1", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and "is not allowed" in err[0]
    assert expected in err[0]
    assert not out.exists()


def test_unreachable_scheduler_is_one_line_exit_2_after_the_connect_timeout(tmp_path, capsys):
    p = _write(tmp_path, '[sweep.vary]\n"tablet.cup_depth" = [0.8, 0.9]\n')
    with socket.socket() as s:  # a port nothing listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    out = tmp_path / "out"
    code = main(["sweep", str(p), "--out", str(out), "--scheduler", f"tcp://127.0.0.1:{port}",
                 "--connect-timeout", "2", "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and err[0].startswith(f"error: --scheduler = 'tcp://127.0.0.1:{port}' is not allowed: "
                                               "no Dask scheduler answered within 2 s")
    assert not out.exists()


@pytest.mark.parametrize("args, expected", [
    (["--workers", "0"], "--workers = 0 is not allowed"),
    (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "give either --workers or --scheduler"),
    # a trial: 100000 was taken (a typo would have started one worker of ~340 MB per design)
    (["--workers", "100000"], "error: --workers = 100000 is not allowed: must be at most "
                              f"{4 * (__import__('os').cpu_count() or 1)} (4 per CPU of this machine"),
])
def test_bad_engine_options(tmp_path, capsys, args, expected):
    p = _write(tmp_path, '[sweep.vary]\n"tablet.cup_depth" = [0.8]\n')
    out = tmp_path / "out"
    assert main(["sweep", str(p), "--out", str(out), "--quiet", *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and expected in err[0]
    assert not out.exists()


def test_an_earlier_results_csv_needs_resume(tmp_path, capsys):
    p = _write(tmp_path, '[sweep.vary]\n"tablet.cup_depth" = [0.8]\n')
    out = tmp_path / "out"
    out.mkdir()
    (out / "results.csv").write_text("tablet.cup_depth,status,error,design_hash\n0.8,ok,,0000000000000000\n")
    assert main(["sweep", str(p), "--out", str(out), "--workers", "1", "--quiet"]) == 2
    assert "give --resume to go on with that sweep, or another folder" in capsys.readouterr().err
    assert main(["sweep", str(p), "--out", str(out), "--workers", "1", "--quiet", "--resume"]) == 2
    assert "1 designs that are not in this sweep file" in capsys.readouterr().err
    assert sorted(q.name for q in out.iterdir()) == ["results.csv"]


def test_sample_sweep_files():
    from pathlib import Path

    from tabletcad.sweep import load_sweep

    root = Path(__file__).resolve().parents[1] / "samples" / "sweep"
    grid = load_sweep(root / "concave_round_grid.toml")
    assert grid.keys == ("tablet.cup_depth", "tablet.band") and len(grid.designs()) == 6
    assert grid.points()[1] == (0.6, 3.2) and grid.points()[2] == (0.9, 2.4)
    lhs = load_sweep(root / "concave_round_lhs.toml")
    pts = np.array(lhs.points())
    assert pts.shape == (40, 3) and pts[:, 0].min() >= 8.0 and pts[:, 0].max() < 12.0
    assert sorted(np.floor((pts[:, 2] - 0.5) / 0.9 * 40).astype(int)) == list(range(40))
    assert len({design_hash(d) for d in lhs.designs()}) == 40


def test_a_sweep_of_more_than_a_million_designs_is_refused_up_front():
    """Two axes of 1e8 values each filled the memory (1.2 GB after 25 s) before any design was built."""
    from tabletcad.errors import DesignError
    from tabletcad.sweep import parse_sweep

    design = {"tablet": {"family": "concave_round", "diameter": 10.0, "band": 2.8, "cup_depth": 0.9}}

    def sweep(vary, **sw):
        return parse_sweep({"design": design, "sweep": {"vary": vary, **sw}})

    with pytest.raises(DesignError, match="num = 100000000 is not allowed: must be an integer from 1 to 1,000,000"):
        sweep({"tablet.band": {"min": 2.0, "max": 3.0, "num": 100_000_000}})
    with pytest.raises(DesignError, match=r"'1000 x 1001' is not allowed: must give at most 1,000,000"):
        sweep({"tablet.band": {"min": 2.0, "max": 3.0, "num": 1000}, "tablet.cup_depth": {"min": 0.5, "max": 1.0, "num": 1001}})
    with pytest.raises(DesignError, match="samples"):
        sweep({"tablet.band": {"min": 2.0, "max": 3.0}}, method="lhs", samples=10**9, seed=1)
    assert len(sweep({"tablet.band": {"min": 2.0, "max": 3.0, "num": 1000},
                      "tablet.cup_depth": {"min": 0.5, "max": 1.0, "num": 1000}}).points()) == 1_000_000


@pytest.mark.parametrize("land, line", [
    (-0.08, "error: design.tablet.land = -0.08 mm is not allowed: must be >= 0 (a length of concave_round; the sweep "
            "does not vary it, so every design would be refused)"),
    ("0.08", "error: design.tablet.land = '0.08' is not allowed: must be a number"),
    (1e-9, "error: design.tablet.land = 1e-09 mm is not allowed: must be 0 or at least"),
    (2e3, "error: design.tablet.land = 2000 mm is not allowed: must be within ±1000 mm"),
])
def test_a_fixed_dimension_no_design_could_take_is_refused_before_the_sweep(tmp_path, capsys, land, line):
    """A base dimension the sweep does not vary, wrong whatever the varied values are, would fail every
    row: refused up front (one line, exit 2, no folder)."""
    _refused_up_front(tmp_path, capsys, f'land = {land!r}\n'.replace("'", '"'), line)


@pytest.mark.parametrize("a", [2.0, 0.0, -1.0])
def test_a_fixed_smoothing_parameter_outside_its_range_is_refused_before_the_sweep(tmp_path, capsys, a):
    """A new user's fixed ``a = 2``: every design had failed on it (exit 0, "0 ok, 3 failed")."""
    _refused_up_front(tmp_path, capsys, f"a = {a!r}\n", f"error: design.tablet.a = {a:g} is not allowed: must be > 0 "
                      "and <= 1")


def test_a_thesis_shapes_fixed_smoothing_parameter_is_read_as_its_patches_read_it():
    """The (0, 1] range is the industry families' (tabletcad.families.round.smoothing); a thesis shape's patches
    take any a > 0 (``build`` makes the sphere at a = 1.5, 5.015 mm across), so its sweep is not refused up front
    (it had been: "every row would fail"), and a = 0 still is."""
    from tabletcad.errors import DesignError

    def sweep(a):
        return parse_sweep({"design": {"tablet": {"family": "thesis.spherical", "diameter": 5.0, "a": a}},
                            "sweep": {"vary": {"tablet.diameter": [5.0, 6.0]}}})

    assert len(sweep(1.5).points()) == 2
    with pytest.raises(DesignError, match=r"^design.tablet.a = 0 is not allowed: must be > 0$"):
        sweep(0.0)


def _refused_up_front(tmp_path, capsys, body: str, line: str) -> None:
    """The sample base with ``body`` added and its cup depth varied: one line starting ``line``, exit 2,
    no output folder."""
    p = _write(tmp_path, body + '[sweep.vary]\n"tablet.cup_depth" = [0.8, 0.9]\n')
    out = tmp_path / "out"
    assert main(["sweep", str(p), "--out", str(out), "--workers", "1", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(line), err
    assert not out.exists()


@pytest.mark.parametrize("vary, line", [
    ("{ min = 0.6, max = 1e300, num = 2 }", 'error: sweep.vary."tablet.cup_depth".max = 1e+300 mm is not allowed: '
                                           "must be within ±1000 mm (size limit"),
    ("{ min = -2000.0, max = 1.0, num = 3 }", 'error: sweep.vary."tablet.cup_depth".min = -2000 mm is not allowed: '
                                             "must be within ±1000 mm"),
    ("[0.6, 1e300]", 'error: sweep.vary."tablet.cup_depth" = 1e+300 mm is not allowed: must be within ±1000 mm'),
])
def test_a_varied_length_beyond_the_size_limit_is_refused_before_the_sweep(tmp_path, capsys, vary, line):
    """A new user's range ``max = 1e300`` (a trial): its design failed as a row, exit 0; a length beyond
    ±1000 mm is refused by every design reader, so up front here (one line, exit 2, no folder), named as
    the file has it."""
    p = _write(tmp_path, f'[sweep.vary]\n"tablet.cup_depth" = {vary}\n')
    out = tmp_path / "out"
    assert main(["sweep", str(p), "--out", str(out), "--workers", "1", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(line), err
    assert not out.exists()
    lhs = {"tablet.cup_depth": {"min": 0.5, "max": 1e300}}
    with pytest.raises(DesignError, match="must be within ±1000 mm"):
        parse_sweep({"design": BASE, "sweep": {"method": "lhs", "samples": 4, "seed": 1, "vary": lhs}})


def test_a_dimension_wrong_only_with_the_varied_values_or_varied_itself_is_left_to_the_rows():
    """Valid alone, too wide for some varied cups (land 4.5 on a 10 mm round), or varied: not refused."""
    base = {"tablet": {**BASE["tablet"], "land": 4.5}}
    assert len(parse_sweep({"design": base, "sweep": {"vary": {"tablet.cup_depth": [0.1, 0.9]}}}).designs()) == 2
    base = {"tablet": {**BASE["tablet"], "land": -0.08}}
    spec = parse_sweep({"design": base, "sweep": {"vary": {"tablet.land": [-0.08, 0.08]}}})
    assert [d["tablet"]["land"] for d in spec.designs()] == [-0.08, 0.08]


@pytest.mark.parametrize("table, line", [
    ("[design.report]\nweigth = 1\n", "error: design.report.weigth = 1 is not allowed: allowed keys are solid_fraction"),
    ("[design.report]\nsolid_fraction = 1.5\ntrue_density_mg_mm3 = 1.5\n",
     "error: design.report.solid_fraction = 1.5 is not allowed: must be > 0 and <= 1"),
    ("[design.tooling]\nclearance_mm = -1\n", "error: design.tooling.clearance_mm = -1 mm is not allowed: must be >= 0"),
])
def test_a_fixed_report_or_tooling_value_no_design_could_take_is_refused_before_the_sweep(tmp_path, capsys, table, line):
    """A ``[design.report]`` or ``[design.tooling]`` key the sweep does not vary, wrong in every design
    (a misspelled key, a solid fraction of 1.5): one line, exit 2, no folder (every row had failed, exit 0)."""
    _refused_up_front(tmp_path, capsys, table, line)


def test_a_report_value_the_sweep_varies_is_left_to_its_rows():
    base = {"tablet": BASE["tablet"], "report": {"solid_fraction": 1.5, "true_density_mg_mm3": 1.5}}
    spec = parse_sweep({"design": base, "sweep": {"vary": {"report.solid_fraction": [0.8, 1.5]}}})
    assert [d["report"]["solid_fraction"] for d in spec.designs()] == [0.8, 1.5]
    spec = parse_sweep({"design": base, "sweep": {"vary": {"report.solid_fraction": [1.5, 0.8]}}})
    assert len(spec.designs()) == 2


def test_a_table_the_sweep_varies_is_read_by_its_rows_whatever_the_order():
    """A tooling standard varied between a standard set and "custom" (which needs its own sizes): the
    first value does not decide for the whole sweep (it had refused ["custom", "EU"] and taken ["EU", "custom"])."""
    import tomllib
    from pathlib import Path

    sample = Path(__file__).resolve().parents[1] / "samples" / "tooling" / "eu_d_oval.toml"
    design = tomllib.loads(sample.read_text())
    for order in (["EU", "custom"], ["custom", "EU"]):
        spec = parse_sweep({"design": design, "sweep": {"vary": {"tooling.standard": order}}})
        assert [d["tooling"]["standard"] for d in spec.designs()] == order


@pytest.mark.parametrize("tablet, varied, expected", [
    # a trial: each of these ran, every row an error, and the sweep exited 0
    ({**BASE["tablet"], "family": "concave_rund"}, "tablet.band",
     "error: design.tablet.family = 'concave_rund' is not allowed: must be one of flat_face_round, "),
    ({**BASE["tablet"], "family": 7}, "tablet.band", "error: design.tablet.family = 7 is not allowed: must be one of "),
    ({k: v for k, v in BASE["tablet"].items() if k != "family"}, "tablet.band",
     "error: design.tablet.family = (not given) is not allowed: must name the tablet's family"),
    ({k: v for k, v in BASE["tablet"].items() if k != "cup_depth"}, "tablet.diameter",
     "error: design.tablet.cup_depth = (not given) is not allowed: family 'concave_round' needs diameter, band, "
     "cup_depth: give it in [design.tablet] or vary it (every design would be refused)"),
    # a misspelt key is named first (it is why the dimension is missing)
    ({**{k: v for k, v in BASE["tablet"].items() if k != "cup_depth"}, "cup_dept": 0.9}, "tablet.band",
     "error: design.tablet.cup_dept = 0.9 is not allowed: family 'concave_round' takes "),
    (dict(family="ffbe", thickness=3.0, bevel_angle=30.0), "tablet.diameter",
     "error: design.tablet.bevel_width = (not given) is not allowed: family 'ffbe' needs diameter, thickness, "
     "bevel_angle, bevel_width (or bevel_depth): "),
])
def test_a_family_or_dimension_every_row_lacks_is_refused_before_the_sweep(tmp_path, capsys, tablet, varied, expected):
    import tomllib

    from tabletcad.pipeline.design import toml_text

    p = tmp_path / "s.toml"
    p.write_text(toml_text({"design": {"tablet": tablet}, "sweep": {"vary": {varied: [9.0, 10.0]}}}), encoding="utf-8")
    assert tomllib.loads(p.read_text())["design"]["tablet"] == tablet
    out = tmp_path / "out"
    assert main(["sweep", str(p), "--out", str(out), "--workers", "1", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(expected), err
    assert not out.exists()
    # what the rows may take: the family varied, a dimension varied, a ffbe by its bevel depth
    for ok in ({"design": {"tablet": {**BASE["tablet"], "family": "concave_round"}},
                "sweep": {"vary": {"tablet.family": ["concave_round", "concave_rund"]}}},
               {"design": {"tablet": {k: v for k, v in BASE["tablet"].items() if k != "cup_depth"}},
                "sweep": {"vary": {"tablet.cup_depth": [0.8, 0.9]}}},
               {"design": {"tablet": dict(family="ffbe", thickness=3.0, bevel_angle=30.0, bevel_depth=0.3)},
                "sweep": {"vary": {"tablet.diameter": [9.0, 10.0]}}}):
        assert len(parse_sweep(ok).designs()) == 2
