"""Byte-reproducible outputs: with SOURCE_DATE_EPOCH set, two builds of one design give the same files.

A tooling build writes every kind of output of ``tabletcad build`` (STEP, STL, GLB, PNG, report) and of
the tooling (assembly and part STEP, DXF, SVG, PDF); its report differs only in the documented timings.
"""

from __future__ import annotations

import filecmp
import json
import os
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

pytest.importorskip("OCP")
pytest.importorskip("ezdxf")
pytest.importorskip("matplotlib")

from tabletcad.cad.export import export  # noqa: E402

pytestmark = pytest.mark.cad

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "samples" / "tooling" / "concave_round_bisect.toml"
EPOCH = 1700000000
STAMP = "2023-11-14T22:13:20+00:00"
#: the report's keys that hold seconds of CPU or wall time, which no two runs share (README: "Reproducible files")
TIMINGS = ("brep.seconds", "brep.export_seconds", "mesh.seconds", "tooling.seconds", "tooling.interference.seconds")


def _build(out: Path, epoch: int | None, hash_seed: int) -> None:
    env = {k: v for k, v in os.environ.items() if k != "SOURCE_DATE_EPOCH"}
    env["PYTHONHASHSEED"] = str(hash_seed)  # two salts for str hashes: an order of a set of names shows
    env["PYTHONPATH"] = str(ROOT) + os.pathsep + env.get("PYTHONPATH", "")
    if epoch is not None:
        env["SOURCE_DATE_EPOCH"] = str(epoch)
    proc = subprocess.run([sys.executable, "-m", "tabletcad", "build", str(SAMPLE), "--out", str(out), "--quiet"],
                          env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr


@pytest.fixture(scope="module")
def two_builds(tmp_path_factory):
    root = tmp_path_factory.mktemp("repro")
    # separate processes: OCC had ordered the assembly's colours by heap addresses, ezdxf the DXF's
    # classes by Python's hash salt
    for name, seed in (("one", 1), ("two", 4)):  # (1 and 4 order LAYOUT and ACDBPLACEHOLDER apart)
        _build(root / name, EPOCH, seed)
    return root / "one", root / "two"


def _without(report: dict, dotted: str) -> None:
    *path, last = dotted.split(".")
    for key in path:
        report = report[key]
    report.pop(last)


def test_two_builds_give_the_same_bytes(two_builds):
    one, two = two_builds
    names = sorted(p.name for p in one.iterdir())
    assert names == sorted(p.name for p in two.iterdir())
    for kind in ("assembly.step", "upper_punch.step", "lower_punch.step", "die.step", "tablet.step", "tablet.stl",
                 "tablet.glb", "tablet.png", "drawing.dxf", "drawing.svg", "drawing.pdf", "tooling.dxf",
                 "tooling.svg", "tooling.pdf"):
        assert kind in names
    differ = [n for n in names if not filecmp.cmp(one / n, two / n, shallow=False)]
    # the report's timings, and so its hash in the build's manifest, are all that may differ
    assert set(differ) <= {"report.json", ".tabletcad-build.json"}, differ
    reports = [json.loads((d / "report.json").read_text(encoding="utf-8")) for d in (one, two)]
    for r in reports:
        for key in TIMINGS:
            _without(r, key)
    assert reports[0] == reports[1]


def test_every_file_is_stamped_with_source_date_epoch(two_builds):
    one, _ = two_builds
    for step in one.glob("*.step"):
        header = step.read_text(encoding="ascii").split("ENDSEC;")[0]
        assert re.search(r"FILE_NAME\('[^']*','" + re.escape(STAMP) + "'", header), (step.name, header)
    for dxf in ("drawing.dxf", "tooling.dxf"):
        text = (one / dxf).read_text(encoding="utf-8")
        days = {float(v) for v in re.findall(r"\$TDU?(?:CREATE|UPDATE)\n 40\n(\S+)\n", text)}
        # AutoCAD's Julian date: the day number from civil midnight (1970-01-01 is day 2440588), plus the day's fraction
        assert len(days) == 1 and days.pop() == pytest.approx(2440588 + EPOCH / 86400.0, abs=1e-6)
        assert text.count(f" @ {STAMP}") == 2  # CREATED_BY_EZDXF and WRITTEN_BY_EZDXF
    for svg in ("drawing.svg", "tooling.svg"):
        assert f"<dc:date>{STAMP}</dc:date>" in (one / svg).read_text(encoding="utf-8")
    for pdf in ("drawing.pdf", "tooling.pdf"):
        assert b"/CreationDate (D:20231114221320Z)" in (one / pdf).read_bytes()


def test_dxf_guids_are_the_content_s(two_builds):
    one, _ = two_builds
    text = (one / "drawing.dxf").read_text(encoding="utf-8")
    fp = re.search(r"\$FINGERPRINTGUID\n  2\n(\S+)\n", text).group(1)
    ver = re.search(r"\$VERSIONGUID\n  2\n(\S+)\n", text).group(1)
    assert re.fullmatch(r"\{[0-9A-F]{8}-[0-9A-F]{4}-5[0-9A-F]{3}-[89AB][0-9A-F]{3}-[0-9A-F]{12}\}", fp), fp
    assert fp != ver and fp not in (one / "tooling.dxf").read_text(encoding="utf-8")


def test_assembly_colours_in_part_order(two_builds):
    one, _ = two_builds
    text = (one / "assembly.step").read_text(encoding="ascii")
    colours = re.findall(r"COLOUR_RGB\('',([\d.]+),([\d.]+),([\d.]+)\)", text)
    # tablet off-white, then the punches' one steel blue (shared), then the die grey, as the parts were added
    assert [tuple(round(float(c), 2) for c in rgb) for rgb in colours] == [
        (0.93, 0.93, 0.86), (0.62, 0.68, 0.78), (0.55, 0.55, 0.58)]


def test_without_source_date_epoch_the_step_header_has_the_time_of_writing(tmp_path, monkeypatch):
    from datetime import datetime, timezone

    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox

    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    before = datetime.now(timezone.utc).replace(microsecond=0)
    export(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape(), tmp_path / "box.step")
    stamp = re.search(r"FILE_NAME\('[^']*','([^']+)'", (tmp_path / "box.step").read_text(encoding="ascii")).group(1)
    assert stamp.endswith("+00:00")  # UTC, said so (OCC wrote the local time without its zone)
    assert before <= datetime.fromisoformat(stamp) <= datetime.now(timezone.utc)


def test_3mf_twice_is_the_same_zip_dated_by_the_epoch(tmp_path, monkeypatch):
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox

    monkeypatch.setenv("SOURCE_DATE_EPOCH", str(EPOCH))
    box = BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape()
    a = export(box, tmp_path / "a.3mf", linear_deflection=0.1)
    import time

    time.sleep(2.1)  # a zip entry's date has a resolution of two seconds
    b = export(box, tmp_path / "b.3mf", linear_deflection=0.1)
    assert a.read_bytes() == b.read_bytes()
    with zipfile.ZipFile(a) as zf:
        assert {i.date_time for i in zf.infolist()} == {(2023, 11, 14, 22, 13, 20)}


TAIL = """ISO-10303-21;
HEADER;
ENDSEC;
DATA;
#1 = SHAPE_REPRESENTATION('a #9',(#2),#3);
#2 = SOLID('');
#3 = CONTEXT('');
#4 = SOLID('');
#5 = CONTEXT('');
{tail}ENDSEC;
END-ISO-10303-21;
"""


def test_style_tail_is_renumbered_by_what_it_styles():
    from tabletcad.cad.export import canonical_style_order

    blue_first = ("#6 = MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION('',(#7)\n  ,#5);\n"
                  "#7 = STYLED_ITEM('color',(#8),#4);\n#8 = COLOUR_RGB('b;''#1',0.,0.,1.);\n"
                  "#9 = MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION('',(#10),#3);\n"
                  "#10 = STYLED_ITEM('color',(#11),#2);\n#11 = COLOUR_RGB('',1.,0.,0.);\n")
    red_first = ("#6 = MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION('',(#7),#3);\n"
                 "#7 = STYLED_ITEM('color',(#8),#2);\n#8 = COLOUR_RGB('',1.,0.,0.);\n"
                 "#9 = MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION('',(#10)\n  ,#5);\n"
                 "#10 = STYLED_ITEM('color',(#11),#4);\n#11 = COLOUR_RGB('b;''#1',0.,0.,1.);\n")
    a = canonical_style_order(TAIL.format(tail=blue_first))
    assert a == canonical_style_order(TAIL.format(tail=red_first)) == TAIL.format(tail=red_first)
    assert "#1 = SHAPE_REPRESENTATION('a #9',(#2),#3);" in a  # strings and the entities before the tail kept
    # a file whose earlier entities refer into the tail is left as it is
    odd = TAIL.format(tail=blue_first).replace("(#2),#3)", "(#2,#7),#3)")
    assert canonical_style_order(odd) == odd


def test_an_assembly_written_twice_in_one_process_is_the_same_file(tmp_path):
    # OCC numbers the assembly links (NEXT_ASSEMBLY_USAGE_OCCURRENCE ids) from a counter of the process:
    # the second file had ids 3 and 4 (the second size of a tooling batch: 5 to 8)
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox

    from tabletcad.tooling.assembly import write_assembly

    parts = {"tablet": BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape(), "die": BRepPrimAPI_MakeBox(4.0, 4.0, 1.0).Shape()}
    a = write_assembly(parts, tmp_path / "a.step")
    b = write_assembly(parts, tmp_path / "b.step")
    text = a.read_text(encoding="ascii")
    assert re.findall(r"NEXT_ASSEMBLY_USAGE_OCCURRENCE\('(\d+)','(\w+)'", text) == [("1", "tablet"), ("2", "die")]
    assert a.read_bytes() == b.read_bytes()


def test_nauo_ids_are_numbered_in_file_order():
    from tabletcad.cad.export import canonical_nauo_ids

    text = ("#7 = NEXT_ASSEMBLY_USAGE_OCCURRENCE('13','a','',#5,#6,$);\n#9 = PRODUCT('NEXT_ASSEMBLY_USAGE_OCCURRENCE"
            "(''2''','','',(#1));\n#12 =  NEXT_ASSEMBLY_USAGE_OCCURRENCE( '14','b','',#5,#8,$);\n")
    assert canonical_nauo_ids(text) == text.replace("'13'", "'1'").replace("'14'", "'2'")
