"""The command line's parallel build (:mod:`tabletcad.io.forked`): a parallel tooling build (picture,
writers and the gap in three children) writes the same files and report as the one-process build;
a failure in a child or in the parent leaves no file and no process behind."""

import json
import os
from pathlib import Path

import pytest

from support.processes import gone
from tabletcad.errors import DesignError
from tabletcad.io import forked
from tabletcad.io.forked import Forked

pytest.importorskip("OCP")
pytest.importorskip("manifold3d")

pytestmark = [pytest.mark.cad]

ROOT = Path(__file__).resolve().parents[1]


SAMPLE = ROOT / "samples" / "tooling" / "shallow_convex_round.toml"
#: a tool set of flat faces, for the failures (the same three children; its parallel build 2.6 CPU-s, SAMPLE's 4.3)
FLAT = {"tablet": {"family": "flat_face_round", "diameter": 8.0, "thickness": 3.0},
        "tooling": {"clearance_mm": 0.02, "tip_length_mm": 6.0}}


class _Recording(Forked):
    made: list = []

    def __init__(self, work):
        super().__init__(work)
        # (a fork the system refused runs its work in this process: the test then names the reason)
        assert self.pid is not None, f"the system refused the fork: {self.refused!r}"
        _Recording.made.append(self.pid)


@pytest.fixture
def recorded(monkeypatch):
    """Every Forked child of the build, recorded; the parallel path taken on any machine."""
    import tabletcad.pipeline.build as build

    _Recording.made = []
    monkeypatch.setattr(forked, "Forked", _Recording)
    monkeypatch.setattr(build, "Forked", _Recording)
    monkeypatch.setattr(forked, "can_fork", lambda: True)
    monkeypatch.setattr(build, "can_fork", lambda: True)
    return _Recording.made


def _without_seconds(report: dict) -> dict:
    def clean(o):
        if isinstance(o, dict):
            return {k: clean(v) for k, v in o.items() if "seconds" not in k}
        if isinstance(o, list):
            return [clean(v) for v in o]
        return o

    return clean(report)


@pytest.mark.cad
def test_a_parallel_tooling_build_writes_what_the_sequential_one_writes(tmp_path, recorded, monkeypatch):
    import tabletcad.pipeline.build as build
    from tabletcad.pipeline.build import build_design

    shared = []  # the forks made when the two drawing children's modules were imported: none yet
    monkeypatch.setattr(build, "import_shared", lambda: shared.append(len(recorded)))
    seq = build_design(SAMPLE, tmp_path / "seq", progress=False, parallel=False)
    assert recorded == [] and shared == []
    par = build_design(SAMPLE, tmp_path / "par", progress=False, parallel=True)
    # the picture, the tooling's writers and the closed-position check's gap
    assert len(recorded) == 3 and all(gone(p) for p in recorded)
    assert shared == [0]
    assert sorted(os.listdir(tmp_path / "par")) == sorted(os.listdir(tmp_path / "seq"))
    assert _without_seconds(par) == _without_seconds(seq)
    assert par["tooling"]["drawing"]["dimension_texts"] and par["tooling"]["files"] == seq["tooling"]["files"]
    on_disk = json.loads((tmp_path / "par" / "report.json").read_text())
    assert list(on_disk["tooling"]) == list(json.loads((tmp_path / "seq" / "report.json").read_text())["tooling"])
    for name in ("upper_punch.step", "die.step", "drawing.dxf", "tablet.png"):  # the children's files are whole
        assert (tmp_path / "par" / name).stat().st_size > 1000


@pytest.mark.cad
@pytest.mark.parametrize("where", ["drawing", "picture", "closed_position", "gap"])
def test_a_failure_in_either_process_leaves_nothing(tmp_path, recorded, monkeypatch, where):
    import tabletcad.pipeline.build as build
    import tabletcad.tooling.drawing as drawing
    import tabletcad.tooling.interference as interference
    import tabletcad.tooling.toolset as toolset
    from tabletcad.pipeline.build import build_design

    def fail(*a, **k):
        raise DesignError("test", where, "fails here on purpose")

    target = {"drawing": (drawing, "write_drawing"), "picture": (build, "plot_tablet"),
              "closed_position": (toolset, "check_closed_position"), "gap": (interference, "_largest_gap")}[where]
    from tabletcad.pipeline.design import Design

    monkeypatch.setattr(*target, fail)
    out = tmp_path / "out"
    with pytest.raises(DesignError, match=f"test = '{where}' is not allowed: fails here on purpose"):
        build_design(Design.from_dict(FLAT, "flat"), out, progress=False, parallel=True)
    assert not out.exists() and os.listdir(tmp_path) == []
    assert recorded and all(gone(p) for p in recorded)


@pytest.mark.cad
def test_an_fe_rating_waits_for_the_closed_position_check(tmp_path, recorded, monkeypatch):
    """With ``[tooling.fe_rating]`` the parallel build keeps the one-process order: the check, then the
    FE rating (none for tooling that fails the check), then the files."""
    import tabletcad.tooling.toolset as toolset
    from tabletcad.pipeline.design import Design
    from tabletcad.tooling.stage import tooling_stage

    calls = []

    def fail(*a, **k):
        calls.append("check")
        raise DesignError("test", "check", "fails here on purpose")

    monkeypatch.setattr(toolset, "check_closed_position", fail)
    d = Design.from_toml(SAMPLE)
    with pytest.raises(DesignError, match="fails here on purpose"):
        tooling_stage(tablet=d.build(), spec=d.tooling_spec, shape=None, out=tmp_path, report={},
                      fe_rating=lambda ts: calls.append("fe") or {}, parallel=True)
    assert calls == ["check"] and os.listdir(tmp_path) == [] and recorded == []
