"""A second new user's trial (session 22) of the FE, sweep and optimise commands: values that crashed
(exit 1), ran out of memory or stalled, and names that were not the file's keys or the options given.

Each case: the exact one-line error, exit status 2, nothing written.  The checks run before any mesh
or solve, so each case takes milliseconds."""

from __future__ import annotations

import pytest

pytest.importorskip("skfem")
pytest.importorskip("gmsh")

from tabletcad.cli import main  # noqa: E402

pytestmark = [pytest.mark.fe, pytest.mark.sweep]

DISC = '[tablet]\nfamily = "flat_face_round"\ndiameter = 10.0\nthickness = 1.0\n'


@pytest.mark.parametrize("args, line", [
    (["--force", "1e308"], "error: --force = 1e+308 N is not allowed: must be >= 1e-06 and <= 1e+09 N"),
    (["--force", "100", "--E", "1e308"], "error: --E = 1e+308 MPa is not allowed: must be >= 0.001 and <= 1e+07 MPa"),
    (["--force", "100", "--mesh-size", "1e200"], "error: --mesh-size = 1e+200 mm is not allowed: must be > 0 and <= 10 mm"),
    (["--force", "100", "--strip-width", "1e-300"],
     "error: --strip-width = 1e-300 mm is not allowed: must be >= 0.001 mm (Tolerances.min_length)"),
    (["--force", "100", "--nu", "0.4999"],  # stalled the direct solve for minutes
     "error: --nu = 0.4999 is not allowed: must be >= -0.9 and <= 0.49 (towards 0.5 the quadratic tetrahedra's "
     "system becomes singular)"),
    (["--force", "100", "--mesh-size", "0.121"],  # 1.5 million unknowns ran out of 22 GB
     "error: --mesh-size = 0.121 mm is not allowed: must be >= 0.236 mm for this solid (about 1.49e+06 unknowns; "
     "at most 2e+05 fit in memory)"),
])
def test_fe_diametral_refuses_what_it_cannot_solve(tmp_path, capsys, args, line):
    d = tmp_path / "disc.toml"
    d.write_text(DISC)
    rc = main(["fe", "diametral", str(d), *args, "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and err == [line]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["disc.toml"]


@pytest.mark.parametrize("args, line", [
    (["--reference-force", "80", "--reference-diameter", "8", "--reference-thickness", "0.0005"],
     "error: --reference-thickness = 0.0005 mm is not allowed: must be >= 0.001 and <= 1000 mm"),
    (["--tensile-strength", "1e308"], "error: --tensile-strength = 1e+308 MPa is not allowed: must be > 0 and <= 1000 MPa"),
    # a strength in pascals had been taken (an FE breaking force of 1.3e8 N)
    (["--tensile-strength", "2e6"], "error: --tensile-strength = 2e+06 MPa is not allowed: must be > 0 and <= 1000 MPa"),
])
def test_fe_strength_names_the_reference_options(tmp_path, capsys, args, line):
    d = tmp_path / "disc.toml"
    d.write_text(DISC)
    rc = main(["fe", "strength", str(d), *args, "--coarse"])
    assert rc == 2 and capsys.readouterr().err.strip().splitlines() == [line]


@pytest.mark.parametrize("E", ["210", "1e300"])
def test_fe_punch_takes_a_punch_steels_modulus(tmp_path, capsys, E):
    """``--E 210`` (210 GPa typed as MPa) had been taken, rating the tip's buckling a thousand times too low,
    and 1e300 too: the range is [tooling] punch_youngs_modulus_MPa's, refused before the design is read."""
    from pathlib import Path

    sample = Path(__file__).resolve().parents[1] / "samples" / "tooling" / "tsm_b_round.toml"
    rc = main(["fe", "punch", str(sample), "--force", "10", "--steel", "S7_tempered_205C", "--E", E,
               "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and err == [f"error: --E = {float(E):g} MPa is not allowed: must be >= 50000 and <= 1e+07 MPa"]
    assert list(tmp_path.iterdir()) == []


def test_fe_on_a_cut_away_is_bad_input_not_a_geometry_failure(tmp_path, capsys):
    from pathlib import Path

    sample = Path(__file__).resolve().parents[1] / "samples" / "cutaway_convex_round.toml"
    rc = main(["fe", "diametral", str(sample), "--force", "100"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and err[0].startswith("error: trim.v = [1.5707963267948966, 6.283185307179586] is "
                                                            "not allowed: the diametral test needs the whole tablet")


SWEEP = '[design.tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 2.8\ncup_depth = 0.9\n{extra}\n[sweep.vary]\n{vary}\n'


@pytest.mark.parametrize("extra, vary, line", [
    ('colour = "red"', '"tablet.diameter" = [8.0, 10.0]',  # every row failed, exit 0
     "error: design.tablet.colour = 'red' is not allowed: family 'concave_round' takes diameter, band, cup_depth, land"),
    ("", '"tablet.diameter" = ["a", "b"]', "error: sweep.vary.\"tablet.diameter\" = 'a' is not allowed: must be a finite number"),
    ("", '"tablet.diameter" = { min = -1.7e308, max = 1.7e308, num = 3 }',  # inf and nan values
     'error: sweep.vary."tablet.diameter".max = 1.7e+308 is not allowed: the range\'s width from min = -1.7e+308 must '
     "be a finite number"),
])
def test_sweep_files_every_row_of_which_would_fail(tmp_path, capsys, extra, vary, line):
    f = tmp_path / "s.toml"
    f.write_text(SWEEP.format(extra=extra, vary=vary))
    rc = main(["sweep", str(f), "--out", str(tmp_path / "out"), "--workers", "1"])
    assert rc == 2 and capsys.readouterr().err.strip().splitlines() == [line]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_sweep_connect_timeout_must_be_finite(tmp_path, capsys):
    from pathlib import Path

    sample = Path(__file__).resolve().parents[1] / "samples" / "sweep" / "concave_round_grid.toml"
    rc = main(["sweep", str(sample), "--out", str(tmp_path / "o"), "--scheduler", "tcp://127.0.0.1:1",
               "--connect-timeout", "inf"])
    assert rc == 2 and capsys.readouterr().err.strip().splitlines() == [
        "error: --connect-timeout = inf s is not allowed: must be > 0 and <= 3600"]


PROBLEM = """[problem]
kind = "family"
family = "flat_face_round"
sense = "min"
objective = "surface_area_mm2"
[variables]
diameter = {{ lower = {lo}, upper = {hi}, initial = 10.0 }}
thickness = {{ lower = 1.0, upper = 10.0, initial = 3.0 }}
[[constraint]]
quantity = "volume_mm3"
{constraint}
"""


@pytest.mark.parametrize("lo, hi, constraint, line", [
    (14.0, 4.0, "target = 235.0", "error: variables.diameter.upper = 4 mm is not allowed: must be >= lower = 14"),
    (4.0, 14.0, "target = 235.0\nlower = 1.0",
     "error: constraint[0] = 'lower/upper' is not allowed: an equality constraint takes only a target"),
])
def test_optimise_names_the_file_s_keys(tmp_path, capsys, lo, hi, constraint, line):
    f = tmp_path / "p.toml"
    f.write_text(PROBLEM.format(lo=lo, hi=hi, constraint=constraint))
    rc = main(["optimise", str(f), "--out", str(tmp_path / "out"), "--quiet"])
    assert rc == 2 and capsys.readouterr().err.strip().splitlines() == [line]


def test_fe_out_owns_exactly_the_files_it_writes(tmp_path, capsys):
    """``fe diametral --out`` overwrote a user's ``stress.vtu``; now refused before the solve, and a
    rerun replaces only what the earlier run wrote (its manifest)."""
    d = tmp_path / "disc.toml"
    d.write_text(DISC)
    out = tmp_path / "out"
    out.mkdir()
    (out / "stress.vtu").write_text("mine")
    args = ["fe", "diametral", str(d), "--force", "100", "--mesh-size", "1.0", "--no-error-estimate", "--out", str(out)]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"error: --out = '{out}' is not allowed: must not hold files this run "
                                               "writes that no earlier tabletcad fe run wrote there")
    assert (out / "stress.vtu").read_text() == "mine" and sorted(p.name for p in out.iterdir()) == ["stress.vtu"]
    (out / "stress.vtu").unlink()
    (out / "notes.txt").write_text("also mine")
    for _ in range(2):  # the second run replaces the first's files
        assert main(args) == 0
        capsys.readouterr()
        assert sorted(p.name for p in out.iterdir()) == [".tabletcad-fe.json", "notes.txt", "section.png", "stress.vtu"]
    assert (out / "notes.txt").read_text() == "also mine"


def test_a_sweep_does_not_take_a_folder_s_other_files_for_its_own(tmp_path, capsys):
    """``--resume`` deleted a user's ``results.partial.jsonl`` ("mine"), and a first run overwrote a
    ``plot_<column>.png`` it had not written; both refused now, the files left as they were."""
    from pathlib import Path

    sample = Path(__file__).resolve().parents[1] / "samples" / "sweep" / "concave_round_grid.toml"
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir(), b.mkdir()
    (a / "results.partial.jsonl").write_text("mine\n")
    (b / "plot_volume_mm3.png").write_text("mine")
    assert main(["sweep", str(sample), "--out", str(a), "--workers", "1", "--resume"]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        f"error: --out = '{a}' is not allowed: holds a results.partial.jsonl that no sweep wrote (line 1); move it "
        "or write into another folder"]
    assert main(["sweep", str(sample), "--out", str(b), "--workers", "1", "--plot", "volume_mm3"]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        f"error: --out = '{b}' is not allowed: must not hold files this sweep writes that no earlier run of it wrote "
        "(plot_volume_mm3.png): move them or write into another folder"]
    assert [p.read_text() for p in (a / "results.partial.jsonl", b / "plot_volume_mm3.png")] == ["mine\n", "mine"]
    assert sorted(p.name for p in a.iterdir()) == ["results.partial.jsonl"]
    assert sorted(p.name for p in b.iterdir()) == ["plot_volume_mm3.png"]


@pytest.mark.parametrize("address", ["notaurl", "", "tcp://", "http://127.0.0.1:1", "inproc://x", "tcp://127.0.0.1:99999"])
def test_a_malformed_scheduler_address_is_refused_before_connecting(tmp_path, capsys, monkeypatch, address):
    """These waited twice the connect timeout and printed a traceback of Dask's half-made client:
    now no client is made."""
    from pathlib import Path

    import distributed

    from tabletcad.parallel import check_scheduler_address

    check_scheduler_address("tcp://127.0.0.1:8786"), check_scheduler_address("[::1]:8786")  # well formed
    monkeypatch.setattr(distributed, "Client", lambda *a, **k: pytest.fail("a client was made"))
    sample = Path(__file__).resolve().parents[1] / "samples" / "sweep" / "concave_round_grid.toml"
    rc = main(["sweep", str(sample), "--out", str(tmp_path / "o"), "--scheduler", address])
    assert rc == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        f"error: --scheduler = {address!r} is not allowed: must be a Dask scheduler address: [tcp://]host:port "
        "(or tls://, ws://, wss://), the port from 1 to 65535"]
    assert not (tmp_path / "o").exists()


def test_an_output_that_cannot_be_written_is_named_as_its_option(capsys):
    """``path = '/proc/.x.57zqaxab.json'`` named a temporary file, not the option; refused before any work
    (a folder that takes no file: probed, as os.access says yes to root)."""
    from pathlib import Path

    assert main(["shapes", "--json-file", "/proc/x.json"]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        "error: --json-file = '/proc/x.json' is not allowed: cannot be written: folder /proc is not writable"]
    sample = Path(__file__).resolve().parents[1] / "samples" / "sweep" / "concave_round_grid.toml"
    assert main(["sweep", str(sample), "--out", "/proc/sweep", "--workers", "1"]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        "error: --out = '/proc/sweep' is not allowed: cannot be written: folder /proc is not writable"]


@pytest.mark.parametrize("store, allowed", [
    ("afile", "must be a folder: {tmp}/afile is a file"),
    ("nosuchproto://x", "must be a folder or an fsspec URL (Protocol not known: nosuchproto)"),
])
def test_a_store_no_worker_could_write_is_refused(tmp_path, capsys, monkeypatch, store, allowed):
    """Every row had failed (NotADirectoryError, Protocol not known) with exit 0."""
    from pathlib import Path

    monkeypatch.chdir(tmp_path)
    (tmp_path / "afile").write_text("x")
    sample = Path(__file__).resolve().parents[1] / "samples" / "sweep" / "concave_round_grid.toml"
    assert main(["sweep", str(sample), "--out", str(tmp_path / "o"), "--workers", "1", "--store", store]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        f"error: --store = {store!r} is not allowed: " + allowed.format(tmp=tmp_path)]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]


def test_fe_diametral_names_what_makes_a_tablet_hollow(tmp_path, capsys):
    """A thesis ring was refused as "trim.w = [0.5, 1.0]", a table its design file does not have."""
    from pathlib import Path

    ring = Path(__file__).resolve().parents[1] / "samples" / "ring.toml"
    rc = main(["fe", "diametral", str(ring), "--force", "100", "--out", str(tmp_path / "out")])
    assert rc == 2 and capsys.readouterr().err.splitlines() == [
        "error: tablet.inner_diameter = 6 mm is not allowed: a hollow tablet (a ring) is not supported by the diametral "
        "FE test, which loads solid tablets only"]
    d = tmp_path / "shell.toml"
    d.write_text(DISC + "[trim]\nw = [0.5, 1.0]\n")
    rc = main(["fe", "diametral", str(d), "--force", "100", "--out", str(tmp_path / "out")])
    assert rc == 2 and capsys.readouterr().err.splitlines() == [
        "error: trim.w = [0.5, 1.0] is not allowed: a hollow tablet (w from above 0) is not supported by the diametral "
        "FE test, which loads solid tablets only: remove [trim] w or start it at 0"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["shell.toml"]


def test_fe_diametral_says_a_default_mesh_size_is_the_default(tmp_path, capsys):
    """A 0.001 mm thin disc was refused as "--mesh-size = 0.0005 mm", a value the user never gave."""
    d = tmp_path / "thin.toml"
    d.write_text('[tablet]\nfamily = "flat_face_round"\ndiameter = 10.0\nthickness = 0.001\n')
    rc = main(["fe", "diametral", str(d), "--force", "1", "--out", str(tmp_path / "out")])
    assert rc == 2 and capsys.readouterr().err.splitlines() == [
        "error: --mesh-size = (not given) is not allowed: its default for this tablet, min(thickness/2, plan width/12) "
        "= 0.0005 mm, gives about 2.11e+10 unknowns, more than the 2e+05 that fit in memory: give a mesh size of at "
        "least 0.0236 mm"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["thin.toml"]


@pytest.mark.parametrize("key, value, line", [
    ("diameter", "-10.0", "error: design.tablet.diameter = -10 mm is not allowed: must be > 0 (a length of "
                          "concave_round; the sweep does not vary it, so every design would be refused)"),
    ("land", "-0.1", "error: design.tablet.land = -0.1 mm is not allowed: must be >= 0 (a length of concave_round; the "
                     "sweep does not vary it, so every design would be refused)"),
])
def test_sweep_states_a_fixed_lengths_true_range(tmp_path, capsys, key, value, line):
    """diameter = -10 was refused as "must be >= 0", but a diameter of 0 is refused too."""
    text = SWEEP.format(extra="", vary='"tablet.band" = [2.4, 3.0]').replace("[design.tablet]\n",
                                                                             f"[design.tablet]\n{key} = {value}\n", 1)
    text = text.replace("diameter = 10.0\n", "") if key == "diameter" else text
    f = tmp_path / "s.toml"
    f.write_text(text)
    rc = main(["sweep", str(f), "--out", str(tmp_path / "out"), "--workers", "1"])
    assert rc == 2 and capsys.readouterr().err.splitlines() == [line]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_sweep_names_the_journal_a_folder_holds(tmp_path, capsys):
    """A folder holding only a results.partial.jsonl was said to hold results.csv."""
    from pathlib import Path

    sample = Path(__file__).resolve().parents[1] / "samples" / "sweep" / "concave_round_grid.toml"
    out = tmp_path / "o"
    out.mkdir()
    (out / "results.partial.jsonl").write_text('{"x": 1}\n')
    rc = main(["sweep", str(sample), "--out", str(out), "--workers", "1"])
    assert rc == 2 and capsys.readouterr().err.splitlines() == [
        f"error: --out = '{out}' is not allowed: already holds results.partial.jsonl, the name a sweep writes its "
        "results under; give --resume to go on with that sweep, or another folder"]
    assert sorted(p.name for p in out.iterdir()) == ["results.partial.jsonl"]
