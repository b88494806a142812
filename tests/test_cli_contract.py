"""The command line's contract on bad input, internal errors and Ctrl-C (issue 13 items 4, 5, 9; issue 19).

Bad input: exit status 2, exactly one stderr line
``error: <parameter> = <value> is not allowed: <range>``, nothing written (no
output, no staging folder in the output's parent).  An internal error: exit 1,
one line naming the log file that holds the traceback.  Ctrl-C: one line
``interrupted``, exit 130.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import tabletcad.cli as cli_mod
from tabletcad.cli import main
from tabletcad.pipeline.design import design_from_dict
from tabletcad.errors import DesignError
from tabletcad.families import FAMILIES

ROOT = Path(__file__).resolve().parents[1]
ONE_LINE = re.compile(r"^error: \S+ = .+ is not allowed: .+$")


def run(capsys, *args) -> tuple[int, str, str]:
    rc = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return rc, out, err


def assert_refused(rc: int, err: str, parameter: str) -> str:
    """Exit 2 and one contract line naming ``parameter``; return the line."""
    lines = err.splitlines()
    assert rc == 2, err
    assert len(lines) == 1 and "Traceback" not in err, err
    assert ONE_LINE.match(lines[0]), lines[0]
    assert lines[0].startswith(f"error: {parameter} = "), lines[0]
    return lines[0]


def design(tmp_path: Path, text: str, name: str = "d.toml") -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


FLAT = '[tablet]\nfamily = "thesis.flat_faced_round"\nthickness = 6.0\n'


@pytest.mark.parametrize(
    "text, parameter, fragment",
    [
        (FLAT + "diameter = 1e300\n", "tablet.diameter", "within ±1000 mm"),
        (FLAT + "diameter = " + "9" * 401 + "\n", "tablet.diameter", "an integer of 401 digits"),
        (FLAT + "diameter = " + "9" * 5000 + "\n", "DESIGN", "numbers Python can read"),
        (FLAT + "diameter = true\n", "tablet.diameter", "true and false are not numbers"),
        (FLAT + 'diameter = "10"\n', "tablet.diameter", "must be a number"),
        (FLAT + "diameter = -1e-300\n", "tablet.diameter", "> 0"),
        # features below the 1 µm the surfaces are certified to: refused before any geometry
        # (a 1e-9 mm band used to reach the CAD stage and fail there, a 1 nm tablet to build)
        ('[tablet]\nfamily = "concave_round"\ndiameter = 10.0\ncup_depth = 1.0\nband = 1e-9\n', "tablet.band",
         "at least 0.001 mm"),
        ('[tablet]\nfamily = "concave_round"\ndiameter = 1e-6\ncup_depth = 1e-7\nband = 1e-7\n', "tablet.diameter",
         "at least 0.001 mm"),
        ('[tablet]\nfamily = "capsule"\nlength = 18.0\nwidth = 8.0\nband = 3.0\ncup_depth = 1.2\nland = 5e-4\n',
         "tablet.land", "must be 0 or at least 0.001 mm"),
        (FLAT, "tablet.diameter", "needs diameter, thickness"),
        ('[tablet]\nfamily = "concave_round"\ndiameter = 10.0\ncup_depth = 1.0\nband = 1e300\n', "tablet.band", "within ±1000 mm"),
        ('[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 3.0\n', "tablet.cup_depth", "optional: land"),
        ("x = " + "[" * 5000 + "]" * 5000 + "\n", "DESIGN", "nested"),
        (FLAT + "diameter = 10.0\n[trim]\nv = [0.0, true]\n", "trim.v[1]", "not numbers"),
        (FLAT + "diameter = 10.0\n[reshape]\nradius = 1e300\n", "reshape.radius", "<= 1000"),
        (FLAT + "diameter = 10.0\n[reshape]\nradius = 500.0\n", "reshape", "it reaches 25"),
        ('[tablet]\nfamily = "custom_outline"\noutline = [[0, 0], [1e300, 0], [0, 5]]\nband = 2.0\ncup_depth = 0.3\n',
         "tablet.outline[1][0]", "within ±1000 mm"),
        ('[tablet]\nfamily = "free_form"\n[[patch]]\ncurves = [{type = "circle", radius = 1.0, z = false}, "previous", '
         '"previous", "previous"]\n', "patch[0].curves[0].z", "not numbers"),  # the key given (it had said center)
        (FLAT + 'diameter = 10.0\n"bad key" = 1\n', "tablet.bad.key", "takes diameter, thickness"),
        ("[tablet]\nfamily = 3\n", "tablet.family", "must be one of"),
    ],
)
def test_bad_design_files_one_line_nothing_written(capsys, tmp_path, text, parameter, fragment):
    src = design(tmp_path, text)
    out = tmp_path / "out"
    t0 = time.perf_counter()
    rc, stdout, err = run(capsys, "build", src, "--out", out, "--quiet")
    line = assert_refused(rc, err, parameter)
    assert fragment in line
    assert stdout == "" and not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]  # no staging folder left
    # the design report and the mesher read design files the same way
    assert run(capsys, "report", src)[0] == 2
    assert run(capsys, "mesh", src, "--nodes", 3, 3, 3, "--out", tmp_path / "m.vtu")[0] == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]
    print(f"{parameter}: refused in {time.perf_counter() - t0:.2f} s")  # speed is shown, not asserted


def test_design_from_dict_refuses_booleans_and_huge_integers():
    for value in (True, False, 10**401, float("inf")):
        with pytest.raises(DesignError) as ei:
            design_from_dict({"tablet": {"family": "thesis.spherical", "diameter": value}})
        assert ei.value.parameter == "tablet.diameter" and "\n" not in str(ei.value)


def test_every_family_refuses_each_missing_required_parameter():
    for name, fam in FAMILIES.items():
        full = dict(fam.defaults)
        assert fam.required and set(fam.required) <= set(fam.params)
        for k in fam.required:
            data = {"tablet": {"family": name, **{q: v for q, v in full.items() if q != k}}}
            with pytest.raises(DesignError) as ei:
                design_from_dict(data)
            assert ei.value.parameter == f"tablet.{k}" and ei.value.value == "missing"
        # optional parameters are exactly those that switch a feature off (default 0)
        assert all(fam.defaults[k] == 0.0 for k in fam.params if k not in fam.required)


def test_a_directory_as_design_file(capsys, tmp_path):
    (tmp_path / "folder").mkdir()
    for cmd in (["build", tmp_path / "folder", "--out", tmp_path / "o"], ["report", tmp_path / "folder"],
                ["mesh", tmp_path / "folder", "--nodes", 3, 3, 3, "--out", tmp_path / "m.vtu"]):
        rc, _, err = run(capsys, *cmd)
        assert "folder" in assert_refused(rc, err, "DESIGN")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder"]


def test_out_naming_an_existing_file(capsys, tmp_path):
    (tmp_path / "taken").write_text("keep me")
    rc, _, err = run(capsys, "build", ROOT / "samples" / "spherical.toml", "--out", tmp_path / "taken")
    assert "a file of that name exists" in assert_refused(rc, err, "--out")
    assert (tmp_path / "taken").read_text() == "keep me"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["taken"]


@pytest.mark.parametrize("command", ["build", "optimise", "sweep"])
def test_out_that_cannot_be_a_folder_is_refused_before_any_work(capsys, tmp_path, monkeypatch, command):
    """An empty --out (an unset shell variable: it would build into the current folder), a folder
    under a file, a folder of a virtual file system: one line for --out, nothing written."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "afile").write_text("x")
    arg = {"build": ROOT / "samples" / "spherical.toml",
           "optimise": ROOT / "samples" / "optimise" / "cylinder_min_area.toml",
           "sweep": ROOT / "samples" / "sweep" / "concave_round_grid.toml"}[command]
    cases = [("", "must name a folder"), (tmp_path / "afile" / "sub", "is a file, not a folder")]
    if command == "build" and Path("/proc/self").is_dir():
        cases.append(("/proc/tabletcad-out", "cannot be written"))
    for out, fragment in cases:
        rc, _, err = run(capsys, command, arg, "--out", out)
        assert fragment in assert_refused(rc, err, "--out"), (out, err)
        assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]


