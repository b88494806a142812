"""The command line's parallel build (:mod:`tabletcad.io.forked`): a forked child returns its value or
its exception, is stopped by ``cancel``, and never uses OCC's thread pool; a parallel tooling build
(picture, writers and the gap in three children) writes the same files and report as the sequential
one; a failure in a child or in the parent leaves no file and no process behind."""

import json
import os
import time
from pathlib import Path

import pytest

from tabletcad.errors import DesignError, GeometryError
from tabletcad.io import forked
from tabletcad.io.forked import OCC_PARALLEL, Forked

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="os.fork is POSIX only")

ROOT = Path(__file__).resolve().parents[1]


def _gone(pid: int) -> bool:
    """True when ``pid`` is no child of this process any more (reaped: no zombie left)."""
    try:
        os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        return True
    return False


class _Unpicklable(Exception):
    def __init__(self, a, b):  # an attribute pickle cannot take (with or without tblib's exception pickling)
        super().__init__(f"{a} and {b}")
        self.callback = lambda: None


def test_the_child_returns_its_value_and_runs_occ_without_its_thread_pool():
    child = Forked(lambda: (sum(range(10)), OCC_PARALLEL[0], os.getpid()))
    total, occ_parallel, pid = child.result()
    assert total == 45 and occ_parallel is False and pid == child.pid != os.getpid()
    assert OCC_PARALLEL[0] is True  # the parent's is left alone
    assert _gone(child.pid)


def test_the_childs_exception_is_raised_in_the_parent():
    def bad():
        raise DesignError("[tooling] clearance_mm", -1.0, "must be > 0")

    child = Forked(bad)
    with pytest.raises(DesignError) as e:
        child.result()
    assert str(e.value) == str(DesignError("[tooling] clearance_mm", -1.0, "must be > 0"))
    assert _gone(child.pid)
    if hasattr(e.value, "__notes__"):  # Python >= 3.11: the child's traceback comes along
        assert "in bad" in e.value.__notes__[-1] and "forked helper" in e.value.__notes__[-1]

    def geometry():
        raise GeometryError("sewing left 2 free edges", object())

    with pytest.raises(GeometryError, match="^sewing left 2 free edges"):
        Forked(geometry).result()
    assert str(pytest.raises(GeometryError, lambda: Forked(geometry).result()).value) == "sewing left 2 free edges"

    def unpicklable():
        raise _Unpicklable("left", "right")

    with pytest.raises(RuntimeError, match="_Unpicklable: left and right"):
        Forked(unpicklable).result()


def test_a_refused_fork_runs_the_work_here_and_closed_output_streams_do_not_matter(monkeypatch):
    import sys

    def refuse():
        raise OSError(11, "Resource temporarily unavailable")

    before = len(os.listdir("/proc/self/fd"))
    with monkeypatch.context() as m:
        m.setattr(os, "fork", refuse)
        child = Forked(lambda: os.getpid())
    assert child.pid is None and child.result() == os.getpid()  # run in this process, when asked
    assert len(os.listdir("/proc/self/fd")) == before  # the pipe was closed
    monkeypatch.setattr(sys, "stdout", None)  # `tabletcad build ... >&-`
    assert Forked(lambda: 7).result() == 7


def test_an_interrupted_wait_leaves_no_child_and_no_descriptor():
    """Ctrl-C while the parent waits (here: the child's read raises) ends in cancel without a second close."""
    import signal

    before = len(os.listdir("/proc/self/fd"))
    old = signal.signal(signal.SIGALRM, lambda *a: (_ for _ in ()).throw(KeyboardInterrupt()))
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.3)
        with pytest.raises(KeyboardInterrupt):
            with Forked(lambda: time.sleep(30)) as child:
                child.result()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    assert _gone(child.pid) and len(os.listdir("/proc/self/fd")) == before


def test_the_child_dies_with_its_parent(tmp_path):
    """A parent killed outright (SIGKILL) takes its helper with it: no writer goes on alone."""
    import subprocess
    import sys

    code = ("import os, sys, time\n"
            "from tabletcad.io.forked import Forked\n"
            "c = Forked(lambda: time.sleep(60))\n"
            "print(c.pid, flush=True)\n"
            "time.sleep(60)\n")
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True,
                         env={**os.environ, "PYTHONPATH": str(ROOT)})
    pid = int(p.stdout.readline())
    p.kill()
    p.wait(timeout=30)
    for _ in range(100):  # the orphan is killed by the kernel and reaped by init
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            break
        time.sleep(0.1)
    else:
        raise AssertionError(f"helper {pid} outlived its parent")


def test_a_child_that_dies_is_an_error_and_cancel_stops_a_running_one():
    child = Forked(lambda: os._exit(3))
    with pytest.raises(RuntimeError, match="ended without a result"):
        child.result()
    t0 = time.perf_counter()
    with Forked(lambda: time.sleep(60)) as sleeper:
        pass  # leaving the block without a result cancels it
    assert time.perf_counter() - t0 < 10.0
    assert _gone(sleeper.pid)


# ----------------------------------------------------------------------------- builds
pytest.importorskip("OCP")
pytest.importorskip("manifold3d")

SAMPLE = ROOT / "samples" / "tooling" / "shallow_convex_round.toml"


class _Recording(Forked):
    made: list = []

    def __init__(self, work):
        super().__init__(work)
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
def test_a_parallel_tooling_build_writes_what_the_sequential_one_writes(tmp_path, recorded):
    from tabletcad.pipeline.build import build_design

    seq = build_design(SAMPLE, tmp_path / "seq", progress=False, parallel=False)
    assert recorded == []
    par = build_design(SAMPLE, tmp_path / "par", progress=False, parallel=True)
    # the picture, the tooling's writers and the closed-position check's gap
    assert len(recorded) == 3 and all(_gone(p) for p in recorded)
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
    monkeypatch.setattr(*target, fail)
    out = tmp_path / "out"
    with pytest.raises(DesignError, match=f"test = '{where}' is not allowed: fails here on purpose"):
        build_design(SAMPLE, out, progress=False, parallel=True)
    assert not out.exists() and os.listdir(tmp_path) == []
    assert recorded and all(_gone(p) for p in recorded)
