"""``tabletcad sweep`` stopped by a signal, as a real process in its own process group (a terminal's
Ctrl-C reaches the whole group; a process manager's SIGTERM the command, or the group).

A run stopped before its first design leaves nothing: no ``--out`` folder nor the parents it made, and a
folder that existed before holds only what it held.  One stopped between designs keeps the rows written
(the journal ``--resume`` reads).  Ctrl-C: one line ``interrupted``, status 130; SIGTERM: status 143,
nothing printed.  Nothing else on stderr: no worker tracebacks, no resource tracker's warning of leaked
semaphores, no Dask log; and no process of the run left alive.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest

pytestmark = pytest.mark.sweep
pytest.importorskip("distributed")
pytest.importorskip("pandas")
psutil = pytest.importorskip("psutil")  # (a dependency of distributed)

from tabletcad.sweep.results import JOURNAL, read_done  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

# the cheapest designs: flat-faced rounds, report only; far more than a test waits for
SWEEP = ('[design.tablet]\nfamily = "flat_face_round"\ndiameter = 8.0\nthickness = 3.0\n'
         '[sweep.vary]\n"tablet.thickness" = { min = 2.0, max = 4.0, num = 400 }\n')
STATUS = {signal.SIGINT: 130, signal.SIGTERM: 143}
STDERR = {signal.SIGINT: "interrupted\n", signal.SIGTERM: ""}


def _workers_starting(pid: int) -> bool:
    """Whether the process ``pid`` has started a worker process (multiprocessing's spawn)."""
    try:
        return any("spawn_main" in " ".join(c.cmdline()) for c in psutil.Process(pid).children(recursive=True))
    except psutil.Error:
        return False


def _alive_in_session(sid: int) -> list[str]:
    """The processes of session ``sid`` that still run (zombies, gone but not yet reaped, aside)."""
    alive = []
    for proc in psutil.process_iter(["pid", "status", "cmdline"]):
        try:
            if os.getsid(proc.pid) == sid and proc.info["status"] != psutil.STATUS_ZOMBIE:
                alive.append(" ".join(proc.info["cmdline"] or []))
        except (OSError, psutil.Error):
            continue
    return alive


def _stop_sweep(tmp_path: Path, out: Path, ready: Callable[[subprocess.Popen], bool], sig: int, *,
                group: bool = True, workers: int = 1, start_method: str | None = None) -> tuple[int, str]:
    """Run ``tabletcad sweep`` into ``out``, send ``sig`` (to its process group, or to it alone) once
    ``ready(process)``, and return its status and stderr; check that none of its processes is left.
    ``start_method``: multiprocessing's default in the command's process (else the platform's)."""
    sweep = tmp_path / "s.toml"
    sweep.write_text(SWEEP, encoding="utf-8")
    program = ["-m", "tabletcad"] if start_method is None else [
        "-c", f"import multiprocessing, sys; multiprocessing.set_start_method({start_method!r}); "
              "from tabletcad.cli import main; sys.argv[0] = 'tabletcad'; sys.exit(main())"]
    p = subprocess.Popen([sys.executable, *program, "sweep", str(sweep), "--out", str(out), "--workers",
                          str(workers), "--quiet"], cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(ROOT)},
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        t0 = time.monotonic()
        while not ready(p) and p.poll() is None and time.monotonic() - t0 < 120:
            time.sleep(0.005)
        assert p.poll() is None, p.communicate()
        (os.killpg if group else os.kill)(p.pid, sig)
        _, err = p.communicate(timeout=120)
        t0 = time.monotonic()
        while _alive_in_session(p.pid) and time.monotonic() - t0 < 10:
            time.sleep(0.1)
        assert _alive_in_session(p.pid) == []
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
            p.communicate()
    return p.returncode, err


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_sweep_stopped_before_its_first_design_leaves_no_folder(tmp_path, sig):
    """Stopped once its --out folder is made (the cluster is up), before the first design is in: the
    folder goes, and so do the parents the run made.  A SIGTERM had ended the process at once (status
    -15), leaving the empty folder and printing the resource tracker's warning of 6 leaked semaphores."""
    out = tmp_path / "new" / "out"
    rc, err = _stop_sweep(tmp_path, out, lambda p: out.exists(), sig)
    assert (rc, err) == (STATUS[sig], STDERR[sig])
    assert sorted(q.name for q in tmp_path.iterdir()) == ["s.toml"]


def test_a_sigterm_to_the_command_alone_leaves_a_given_folder_as_it_was(tmp_path):
    """A folder that existed before keeps what it held, and only that: a SIGTERM sent to the command
    alone (a process manager's) while its workers start; the cluster's closing ends the workers."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "mine.txt").write_text("kept", encoding="utf-8")
    rc, err = _stop_sweep(tmp_path, out, lambda p: _workers_starting(p.pid), signal.SIGTERM, group=False)
    assert (rc, err) == (143, "")
    assert [(q.name, q.read_text()) for q in out.iterdir()] == [("mine.txt", "kept")]


def test_a_sigterm_between_designs_keeps_the_rows_written(tmp_path):
    """Stopped between designs, the journal stays for --resume, and nothing else is written; Dask's
    in-process scheduler had logged "Couldn't gather keys" for the result the client no longer fetched."""
    out = tmp_path / "out"
    journal = out / JOURNAL
    rc, err = _stop_sweep(tmp_path, out, lambda p: journal.exists() and journal.stat().st_size > 0, signal.SIGTERM)
    assert (rc, err) == (143, "")
    assert [q.name for q in out.iterdir()] == [JOURNAL]
    assert 1 <= len(read_done(out)) < 400


def test_a_ctrl_c_while_the_workers_start_prints_one_line(tmp_path):
    """A terminal's Ctrl-C reaches the workers too.  Sent while they start, it had killed them in their
    imports (their tracebacks after ``interrupted``) and cut the cluster's start in two: the half-started
    cluster was never closed, and Python's resource tracker printed "There appear to be 12 leaked
    semaphore objects to clean up at shutdown" (the nannies' multiprocessing queues, 6 semaphores a
    worker).  The workers are now born with SIGINT blocked, and the start ends before the Ctrl-C acts."""
    out = tmp_path / "out"
    rc, err = _stop_sweep(tmp_path, out, lambda p: _workers_starting(p.pid), signal.SIGINT, workers=2)
    assert (rc, err) == (130, "interrupted\n")
    assert not out.exists()


BUSY_WORKER = '''
import sys
import time
from pathlib import Path

from tabletcad.parallel import open_client


def busy_after_a_bar(marker):
    from tqdm import tqdm

    with tqdm(total=1, disable=True):  # as a design's build does (tabletcad.pipeline.build)
        pass
    Path(marker).touch()
    end = time.monotonic() + 60
    while time.monotonic() < end:  # busy, as in an OpenCascade call: not stopped within the grace
        pass


if __name__ == "__main__":
    try:
        with open_client(1) as client:
            fut = client.submit(busy_after_a_bar, sys.argv[1], pure=False)
            t0 = time.monotonic()
            while not Path(sys.argv[1]).exists() and time.monotonic() - t0 < 120:
                time.sleep(0.02)
            raise KeyboardInterrupt  # (the command line's Ctrl-C, there)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        sys.exit(130)
'''


def test_a_worker_killed_in_a_build_leaves_no_semaphore(tmp_path):
    """A run stopped while a worker is busy in a build (the full test pass on a loaded machine: 1 run in
    40 of the Ctrl-C during file builds): the worker, not stopped within the grace, is killed by its
    nanny, and the semaphore of tqdm's lock, made by the build's hidden progress bar, was never unlinked:
    "resource_tracker: There appear to be 1 leaked semaphore objects to clean up at shutdown" after
    ``interrupted``.  The workers' tqdm lock has no name now (tabletcad.worker_setup)."""
    script = tmp_path / "busy.py"
    script.write_text(BUSY_WORKER, encoding="utf-8")
    p = subprocess.run([sys.executable, str(script), str(tmp_path / "running")], cwd=tmp_path, capture_output=True,
                       text=True, timeout=300, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert (p.returncode, p.stderr) == (130, "interrupted\n")
    assert (tmp_path / "running").exists()


@pytest.mark.parametrize("start_method", ["forkserver", "spawn"])
def test_a_ctrl_c_between_designs_leaves_no_semaphore_whatever_the_start_method(tmp_path, start_method):
    """Where multiprocessing's default start method is not ``fork`` (macOS: spawn; Linux from Python 3.14:
    forkserver), tqdm's lock of the sweep's progress bar is a named semaphore in the command's process,
    which a Ctrl-C ends by ``os._exit``: the resource tracker printed "There appear to be 1 leaked
    semaphore objects to clean up at shutdown" after ``interrupted``, every time.  The command line now
    runs multiprocessing's exit-time finalizers first."""
    out = tmp_path / "out"
    journal = out / JOURNAL
    rc, err = _stop_sweep(tmp_path, out, lambda p: journal.exists() and journal.stat().st_size > 0, signal.SIGINT,
                          start_method=start_method)
    assert (rc, err) == (130, "interrupted\n")
    assert [q.name for q in out.iterdir()] == [JOURNAL]