@pytest.mark.skipif(not Path("/sys/kernel").is_dir(), reason="Linux's /sys (present on every CI machine)")
@pytest.mark.parametrize("args, option", [
    (["fe", "diametral", "{fam}/concave_round.toml", "--force", "100", "--out", "/sys/tabletcad-out"], "--out"),
    (["fe", "diametral", "{fam}/concave_round.toml", "--force", "100", "--json-file", "/sys/x.json"], "--json-file"),
    (["report", "{fam}/concave_round.toml", "--csv", "/sys/x.csv"], "--csv"),
    (["optimise", "{root}/samples/optimise/cylinder_min_area.toml", "--out", "/sys/tabletcad-out"], "--out"),
    (["build", "{fam}/concave_round.toml", "--out", "/sys/tabletcad-out"], "--out"),
])
def test_an_output_in_a_folder_that_takes_no_files_is_refused_first(capsys, monkeypatch, args, option):
    """/sys passes os.access for root, but takes no new file: refused before any work (fe and optimise
    had failed only after the solve, 5-9 s later).  os.access is made to say yes, as it does to root,
    so that the probe decides for any user."""
    import os

    monkeypatch.setattr(os, "access", lambda *a, **k: True)
    argv = [a.format(fam=ROOT / "samples" / "families", root=ROOT) for a in args]
    rc, out, err = run(capsys, *argv)
    assert "cannot be written: folder /sys is not writable" in assert_refused(rc, err, option)


@pytest.mark.parametrize(
    "args, parameter, fragment",
    [
        (["mesh", "{sample}", "--nodes", "5", "x", "5", "--out", "{tmp}/m.vtu"], "--nodes", "must be an integer"),
        (["mesh", "{sample}", "--nodes", "5", "2.5", "5", "--out", "{tmp}/m.vtu"], "--nodes", "must be an integer"),
        (["mesh", "{sample}", "--nodes", "1", "21", "5", "--out", "{tmp}/m.vtu"], "--nodes", "from 2 to 2000"),
        (["mesh", "{sample}", "--nodes", "5", "5", "5", "--out", "{tmp}/m.obj"], "--out", ".vtu"),
        # a mesh file under a file: named as the option (it was "path = ... file exists", after the geometry)
        (["mesh", "{sample}", "--nodes", "5", "5", "5", "--out", "{sample}/m.vtu"], "--out",
         "cannot be created: {sample} is a file, not a folder"),
        (["optimise", "{sample}", "--out", "{tmp}/o", "--method", "newton"], "--method", "SLSQP"),
        (["report", "{sample}", "--solid-fraction", "half"], "--solid-fraction", "must be a number"),
        (["build", "{sample}", "--out", "{tmp}/o", "--colour", "red"], "option", "takes --out"),
        (["build", "{sample}"], "--out", "needs it"),
        (["build", "{sample}", "--out"], "--out", "needs a value"),
        (["build"], "DESIGN", "needs it"),
        (["bild", "{sample}"], "command", "must be one of"),
        (["build", "{sample}", "{sample}", "--out", "{tmp}/o"], "argument", "no further arguments"),
    ],
)
def test_bad_arguments_one_line(capsys, tmp_path, args, parameter, fragment):
    sample = ROOT / "samples" / "spherical.toml"
    argv = [a.format(sample=sample, tmp=tmp_path) for a in args]
    rc, out, err = run(capsys, *argv)
    assert fragment.format(sample=sample) in assert_refused(rc, err, parameter)
    assert out == "" and list(tmp_path.iterdir()) == []


def test_mesh_refused_by_memory_budget_before_allocating(capsys, tmp_path):
    import tracemalloc

    tracemalloc.start()
    rc, _, err = run(capsys, "mesh", ROOT / "samples" / "spherical.toml", "--nodes", 2000, 2000, 2000,
                     "--out", tmp_path / "m.vtu")
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    line = assert_refused(rc, err, "--nodes")
    # 2 patches x 2000^3 nodes x 300 bytes = 4.8e12 bytes = 4470 GiB
    assert "4.47e+03 GiB" in line and "1.6e+10 nodes (2 patches)" in line
    assert peak < 200 * 2**20  # nothing close to the mesh was allocated
    assert list(tmp_path.iterdir()) == []


def test_memory_budget_scales_with_available_memory(monkeypatch):
    from tabletcad.cli import geometry

    monkeypatch.setattr(geometry, "available_memory", lambda: 10_000_000)  # 10 MB
    geometry._check_mesh_memory((10, 10, 10), 3)  # 3000 nodes x 300 B = 0.9 MB <= 5 MB
    with pytest.raises(DesignError) as ei:
        geometry._check_mesh_memory((30, 30, 30), 3)  # 81000 nodes x 300 B = 24.3 MB > 5 MB
    assert ei.value.parameter == "--nodes" and "below 5.56e+03" in ei.value.allowed  # 5e6 / (300 * 3)


def test_shapes_marks_required_and_optional_and_prints_whole_descriptions(capsys):
    rc, out, _ = run(capsys, "shapes")
    assert rc == 0
    text = " ".join(out.split())
    for name, fam in FAMILIES.items():
        assert f"{name} required: " + ", ".join(f"{k} [{fam.params[k]}]" + (f" (or {fam.alternatives[k]})" if k in
                                                fam.alternatives else "") for k in fam.required) in text
        doc = " ".join(fam.func.__doc__.strip().split("\n\n")[0].replace("``", "").split())
        assert fam.description == doc and doc in text and doc[-1] in ".)"
    assert "concave_round required: diameter [mm], band [mm], cup_depth [mm]; optional: land [mm] = 0" in text
    rc, out, _ = run(capsys, "shapes", "--json")
    d = json.loads(out)
    assert d["concave_round"]["required"] == ["diameter", "band", "cup_depth"] and d["concave_round"]["optional"] == ["land"]
    assert d["thesis.flat_faced_round"]["optional"] == []
    # a ffbe's bevel by its width or its depth: listed so, and in the JSON
    assert "ffbe required: diameter [mm], thickness [mm], bevel_angle [deg], bevel_width [mm] (or bevel_depth); " \
           "optional: bevel_depth [mm] = 0" in text
    assert d["ffbe"]["alternatives"] == {"bevel_width": "bevel_depth"} and d["concave_round"]["alternatives"] == {}
    # the designs of any shape too, as the listing has them (the JSON had left them out: 25 of the 27)
    assert list(d) == [*FAMILIES, "custom_outline", "free_form"] and all(f"{n} " in text for n in d)
    assert d["custom_outline"]["required"] == ["outline", "band", "cup_depth"]
    assert d["custom_outline"]["alternatives"] == {"outline": "segments"} and d["free_form"]["required"] == ["patch"]
    for entry in d.values():
        assert set(entry) == {"params", "required", "optional", "alternatives", "defaults", "description"}
        assert sorted(entry["required"] + entry["optional"]) == sorted(entry["params"]) == sorted(entry["defaults"])


#: the one line of a command whose standard output is refused (a full disk)
FULL_DISK_LINE = "error: output = '(being written)' is not allowed: no space left on device"


def _on_a_full_disk(args: list[str], **kw) -> subprocess.CompletedProcess:
    """``tabletcad <args>`` in a subprocess with its standard output on /dev/full (every write: no space left on
    device), its standard error captured."""
    with open("/dev/full", "w") as full:
        return subprocess.run([sys.executable, "-m", "tabletcad", *args], stdout=full, stderr=subprocess.PIPE,
                              text=True, **kw)


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs Linux's /dev/full")
@pytest.mark.parametrize("args", [["shapes", "--json"], ["report", str(ROOT / "samples" / "families" / "concave_round.toml")]])
def test_standard_output_on_a_full_disk_is_the_machines_state_not_a_bug(tmp_path, args):
    """``> /dev/full`` (every write: no space left on device) had been reported as an internal error with a
    traceback log, exit 1: it is one line naming the output, exit 2, and no log."""
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "cache")}
    proc = _on_a_full_disk(args, env=env, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.splitlines() == [FULL_DISK_LINE]
    assert not (tmp_path / "cache").exists()


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs Linux's /dev/full")
@pytest.mark.parametrize("args", [["love", "--json"], ["report", "OLD"]])
def test_a_full_disk_after_a_warning_is_still_one_line(tmp_path, args):
    """A trial: ``love --json > /dev/full`` printed its fit's warning and then the error, two lines for one
    refusal, and so did a report of a design under an old family name.  A command's warnings are printed
    once it has its result; a refusal is its one line.  Written in full, both print their warnings."""
    old = tmp_path / "old.toml"
    old.write_text('[tablet]\nfamily = "flat_faced_round"\ndiameter = 10.0\nthickness = 3.0\n', encoding="utf-8")
    args = [str(old) if a == "OLD" else a for a in args]
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "cache")}
    proc = _on_a_full_disk(args, env=env, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.splitlines() == [FULL_DISK_LINE]
    proc = subprocess.run([sys.executable, "-m", "tabletcad", *args], capture_output=True, text=True, env=env,
                          timeout=120)
    assert proc.returncode == 0 and proc.stdout and proc.stderr.startswith("warning: "), proc.stderr


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs Linux's /dev/full")
@pytest.mark.parametrize("args, made", [
    pytest.param(["build", "{root}/samples/flat_faced_round.toml", "--out", "b"], ["b"], marks=pytest.mark.cad),
    (["mesh", "{root}/samples/spherical.toml", "--nodes", "5", "9", "3", "--out", "m.vtu"], ["m.vtu"]),
    (["report", "{root}/samples/families/concave_round.toml", "--csv", "c.csv", "--plot", "c.png", "--json-file",
      "c.json"], ["c.csv", "c.json", "c.png"]),
    pytest.param(["optimise", "{root}/samples/optimise/cylinder_min_area.toml", "--out", "o"], ["o"],
                 marks=pytest.mark.cad),
    pytest.param(["fe", "diametral", "{root}/samples/families/concave_round.toml", "--force", "100",
                  "--no-error-estimate", "--out", "f", "--json-file", "f.json"], ["f", "f.json"],
                 marks=pytest.mark.fe),
])
def test_a_refused_standard_output_leaves_no_output(tmp_path, args, made):
    """A trial: ``build ... > /dev/full`` exited 2 with its one line and left the whole build in its folder
    (mesh its file, report its --csv, --plot and --json-file, optimise and fe their folders, fe its --json-file).  The summary is printed before the
    files are put in place; written in full, the same command makes them (exit 0)."""
    if "fe" in args:
        pytest.importorskip("skfem")
        pytest.importorskip("gmsh")
    if args[0] in ("build", "optimise", "fe"):
        pytest.importorskip("OCP")
    args = [a.format(root=ROOT) for a in args]
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "cache")}
    work = tmp_path / "work"
    work.mkdir()
    proc = _on_a_full_disk(args, env={**env, "PYTHONPATH": str(ROOT)}, cwd=work, timeout=300)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.splitlines()[-1:] == [FULL_DISK_LINE]
    assert not any(line.startswith(("error", "warning")) for line in proc.stderr.splitlines()[:-1]), proc.stderr
    assert sorted(p.name for p in work.iterdir()) == []
    proc = subprocess.run([sys.executable, "-m", "tabletcad", *args], capture_output=True, text=True,
                          env={**env, "PYTHONPATH": str(ROOT)}, cwd=work, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in work.iterdir()) == sorted(made)


