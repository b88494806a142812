"""The command line's parallel build (:mod:`tabletcad.io.forked`): a forked child returns its value or
its exception, is stopped by ``cancel``, dies with its parent and never uses OCC's thread pool; a
refused fork runs the work in the parent.  The builds themselves: ``test_build_parallel_cad.py``."""

import os
import time
from pathlib import Path

import pytest

from support.processes import gone
from tabletcad.errors import DesignError, GeometryError
from tabletcad.io.forked import OCC_PARALLEL, Forked

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="os.fork is POSIX only")

ROOT = Path(__file__).resolve().parents[1]


class _Unpicklable(Exception):
    def __init__(self, a, b):  # an attribute pickle cannot take (with or without tblib's exception pickling)
        super().__init__(f"{a} and {b}")
        self.callback = lambda: None


def test_the_child_returns_its_value_and_runs_occ_without_its_thread_pool():
    child = Forked(lambda: (sum(range(10)), OCC_PARALLEL[0], os.getpid()))
    total, occ_parallel, pid = child.result()
    assert total == 45 and occ_parallel is False and pid == child.pid != os.getpid()
    assert OCC_PARALLEL[0] is True  # the parent's is left alone
    assert gone(child.pid)


def test_the_childs_exception_is_raised_in_the_parent():
    def bad():
        raise DesignError("[tooling] clearance_mm", -1.0, "must be > 0")

    child = Forked(bad)
    with pytest.raises(DesignError) as e:
        child.result()
    assert str(e.value) == str(DesignError("[tooling] clearance_mm", -1.0, "must be > 0"))
    assert gone(child.pid)
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
    assert gone(child.pid) and len(os.listdir("/proc/self/fd")) == before


@pytest.mark.parametrize("other_thread", [False, True])
def test_a_ctrl_c_during_the_fork_leaves_no_child_writing(monkeypatch, tmp_path, other_thread):
    """A Ctrl-C that comes during the fork (held in this thread by the signal mask, or taken by another
    thread, whose delivery Python raises in this one at once: OCC's pool, a test runner's I/O thread)
    is raised only once the child is recorded, and the constructor then stops the child it had
    started: the caller never gets the object to cancel, and the child ignores Ctrl-C, so it would
    write on into a staging folder being removed (seen once in a build interrupted 1.5 s in)."""
    import signal
    import threading

    real_fork, pids = os.fork, []

    def fork_then_ctrl_c():
        pid = real_fork()
        if pid:  # the parent
            pids.append(pid)
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)  # time for another thread to take it
        return pid

    stop = threading.Event()
    if other_thread:  # a thread that does not block SIGINT, so the system may deliver it there
        threading.Thread(target=stop.wait, daemon=True).start()
    late = tmp_path / "late.png"
    monkeypatch.setattr(os, "fork", fork_then_ctrl_c)
    try:
        with pytest.raises(KeyboardInterrupt):
            Forked(lambda: (time.sleep(0.5), late.write_text("written after the interrupt")))
    finally:
        monkeypatch.undo()
        stop.set()
    assert pids and gone(pids[0])
    time.sleep(1.0)
    assert not late.exists()


def test_a_ctrl_c_as_the_build_takes_its_picture_child_stops_the_child(monkeypatch, tmp_path):
    """A Ctrl-C just after the picture's child is made, before the build has it in hand: raised once it
    is, so the build's clean-up stops the child and removes the staging folder."""
    import signal

    import tabletcad.pipeline.build as build

    pids = []

    class _CtrlCAfter(Forked):
        def __init__(self, work):
            super().__init__(work)
            pids.append(self.pid)
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)  # (Python runs the handler here)

    monkeypatch.setattr(build, "Forked", _CtrlCAfter)
    monkeypatch.setattr(build, "can_fork", lambda: True)
    with pytest.raises(KeyboardInterrupt):
        build.build_design(ROOT / "samples" / "families" / "concave_round.toml", tmp_path / "out", cad=False,
                           progress=False, parallel=True)
    assert pids and pids[0] is not None and gone(pids[0])
    time.sleep(1.0)
    assert os.listdir(tmp_path) == []


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
    assert gone(sleeper.pid)


def test_the_child_freezes_the_heap_it_inherits_and_the_parents_is_left_alone():
    """The child's collector walks only the objects the child makes (``gc.freeze`` after the fork): the
    parent's objects are in the child's permanent generation, none of them in the parent's."""
    import gc

    frozen_before = gc.get_freeze_count()
    tracked = len(gc.get_objects())  # the parent's objects the collector walks (the permanent one's excepted)
    in_child = Forked(lambda: (gc.get_freeze_count(), len(gc.get_objects()))).result()
    assert in_child[0] >= frozen_before + tracked // 2 and in_child[1] < tracked // 2
    assert gc.get_freeze_count() == frozen_before


def test_fewer_full_collections_within_the_block_and_the_thresholds_restored_after():
    import gc

    from tabletcad.collector import FULL_FACTOR, fewer_full_collections

    old = gc.get_threshold()
    with fewer_full_collections() as inside:
        assert inside == gc.get_threshold() == (old[0], old[1], old[2] * FULL_FACTOR) and FULL_FACTOR > 1
    assert gc.get_threshold() == old
    with pytest.raises(KeyError):
        with fewer_full_collections(3):
            assert gc.get_threshold()[2] == 3 * old[2]
            raise KeyError("a failing build")
    assert gc.get_threshold() == old
    with pytest.raises(ValueError, match="factor = 0 must be >= 1"):
        with fewer_full_collections(0):
            pass


def test_the_build_command_builds_with_fewer_full_collections(monkeypatch, tmp_path):
    import gc

    import tabletcad.pipeline.build as build
    from tabletcad.cli import main
    from tabletcad.collector import FULL_FACTOR

    seen = []

    def fake(*a, **k):
        seen.append(gc.get_threshold())
        raise DesignError("test", "build", "stops here on purpose")

    monkeypatch.setattr(build, "build_design", fake)
    old = gc.get_threshold()
    assert main(["build", str(ROOT / "samples" / "tooling" / "concave_round_bisect.toml"), "--out",
                 str(tmp_path / "out")]) == 2
    assert seen == [(old[0], old[1], old[2] * FULL_FACTOR)] and gc.get_threshold() == old


def test_import_shared_imports_what_both_drawing_children_draw_with():
    """Run in a fresh interpreter: the modules are not there before, are after (and the picture's and the
    drawings' modules import them from there)."""
    import subprocess
    import sys

    code = ("import sys\n"
            "from tabletcad.pipeline.build import SHARED_IMPORTS, import_shared\n"
            "assert SHARED_IMPORTS and not any(m in sys.modules for m in SHARED_IMPORTS), SHARED_IMPORTS\n"
            "import_shared()\n"
            "assert all(m in sys.modules for m in SHARED_IMPORTS)\n"
            "print('ok')\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                         env={**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"})
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr
