"""Every command's files are byte-reproducible with SOURCE_DATE_EPOCH set: each is run twice and its files compared.

``tabletcad build`` is tests/test_reproducible_outputs.py's.  Here: the pictures (SVG, PDF, PNG) of the
mechanics commands, of ``report`` and of ``fe``, ``report``'s tables (CSV, workbook), the JSON files,
``mesh``, ``optimise``, ``sweep`` and :func:`tabletcad.tooling.tooling_batch`.  The only parts allowed to
differ are the documented timings (README, "Reproducible files"), and the manifests' hashes of the files
holding them.  The runs are in this process, one after the other: matplotlib had salted an SVG's element ids
with a new random UUID at every save.
"""

from __future__ import annotations

import csv
import io
import itertools
import json
import re
import zipfile
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest

from tabletcad.cli import main

ROOT = Path(__file__).resolve().parents[1]
LACTOSE = ROOT / "samples" / "press" / "lactose_appendix_b.csv"
CONCAVE = ROOT / "samples" / "families" / "concave_round.toml"
EPOCH = 1700000000
STAMP = "2023-11-14T22:13:20+00:00"
#: a build's report's timings (README: "Reproducible files"), also the columns of a sweep's results.csv
BUILD_TIMINGS = ("brep.seconds", "brep.export_seconds", "mesh.seconds", "tooling.seconds",
                 "tooling.interference.seconds")
THIN = '[tablet]\nfamily = "flat_face_round"\ndiameter = 8.0\nthickness = 1.0\n'
SWEEP = """[design.tablet]
family = "flat_face_round"
diameter = 6.0
thickness = 2.0

[sweep]
method = "grid"
outputs = ["report", "stl"]

[sweep.vary]
"tablet.thickness" = [2.0, 2.5]
"""


def _inputs(folder: Path) -> None:
    """The tables and designs the cases read, in ``folder``."""
    p = np.array([5.0, 10, 20, 40, 60, 80, 120, 160, 200])
    sf = 0.6 + 0.35 * (1 - np.exp(-p / 80))
    rows = ["pressure_MPa,solid_fraction,tensile_strength_MPa"] + [
        f"{a:.15g},{b:.15g},{8 * np.exp(6 * (b - 1)):.15g}" for a, b in zip(p, sf)]
    (folder / "profiles.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    h = 10 * (1 - 0.02 * p / (1 + 0.05 * p))
    rows = ["pressure_MPa,thickness_mm"] + [f"{a:.15g},{b:.15g}" for a, b in zip(p, h)]
    (folder / "press.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    (folder / "thin.toml").write_text(THIN, encoding="utf-8")
    (folder / "sweep.toml").write_text(SWEEP, encoding="utf-8")


def _cli(*args: Any, rc: int = 0) -> Callable[[Path, int], None]:
    """A case that runs ``tabletcad ARGS`` (paths relative to the run's folder, its current one)."""
    def run(_folder: Path, _k: int) -> None:
        assert main([str(a) for a in args]) == rc
    return run


def _optimise(monkeypatch) -> Callable[[Path, int], None]:
    def run(folder: Path, k: int) -> None:
        # the second run as if on a machine twice as slow: its wall time, 2 s, is the first's 1 s twice
        clock = itertools.count(step=float(k))
        monkeypatch.setattr("tabletcad.optimise.solvers.now", lambda: next(clock))
        _cli("optimise", ROOT / "samples" / "optimise" / "spherical_tablet_a.toml", "--out", "opt", "--quiet")(folder, k)
    return run


def _batch(folder: Path, _k: int) -> None:
    from tabletcad.tooling import tooling_batch

    tooling_batch("flat_face_round", [dict(diameter=6.0, thickness=2.0)], out_dir="batch", progress=False,
                  check=False)


#: case -> (what it runs, {file: its timing keys}, marks)
CASES: dict[str, tuple[Any, dict[str, tuple[str, ...]], tuple]] = {
    "heckel": (_cli("heckel", LACTOSE, "--plot", "heckel.svg", "--json-file", "heckel.json"), {}, ()),
    "heckel_pdf": (_cli("heckel", LACTOSE, "--plot", "heckel.pdf"), {}, ()),
    "profiles": (_cli("profiles", "profiles.csv", "--plot", "profiles.svg", "--json-file", "profiles.json"), {}, ()),
    "contact": (_cli("contact", "--force", 3.5, "--plot", "contact.svg", "--json-file", "contact.json"), {}, ()),
    "contact_png": (_cli("contact", "--force", 3.5, "--plot", "contact.png"), {}, ()),
    "shell": (_cli("shell", "--outer", 2.5, "--inner", 2.0, "--E", 100, "--nu", 0.3, "--p-ext", 3, "--terms", 20,
                   "--csv", "shell.csv", "--plot", "shell.svg", "--json-file", "shell.json"), {}, ()),
    "kawakita": (_cli("kawakita", "press.csv", "--json-file", "kawakita.json"), {}, ()),
    "walker": (_cli("walker", "press.csv", "--json-file", "walker.json"), {}, ()),
    "love": (_cli("love", "--json-file", "love.json"), {}, ()),
    "strength": (_cli("strength", "diametral", "--force", 100, "--diameter", 10, "--thickness", 3,
                      "--json-file", "strength.json"), {}, ()),
    "shapes": (_cli("shapes", "--json-file", "shapes.json"), {}, ()),
    "report": (_cli("report", CONCAVE, "--plot", "report.png", "--json-file", "report.json", "--csv", "report.csv"),
               {}, ()),
    "report_xlsx": (_cli("report", CONCAVE, "--xlsx", "report.xlsx"), {}, (pytest.mark.tables,)),
    **{f"mesh_{fmt}": (_cli("mesh", CONCAVE, "--nodes", 3, 4, 3, "--out", f"mesh.{fmt}"), {}, ())
       for fmt in ("vtu", "xdmf", "msh", "vtk")},
    "optimise": (None, {"opt/report.json": ("wall_time_s",), "opt/tablet/report.json": BUILD_TIMINGS}, ()),
    "fe_diametral": (_cli("fe", "diametral", "thin.toml", "--force", 50, "--mesh-size", 1.5, "--no-error-estimate",
                          "--out", "fe", "--json-file", "fe.json"), {}, (pytest.mark.fe, pytest.mark.cad)),
    "sweep": (_cli("sweep", "sweep.toml", "--out", "sweep", "--workers", 1, "--plot", "volume_mm3", "--quiet"),
              {"sweep/results.csv": BUILD_TIMINGS}, (pytest.mark.sweep, pytest.mark.cad)),
    "tooling_batch": (_batch, {"batch/batch.json": ("seconds", "occ_boolean_seconds")}, (pytest.mark.cad,)),
}
_NEEDS = {"report_xlsx": ("openpyxl",), "fe_diametral": ("skfem", "gmsh", "OCP"), "sweep": ("distributed", "OCP"),
          "tooling_batch": ("OCP", "ezdxf")}


def _files(folder: Path) -> dict[str, Path]:
    return {p.relative_to(folder).as_posix(): p for p in sorted(folder.rglob("*")) if p.is_file()}


def _drop(data: Any, dotted: str) -> None:
    """Remove the key ``dotted`` (``a.b.c``) from ``data``, and from every element of a list on its way."""
    if isinstance(data, list):
        for item in data:
            _drop(item, dotted)
        return
    head, _, rest = dotted.partition(".")
    if rest and isinstance(data.get(head), (dict, list)):
        _drop(data[head], rest)
    elif not rest:
        data.pop(head, None)


def _without_timings(path: Path, keys: tuple[str, ...]) -> Any:
    """The content of a JSON file, or the rows of a CSV file, without the timing ``keys``."""
    text = path.read_text(encoding="utf-8")
    if path.suffix == ".csv":
        return [{k: v for k, v in row.items() if k not in keys} for row in csv.DictReader(io.StringIO(text))]
    data = json.loads(text)
    for key in keys:
        _drop(data, key)
    return data


def _manifest_without(path: Path, root: Path, timed: set[str]) -> dict:
    """A tabletcad manifest without the hashes of the files that may differ (timed, or a manifest in a subfolder)."""
    data = json.loads(path.read_text(encoding="utf-8"))
    base = path.parent.relative_to(root)
    data["files"] = {name: h for name, h in data["files"].items()
                     if not ((base / name).as_posix() in timed or Path(name).name.startswith(".tabletcad-"))}
    return data


@pytest.mark.parametrize("case", [pytest.param(c, marks=CASES[c][2]) for c in CASES])
def test_a_command_run_twice_writes_the_same_bytes(case, tmp_path, monkeypatch):
    for module in _NEEDS.get(case, ()):
        pytest.importorskip(module)
    run, timed, _ = CASES[case]
    if run is None:
        run = _optimise(monkeypatch)
    monkeypatch.setenv("SOURCE_DATE_EPOCH", str(EPOCH))
    folders = []
    for k in (1, 2):
        folder = tmp_path / str(k)
        folder.mkdir()
        _inputs(folder)
        monkeypatch.chdir(folder)  # relative output paths: a JSON file that names its outputs names the same
        run(folder, k)
        folders.append(folder)
    one, two = (_files(f) for f in folders)
    assert sorted(one) == sorted(two)
    assert set(timed) <= set(one), sorted(one)
    written = [n for n in one if n not in ("profiles.csv", "press.csv", "thin.toml", "sweep.toml")]
    assert written
    for name in sorted(written, key=lambda n: Path(n).name.startswith(".tabletcad-")):  # manifests last
        a, b = one[name], two[name]
        if name in timed:
            assert _without_timings(a, timed[name]) == _without_timings(b, timed[name]), name
        elif a.name.startswith(".tabletcad-") and timed:
            assert _manifest_without(a, folders[0], set(timed)) == _manifest_without(b, folders[1], set(timed)), name
        else:
            assert a.read_bytes() == b.read_bytes(), name
    if case == "optimise":  # the timings did differ (the convergence picture had shown them in its title)
        assert json.loads(one["opt/report.json"].read_text())["wall_time_s"] == 1.0
        assert json.loads(two["opt/report.json"].read_text())["wall_time_s"] == 2.0


def test_svg_and_pdf_pictures_are_dated_by_source_date_epoch(tmp_path, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", str(EPOCH))
    monkeypatch.chdir(tmp_path)
    assert main(["heckel", str(LACTOSE), "--plot", "h.svg"]) == 0
    assert main(["heckel", str(LACTOSE), "--plot", "h.pdf"]) == 0
    assert f"<dc:date>{STAMP}</dc:date>" in (tmp_path / "h.svg").read_text(encoding="utf-8")
    assert b"/CreationDate (D:20231114221320Z)" in (tmp_path / "h.pdf").read_bytes()


@pytest.mark.tables
def test_the_workbook_is_dated_by_source_date_epoch(tmp_path, monkeypatch):
    pytest.importorskip("openpyxl")
    monkeypatch.setenv("SOURCE_DATE_EPOCH", str(EPOCH))
    assert main(["report", str(CONCAVE), "--xlsx", str(tmp_path / "r.xlsx")]) == 0
    with zipfile.ZipFile(tmp_path / "r.xlsx") as zf:
        # openpyxl had dated the entries with the local time, and the properties with the time, of writing
        assert {i.date_time for i in zf.infolist()} == {(2023, 11, 14, 22, 13, 20)}
        core = zf.read("docProps/core.xml").decode("utf-8")
    assert core.count(">2023-11-14T22:13:20Z</dcterms:") == 2  # created and modified
    import openpyxl

    assert openpyxl.load_workbook(tmp_path / "r.xlsx")["report"]["A2"].value == "concave_round"


def test_without_source_date_epoch_an_svg_is_dated_now_in_utc(tmp_path, monkeypatch):
    from datetime import datetime, timezone

    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    before = datetime.now(timezone.utc).replace(microsecond=0)
    assert main(["contact", "--force", "3.5", "--plot", str(tmp_path / "c.svg")]) == 0
    stamp = re.search(r"<dc:date>([^<]+)</dc:date>", (tmp_path / "c.svg").read_text(encoding="utf-8")).group(1)
    assert stamp.endswith("+00:00")  # matplotlib had written the local time, without its offset
    assert before <= datetime.fromisoformat(stamp) <= datetime.now(timezone.utc)


def test_save_figure_into_a_stream_and_a_file_gives_the_same_bytes(tmp_path, monkeypatch):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from tabletcad.io.figures import save_figure

    monkeypatch.setenv("SOURCE_DATE_EPOCH", str(EPOCH))
    fig = Figure()
    FigureCanvasAgg(fig)
    fig.subplots().plot([0, 1], [1, 0])
    buf = io.BytesIO()
    assert save_figure(fig, buf, fmt="svg") is None
    assert save_figure(fig, tmp_path / "f.svg") == tmp_path / "f.svg"
    assert buf.getvalue() == (tmp_path / "f.svg").read_bytes()
    assert f"<dc:date>{STAMP}</dc:date>".encode() in buf.getvalue()


def test_redate_zip_keeps_the_entries_and_dates_them(monkeypatch):
    from datetime import datetime, timezone

    from tabletcad.io.timestamp import redate_zip

    src = io.BytesIO()
    with zipfile.ZipFile(src, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("b.xml", "<b/>" * 50)
        zf.writestr(zipfile.ZipInfo("a.txt", date_time=(2001, 2, 3, 4, 5, 6)), "a")
    out = redate_zip(src.getvalue(), datetime(1970, 1, 1, tzinfo=timezone.utc))
    with zipfile.ZipFile(io.BytesIO(out)) as zf:
        infos = zf.infolist()
        assert [(i.filename, i.date_time, i.compress_type) for i in infos] == [
            ("b.xml", (1980, 1, 1, 0, 0, 0), zipfile.ZIP_DEFLATED), ("a.txt", (1980, 1, 1, 0, 0, 0), zipfile.ZIP_STORED)]
        assert zf.read("b.xml") == b"<b/>" * 50 and zf.read("a.txt") == b"a"
    monkeypatch.setenv("SOURCE_DATE_EPOCH", str(EPOCH))
    with zipfile.ZipFile(io.BytesIO(redate_zip(src.getvalue()))) as zf:
        assert {i.date_time for i in zf.infolist()} == {(2023, 11, 14, 22, 13, 20)}


def test_every_picture_is_saved_through_save_figure():
    # one place fixes the SVG salt and the dates: a savefig or print_figure anywhere else would bypass it
    package = ROOT / "tabletcad"
    found = [f"{p.relative_to(ROOT)}:{n}" for p in sorted(package.rglob("*.py")) if p != package / "io" / "figures.py"
             for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
             if re.search(r"\.(savefig|print_figure|print_svg|print_pdf|print_png)\(", line)]
    assert found == []