def test_a_forked_helpers_warning_is_printed_at_once(capsys, monkeypatch):
    """The command's own warnings wait for its outcome; a forked helper's (tabletcad.io.forked: the picture, a
    tooling build's files) would be lost with its copy of the held list, so it prints them as it did."""
    import warnings

    monkeypatch.setattr(cli_mod, "_PENDING_WARNINGS", [])
    monkeypatch.setattr(cli_mod, "_MAIN_PID", [os.getpid()])
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = cli_mod._show_warning
        warnings.warn("held", UserWarning)
        assert capsys.readouterr().err == "" and cli_mod._PENDING_WARNINGS == ["warning: held"]
        monkeypatch.setattr(cli_mod, "_MAIN_PID", [os.getpid() + 1])  # this process stands for a helper
        warnings.warn("from a helper", UserWarning)
    assert capsys.readouterr().err == "warning: from a helper\n" and cli_mod._PENDING_WARNINGS == ["warning: held"]


def test_a_full_disk_while_writing_a_file_names_the_file(capsys, tmp_path, monkeypatch):
    """A write into the temporary file that stands for an output, refused for want of space, carries no file
    name: the output it stands for is named (a review: "output = '(being written)'" on a full tmpfs), and
    nothing is left behind."""
    import errno

    import tabletcad.io.atomic as atomic
    from tabletcad.io.atomic import atomic_path

    target = tmp_path / "m.vtu"
    with pytest.raises(OSError) as info:
        with atomic_path(target) as tmp:
            tmp.write_bytes(b"x")
            raise OSError(errno.ENOSPC, "No space left on device")
    assert info.value.filename == str(target) and info.value.errno == errno.ENOSPC
    assert sorted(tmp_path.iterdir()) == []

    def full(self, data):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(Path, "write_bytes", full)
    monkeypatch.setattr(Path, "write_text", lambda self, *a, **k: full(self, b""))
    import meshio

    monkeypatch.setattr(meshio, "write", lambda path, *a, **k: full(path, b""))
    out = tmp_path / "m.vtu"
    rc, _, err = run(capsys, "mesh", ROOT / "samples" / "flat_faced_round.toml", "--nodes", 5, 8, 3, "--out", out)
    assert rc == 2 and err.splitlines() == [f"error: path = '{out}' is not allowed: no space left on device"], err
    assert sorted(tmp_path.iterdir()) == []


@pytest.mark.parametrize("exc", [ZeroDivisionError("division by zero"), ValueError("a bare ValueError is a bug")])
def test_internal_error_exit_1_with_log(capsys, tmp_path, monkeypatch, exc):
    import tabletcad.pipeline.build

    def broken(*a, **k):
        raise exc

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.setattr(tabletcad.pipeline.build, "build_design", broken)
    rc, out, err = run(capsys, "build", ROOT / "samples" / "spherical.toml", "--out", tmp_path / "o")
    lines = err.splitlines()
    assert rc == 1 and len(lines) == 1 and "Traceback" not in err
    m = re.fullmatch(r"error: internal error \((\w+): (.+)\); traceback in (\S+)", lines[0])
    assert m and m.group(1) == type(exc).__name__ and m.group(2) == str(exc)
    log = Path(m.group(3))
    assert log.parent == tmp_path / "cache" / "tabletcad"
    assert "Traceback" in log.read_text() and f"{type(exc).__name__}: {exc}" in log.read_text()


def test_ctrl_c_while_commands_load(capsys, monkeypatch):
    import importlib

    def interrupted(name, *a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli_mod, "_GROUP", None)
    monkeypatch.setattr(importlib, "import_module", interrupted)
    rc, out, err = run(capsys, "shapes")
    assert rc == 130 and err == "interrupted\n" and out == ""


def _wait_until_numpy_loads(p: subprocess.Popen, timeout: float = 120.0) -> None:
    """Wait until the child has numpy mapped: tabletcad's own code is running by then (a signal
    earlier would land in Python's start-up, before any program can handle it)."""
    maps = Path(f"/proc/{p.pid}/maps")
    t_end = time.monotonic() + timeout
    while time.monotonic() < t_end and p.poll() is None:
        try:
            if "_multiarray_umath" in maps.read_text():
                return
        except OSError:
            return
        time.sleep(0.01)


def test_ctrl_c_during_a_build_subprocess(tmp_path):
    """SIGINT at several moments of a real build (loading, building): one line, 130, nothing left."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    for delay in (0.5, 1.5, 3.0):
        out = tmp_path / f"out{delay}"
        p = subprocess.Popen([sys.executable, "-m", "tabletcad", "build", str(ROOT / "samples" / "families" / "capsule.toml"),
                              "--out", str(out), "--quiet"], cwd=tmp_path, env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        _wait_until_numpy_loads(p)  # past Python's own start-up, whatever the machine's load
        time.sleep(delay - 0.5)
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=120)
        if p.returncode == 0:  # finished before the signal (a very fast machine): nothing to check
            continue
        assert p.returncode == 130 and err == "interrupted\n", (delay, p.returncode, err)
        assert not out.exists() and not any(q.name.startswith(f".{out.name}") for q in tmp_path.iterdir())


_SWALLOWED = """
import os, signal, sys
import tabletcad.pipeline.build as g
from tabletcad.cli import main

def build(*a, **k):  # a library that catches the Ctrl-C and then fails over it (trimesh's lazy imports)
    try:
        os.kill(os.getpid(), signal.SIGINT)
    except BaseException:
        pass
    raise TypeError("unsupported operand type(s) for |: 'ExceptionWrapper' and 'NoneType'")

g.build_design = build
sys.argv = ["tabletcad", "build", sys.argv[1], "--out", sys.argv[2]]
sys.exit(main())
"""


def test_a_ctrl_c_that_a_library_swallowed_is_still_an_interruption(tmp_path):
    p = subprocess.run([sys.executable, "-c", _SWALLOWED, str(ROOT / "samples" / "families" / "capsule.toml"),
                        str(tmp_path / "out")], cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(ROOT)},
                       capture_output=True, text=True, timeout=120)
    assert (p.returncode, p.stderr) == (130, "interrupted\n")
    assert os.listdir(tmp_path) == []


_LOGGED_AFTER = """
import logging, os, signal, sys, threading
import tabletcad.pipeline.build as g
from tabletcad.cli import main

def build(*a, **k):  # a library whose thread logs an error once the Ctrl-C has stopped the main thread
    try:
        os.kill(os.getpid(), signal.SIGINT)
    finally:
        t = threading.Thread(target=lambda: logging.getLogger("tornado.application").error("Exception in callback"))
        t.start()
        t.join()

g.build_design = build
sys.argv = ["tabletcad", "build", sys.argv[1], "--out", sys.argv[2]]
sys.exit(main())
"""


def test_a_librarys_log_after_a_ctrl_c_is_not_printed(tmp_path):
    """After a Ctrl-C the program's one line is ``interrupted``: a sweep's Dask client, stopped while it
    waited, had logged a traceback from its event loop's thread first (distributed 2026.8.0)."""
    p = subprocess.run([sys.executable, "-c", _LOGGED_AFTER, str(ROOT / "samples" / "spherical.toml"),
                        str(tmp_path / "out")], cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(ROOT)},
                       capture_output=True, text=True, timeout=120)
    assert (p.returncode, p.stderr) == (130, "interrupted\n")
    assert os.listdir(tmp_path) == []


_EXIT_HANDLERS = """
import atexit, sys
from tabletcad.cli import main

out = sys.argv[1]
atexit.register(lambda: open(out, "w").write("ran"))  # a library's exit handler
sys.argv = ["tabletcad"] + sys.argv[2:]
sys.exit(main())
"""


@pytest.mark.parametrize("args, status", [(["report", "samples/spherical.toml"], 0),
                                          (["report", "samples/spherical.toml", "--solid-fraction", "2"], 2),
                                          (["report", "no_such_file.toml"], 2)])
def test_the_program_ends_with_its_status_after_the_exit_handlers(tmp_path, args, status):
    """The program ends without tearing its objects down one by one (``cli._finish``), but after the
    exit handlers that libraries registered, with the command's status and its output flushed."""
    flag = tmp_path / "flag"
    p = subprocess.run([sys.executable, "-c", _EXIT_HANDLERS, str(flag), *args], cwd=ROOT,
                       env={**os.environ, "PYTHONPATH": str(ROOT)}, capture_output=True, text=True, timeout=120)
    assert p.returncode == status, p.stderr
    assert flag.read_text() == "ran"
    if status == 0:
        assert "PDE surface vs exact shape" in p.stdout and p.stdout.endswith("\n"), p.stdout
        assert p.stderr == ""
    else:
        assert p.stdout == "" and len(p.stderr.splitlines()) == 1 and p.stderr.startswith("error: ")


def test_readme_says_how_to_reach_the_commands():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    after = text[text.index("## Two commands on a fresh machine"):]
    section = after[:after.index("\n## ", 5)]
    assert ".venv/bin/tabletcad" in section and ". .venv/bin/activate" in section


def test_bare_command_prints_help_and_help_exits_0(capsys):
    rc, out, err = run(capsys)
    assert rc == 0 and out.startswith("Usage: tabletcad") and "build" in out and err == ""
    rc, out, err = run(capsys, "mesh", "--help")
    assert rc == 0 and "--nodes" in out and err == ""


@pytest.mark.parametrize("argv, extra", [
    (["sweep", "samples/sweep/concave_round_grid.toml", "--out", "OUT"], "sweep"),
    (["fe", "diametral", "samples/families/concave_round.toml", "--force", "100", "--out", "OUT"], "fe"),
])
def test_a_missing_extra_is_one_line_naming_it(tmp_path, capsys, monkeypatch, argv, extra):
    """Without Dask or gmsh installed (simulated here; real in the core-only CI pass) the command
    names the extra to install: exit 2, one line, nothing written."""
    for name in ("distributed", "gmsh"):
        monkeypatch.setitem(sys.modules, name, None)  # import raises ImportError
    argv = [str(ROOT / a) if a.startswith("samples/") else str(tmp_path / "out") if a == "OUT" else a for a in argv]
    assert main(argv) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err.splitlines() == [cap.err.strip()] and cap.err.startswith(f"error: tabletcad.{extra} = ")
    assert f"pip install 'tabletcad[{extra}]'" in cap.err
    assert list(tmp_path.iterdir()) == []


def test_mesh_reports_its_volume_error_and_warns_with_a_node_count_that_meets_the_bound(tmp_path, capsys):
    """Straight-edged cells lose volume at second order in the cell size: the flat-faced round at
    8 x 8 x 8 nodes is 12.9 % low (issue 18), the warning's suggested node counts land within
    the 1 % bound, and halving the cells in u and v quarters the error."""
    import meshio

    from tabletcad.pipeline.design import load_design
    from tabletcad.tolerance import DEFAULT

    src = ROOT / "samples" / "flat_faced_round.toml"
    exact = load_design(src).solid_volume()

    def mesh(nodes):
        out = tmp_path / f"m{'_'.join(map(str, nodes))}.vtu"
        assert main(["mesh", str(src), "--nodes", *map(str, nodes), "--out", str(out)]) == 0
        cap = capsys.readouterr()
        m = re.search(r"mesh volume (\S+) mm3 \((\S+) % of the exact (\S+) mm3\)", cap.out)
        assert m, cap.out
        assert float(m.group(3)) == pytest.approx(exact, rel=1e-5)
        got = meshio.read(out)
        return float(m.group(2)) / 100.0, cap.err, got

    rel, err, got = mesh((8, 8, 8))
    assert rel == pytest.approx(-0.129, abs=1e-3)
    assert len(err.splitlines()) == 1 and err.startswith("warning: the mesh volume is 12.9 % below")
    hint = tuple(int(n) for n in re.search(r"--nodes (\d+) (\d+) (\d+)", err).groups())
    rel2, err2, _ = mesh(hint)
    assert abs(rel2) <= DEFAULT.mesh_volume and err2 == ""
    rel3, _, _ = mesh((2 * hint[0] - 1, 2 * hint[1] - 1, hint[2]))  # halved cells: a quarter of the error
    assert rel3 / rel2 == pytest.approx(0.25, abs=0.03)
    assert len(got.points) == 400


def test_ctrl_c_after_an_optimisation_built_its_optimum_is_an_interruption(tmp_path, capsys, monkeypatch):
    """An optimisation builds its optimum into a folder inside its own staging folder, then publishes the
    whole.  A Ctrl-C between the two is an interruption (exit 130, nothing written): it had exited 0 with
    "interrupted after the build was complete: outputs in .out.xxxx/tablet/", a folder then removed."""
    import tabletcad.io.outputs as outputs

    real_replace = os.replace
    sent = []
    out = tmp_path / "out"

    def replace_then_interrupt(src, dst):
        real_replace(src, dst)
        if not sent and Path(dst).parent.name == "tablet" and Path(dst).parent.parent != out:
            sent.append(dst)  # the optimum's build, put in place inside the optimisation's staging folder
            os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(outputs.os, "replace", replace_then_interrupt)
    rc, _, err = run(capsys, "optimise", str(ROOT / "samples" / "optimise" / "cylinder_min_area.toml"), "--out",
                     str(out), "--quiet")
    assert sent, "the optimum was never built"
    assert (rc, err) == (130, "interrupted\n")
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == []
    assert not outputs._open_staging


def test_ctrl_c_while_a_build_publishes_leaves_the_whole_build(tmp_path, capsys, monkeypatch):
    """SIGINT sent while the outputs are being moved into place (after the first file) waits until
    every file and the manifest are there: the folder holds the whole build and the command says
    it finished (exit 0), never half a build beside "interrupted"."""
    import json as _json

    import tabletcad.io.outputs as outputs

    real_replace = os.replace
    sent = []
    out = tmp_path / "out"

    def replace_then_interrupt(src, dst):  # os.replace is the os module's: atomic writes use it too
        real_replace(src, dst)
        if not sent and Path(dst).parent == out:
            sent.append(dst)
            os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(outputs.os, "replace", replace_then_interrupt)
    rc, _, err = run(capsys, "build", str(ROOT / "samples" / "flat_faced_round.toml"), "--out", str(out), "--quiet")
    assert sent, "the build never published"
    assert rc == 0 and err == f"interrupted after the build was complete: outputs in {out}/\n"
    manifest = _json.loads((out / outputs.MANIFEST).read_text())
    assert sorted(manifest["files"]) == sorted(p.name for p in out.iterdir() if p.name != outputs.MANIFEST)
    report = _json.loads((out / "report.json").read_text())
    assert {"report.json", "tablet.png"} <= set(manifest["files"]) == set(report["outputs"])
    assert not [q for q in tmp_path.iterdir() if q.name.startswith(".out.")]


def test_ctrl_c_while_an_extension_initialises_is_an_interrupt(tmp_path, capsys, monkeypatch):
    """A Ctrl-C during an extension module's initialisation surfaces as ``ImportError:
    initialization failed`` caused by the KeyboardInterrupt (seen importing OCP in a fresh clone):
    that is "interrupted" and 130, not an internal error, nor "no CAD library" with a build that
    leaves its CAD files out."""
    import tabletcad.pipeline.build

    def interrupted_import():
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as exc:
            raise ImportError("initialization failed") from exc

    class InterruptedFinder:  # the build's import of the CAD stage meets the interrupted import
        def find_spec(self, name, path=None, target=None):
            if name == "tabletcad.cad.stage":
                interrupted_import()
            return None

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.setenv("TABLETCAD_REQUIRE_CAD", "1")  # the build imports its CAD step (also without OCP installed)
    monkeypatch.delitem(sys.modules, "tabletcad.cad.stage", raising=False)
    monkeypatch.setattr(sys, "meta_path", [InterruptedFinder(), *sys.meta_path])
    out = tmp_path / "out"
    rc, _, err = run(capsys, "build", str(ROOT / "samples" / "spherical.toml"), "--out", str(out))
    assert (rc, err) == (130, "interrupted\n") and not out.exists()
    # and the same ImportError anywhere else in a command
    monkeypatch.setattr(tabletcad.pipeline.build, "geometry_report", lambda *a, **k: interrupted_import())
    rc, _, err = run(capsys, "build", str(ROOT / "samples" / "spherical.toml"), "--out", str(out))
    assert (rc, err) == (130, "interrupted\n") and not out.exists()
    assert not (tmp_path / "cache").exists()  # no internal-error log


def test_sigterm_while_an_extension_initialises_is_a_termination(tmp_path, capsys, monkeypatch):
    """A SIGTERM during an extension module's initialisation (its handler raises SystemExit(143)
    inside the build's staging block) surfaces as ``ImportError: initialization failed`` caused by
    the SystemExit; the build ends with status 143 and nothing written, not as an internal error
    (found by the killed-build test once the build reached the OCP import within 0.1 s)."""
    def terminated_import():
        try:
            raise SystemExit(143)
        except SystemExit as exc:
            raise ImportError("initialization failed") from exc

    class TerminatedFinder:
        def find_spec(self, name, path=None, target=None):
            if name == "tabletcad.cad.stage":
                terminated_import()
            return None

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.setenv("TABLETCAD_REQUIRE_CAD", "1")
    monkeypatch.delitem(sys.modules, "tabletcad.cad.stage", raising=False)
    monkeypatch.setattr(sys, "meta_path", [TerminatedFinder(), *sys.meta_path])
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as info:
        run(capsys, "build", str(ROOT / "samples" / "spherical.toml"), "--out", str(out))
    assert info.value.code == 143
    assert not out.exists() and not [q for q in tmp_path.iterdir() if q.name.startswith(".out.")]
    assert not (tmp_path / "cache").exists()  # no internal-error log


def test_a_json_file_may_not_overwrite_a_folders_ownership_record(capsys, tmp_path):
    """--json-file out/.tabletcad-fe.json had replaced the FE run's record, and the next run into the
    folder refused the files the first one wrote."""
    rc, _, err = run(capsys, "fe", "diametral", ROOT / "samples" / "families" / "concave_round.toml", "--force", "100",
                     "--out", tmp_path / "o", "--json-file", tmp_path / "o" / ".tabletcad-fe.json")
    assert "must not be the record of the files a tabletcad run owns" in assert_refused(rc, err, "--json-file")
    assert list(tmp_path.iterdir()) == []


def test_a_json_file_may_not_overwrite_a_file_a_build_owns(capsys, tmp_path):
    """report --json-file out/report.json replaced the build's report, and the next build into the folder
    refused it as edited; any other name in the folder is the user's to take."""
    out = tmp_path / "o"
    assert main(["build", str(ROOT / "samples" / "spherical.toml"), "--out", str(out), "--quiet"]) == 0
    capsys.readouterr()
    before = (out / "report.json").read_bytes()
    rc, _, err = run(capsys, "report", ROOT / "samples" / "spherical.toml", "--json-file", out / "report.json")
    assert "is a file the tabletcad run in" in assert_refused(rc, err, "--json-file")
    assert (out / "report.json").read_bytes() == before
    rc, _, err = run(capsys, "report", ROOT / "samples" / "spherical.toml", "--json-file", out / "mine.json")
    assert rc == 0 and (out / "mine.json").is_file()


def test_a_ctrl_c_stops_a_long_compiled_call_at_once():
    """``errors.run_interruptibly``: a call into compiled code that holds no GIL (SuperLU's factorisation
    of an FE system ran minutes past a Ctrl-C) runs in a helper thread, so the interrupt is raised while
    the call is still running.  Here the C library's ``system()`` (``os.system``: the GIL released, and
    a signal neither ends its wait for the command nor runs Python's handlers before it returns) running
    ``head`` on a pipe, which ends only when the test writes to the pipe, and a SIGALRM whose handler
    raises KeyboardInterrupt 0.05 s in: the interrupt arrives while the call still waits (called
    directly, it would only arrive after).  (An SVD of a 1600 x 1600 matrix had been the long call: 2-3 s
    of CPU a run, and its lead over the alarm shrank with the machine's load.)"""
    import threading

    from tabletcad.errors import run_interruptibly

    r, w = os.pipe()
    os.set_inheritable(r, True)  # (the command reads it as /dev/fd/r)
    done = threading.Event()

    def long_call():
        os.system(f"head -c 1 /dev/fd/{r} > /dev/null")
        done.set()

    def on_alarm(signum, frame):
        raise KeyboardInterrupt

    # (run_interruptibly broken, the call in this thread: another thread writes to the pipe after 20 s, the
    # call ends, the interrupt is raised in it and done is never set, which fails the test below)
    fallback = threading.Timer(20.0, os.write, (w, b"x"))
    old = signal.signal(signal.SIGALRM, on_alarm)
    try:
        fallback.start()
        signal.setitimer(signal.ITIMER_REAL, 0.05)
        with pytest.raises(KeyboardInterrupt):
            run_interruptibly(long_call)
        assert not done.is_set()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)
        fallback.cancel()
        os.write(w, b"x")  # the call may end now (a byte the fallback wrote too stays unread)
    try:
        done.wait(120)  # (the abandoned call runs on in its thread; let it end before the next test)
        assert done.is_set()
    finally:
        fallback.join()
        os.close(r)
        os.close(w)
    assert run_interruptibly(sum, [1, 2, 3]) == 6  # and a value comes back
    with pytest.raises(ZeroDivisionError):  # as does an error
        run_interruptibly(lambda: 1 / 0)


def test_solves_in_the_helper_thread_leave_no_memory_behind():
    """The FE solve runs in ``run_interruptibly``'s helper thread with its factors made and freed there:
    SuperLU's factors made in one thread and freed in another leaked about 16 MB a solve (a whole test
    run's FE solves then left a worker too big to fork).  25 solves of a 2000-unknown symmetric positive
    definite system by each solver (CHOLMOD, the one used, and SuperLU, its fallback; without scikit-sparse,
    as in the core's run, the one used is SuperLU's solve, so once): the resident memory
    grows by less than 50 MB, so a leak of 2 MB a solve or more fails (as it did with 100 solves and 200 MB,
    in a quarter of the time); without a leak it grew by 0-12 MB in 100 solves."""
    import numpy as np
    import scipy.sparse as sp

    from tabletcad.errors import run_interruptibly
    from tabletcad.fe.elasticity import _factor_and_solve, _superlu_solve

    def rss_mb() -> float:
        with open("/proc/self/status", encoding="ascii") as f:
            return next(int(line.split()[1]) for line in f if line.startswith("VmRSS")) / 1024.0

    R = sp.random(2000, 2000, density=0.002, random_state=0)
    K = (R + R.T + 10.0 * sp.eye(2000)).tocsc()  # symmetric, diagonally dominant: positive definite
    b = np.ones(2000)
    try:
        import sksparse.cholmod  # noqa: F401
    except ImportError:  # _factor_and_solve is SuperLU's solve (the core's run): once is the same test
        solvers = (_factor_and_solve,)
    else:
        solvers = (_factor_and_solve, _superlu_solve)
    for solve in solvers:
        x = run_interruptibly(solve, K, b)
        assert np.allclose(K @ x, b, atol=1e-10)
        before = rss_mb()
        for _ in range(25):
            run_interruptibly(solve, K, b)
        assert rss_mb() - before < 50.0


def test_a_ctrl_c_swallowed_by_a_gc_callback_is_delivered_again():
    """A Ctrl-C raised inside a garbage-collector callback (distributed's ``GCDiagnosis`` while a sweep's
    cluster started, in a full run) is "Exception ignored" to Python and was lost, the sweep running on:
    the program's unraisable hook delivers it to the main thread again; other unraisable errors still
    reach the previous hook."""
    import gc
    import time
    import types

    from tabletcad.cli import _unraisable_interrupt

    seen = []
    hook = _unraisable_interrupt(seen.append)
    other = types.SimpleNamespace(exc_value=ValueError("x"))
    hook(other)
    assert seen == [other]

    def swallowing_callback(phase, info):
        if phase == "start":
            raise KeyboardInterrupt  # what the SIGINT handler raises when the signal arrives here

    previous = sys.unraisablehook
    sys.unraisablehook = hook
    gc.callbacks.append(swallowing_callback)
    try:
        with pytest.raises(KeyboardInterrupt):
            gc.collect()  # the callback's KeyboardInterrupt is unraisable: the hook re-delivers it
            t0 = time.monotonic()
            while time.monotonic() - t0 < 5.0:
                pass
    finally:
        gc.callbacks.remove(swallowing_callback)
        sys.unraisablehook = previous
    assert seen == [other]


def test_a_name_with_control_characters_is_refused_and_letters_are_kept(capsys, tmp_path):
    """name = "... \\u0000 x" built (exit 0) with a NUL on stdout and in the picture, and cut the STEP product's
    name; refused as emboss text is.  é and µ stay accepted."""
    base = '[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 2.8\ncup_depth = 0.9\n'
    bad = design(tmp_path, base + 'name = "Parac\\u00e9tamol 500 \\u00b5g \\u0000 x"\n')
    rc, out, err = run(capsys, "build", bad, "--out", tmp_path / "out")
    line = assert_refused(rc, err, "tablet.name")
    assert line == ("error: tablet.name = 'Paracétamol 500 µg \\x00 x' is not allowed: must be a plain non-empty name "
                    "(no / \\ \" or control character such as a line break or NUL, at most 200 characters)")
    assert out == "" and sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]
    for ch in ("\\t", "\\u001b", "\\u2028", "\\u0085"):
        rc, _, err = run(capsys, "report", design(tmp_path, base + f'name = "a{ch}b"\n'))
        assert_refused(rc, err, "tablet.name")
    rc, out, err = run(capsys, "report", design(tmp_path, base + 'name = "Paracétamol 500 µg x"\n'))
    assert rc == 0 and "Paracétamol 500 µg x" in out, err


def test_an_unknown_subcommand_lists_its_groups_commands(capsys):
    rc, out, err = run(capsys, "fe", "foo")
    assert rc == 2 and out == "" and err.splitlines() == [
        "error: command = 'foo' is not allowed: must be one of diametral, punch, strength (the commands of tabletcad fe)"]
    rc, _, err = run(capsys, "foo")
    assert rc == 2 and err.startswith("error: command = 'foo' is not allowed: must be one of build, contact, fe,")


def test_text_values_are_shown_as_given(capsys, tmp_path):
    """Emboss text "   " was shown as ' ' (whitespace collapsed); the repr keeps it."""
    base = '[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 2.8\ncup_depth = 0.9\n[tooling]\n'
    rc, out, err = run(capsys, "report", design(tmp_path, base + '[[tooling.emboss]]\ntext = "   "\n'))
    assert rc == 2 and out == "" and err.splitlines() == [
        "error: tooling.emboss[0].text = '   ' is not allowed: must be a non-empty string"]


def test_a_patch_table_for_an_array_of_tables_is_named(capsys, tmp_path):
    """[patch] written for [[patch]] was reported as "patch = (not given)"."""
    rc, out, err = run(capsys, "report", design(tmp_path, '[tablet]\nfamily = "free_form"\n[patch]\ncurves = []\n'))
    assert rc == 2 and out == "" and err.splitlines() == [
        "error: patch = {'curves': []} is not allowed: must be an array of tables, [[patch]] (double brackets), one for "
        "each patch with its 4 curves; [patch] is a single table"]
    rc, out, err = run(capsys, "report", design(tmp_path, '[tablet]\nfamily = "free_form"\n'))
    assert err.splitlines() == ["error: patch = (not given) is not allowed: a free_form design needs at least one "
                                "[[patch]] with 4 curves"]
