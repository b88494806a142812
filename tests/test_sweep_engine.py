"""The sweep engine for real: a local Dask cluster of two worker processes, and a separately
started ``dask scheduler`` / ``dask worker`` pair on 127.0.0.1.

Rows equal ``tabletcad build`` exactly, do not depend on the engine or the number of workers,
come in the sweep's order, failed designs are rows, ``--resume`` skips finished designs, file
outputs come back to the client as bytes, and ``tooling_batch`` runs on the same machinery.
"""

from __future__ import annotations

import csv
import json
import math
import socket
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.sweep
pytest.importorskip("distributed")
pd = pytest.importorskip("pandas")

from tabletcad.cli import main  # noqa: E402
from tabletcad.pipeline.design import design_from_dict  # noqa: E402
from tabletcad.errors import DesignError  # noqa: E402
from tabletcad.sweep import design_hash, parse_sweep, run_sweep  # noqa: E402
from tabletcad.sweep.engine import flatten_report  # noqa: E402
from tabletcad.sweep.results import JOURNAL, read_results  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

TABLET = {"family": "concave_round", "diameter": 8.0, "band": 2.6, "cup_depth": 0.8, "land": 0.08}
REPORT = {"solid_fraction": 0.85, "true_density_mg_mm3": 1.5, "breaking_force_N": 90.0}
# three designs: two build, the deepest cup is impossible for an 8 mm tablet (a failed row)
SWEEP = {"design": {"tablet": TABLET, "report": REPORT},
         "sweep": {"vary": {"tablet.cup_depth": [0.7, 9.0, 1.0]}}}
KEY = "tablet.cup_depth"


@pytest.fixture(scope="module")
def local_client():
    import dask
    from distributed import Client, LocalCluster

    # the workers without the statistical profiler, as tabletcad's own local clusters (open_client): a thread
    # sampling each worker's stack every 10 ms (idle, the two workers took 1.75 CPU-s in 30 s with it, 1.08
    # without); and the event loops' latency tick (a measurement only) every second, not every 20 ms (idle,
    # this process 1.02 -> 0.55 and the two workers 0.97 -> 0.45 CPU-s in 30 s). Set for the start only: this
    # process's own settings stay (the open_client tests read them)
    with dask.config.set({"distributed.worker.profile.enabled": False, "distributed.admin.tick.interval": "1s"}):
        cluster = LocalCluster(n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None)
    with cluster, Client(cluster, set_as_default=False) as client:
        client.wait_for_workers(2, timeout=120)
        yield client


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def scheduler_address(tmp_path_factory):
    """``dask scheduler`` and one ``dask worker`` started as separate processes; stopped after the test
    (the one that uses them: kept to the module's end, they polled idle through every later test)."""
    from distributed import Client

    port = _free_port()
    addr = f"tcp://127.0.0.1:{port}"
    cwd = tmp_path_factory.mktemp("dask")
    procs = [subprocess.Popen([sys.executable, "-m", "dask", "scheduler", "--host", "127.0.0.1", "--port", str(port),
                               "--no-dashboard"], cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        # (no nanny process beside the worker: it imported distributed a second time, 0.5 CPU-s)
        procs.append(subprocess.Popen([sys.executable, "-m", "dask", "worker", addr, "--nworkers", "1", "--nthreads", "1",
                                       "--no-dashboard", "--no-nanny", "--host", "127.0.0.1"],
                                      cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        with Client(addr, timeout="60s", set_as_default=False) as c:
            c.wait_for_workers(1, timeout=120)
        yield addr
    finally:
        # the worker first, then its scheduler: a worker stopped with its scheduler gone waits for it until
        # its nanny kills it (8 s: "Worker process still alive after 8.0 seconds, killing")
        for p in reversed(procs):
            p.terminate()
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait(timeout=30)


def test_a_local_cluster_takes_no_fixed_port():
    """With 8787 (Dask's default HTTP port) taken, as by another sweep or a notebook, a local cluster
    starts without a warning, its scheduler's HTTP server on a free port of this machine only."""
    import warnings

    from tabletcad.sweep.engine import open_client

    held = socket.socket()
    try:
        held.bind(("", 8787))
        held.listen()
    except OSError:  # taken already: the case itself
        pass
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with open_client(1) as client:
                link = client.dashboard_link
                assert client.submit(abs, -3).result() == 3
    finally:
        held.close()
    assert not [w for w in caught if "already in use" in str(w.message)]
    assert link.startswith("http://127.0.0.1:") and ":8787/" not in link


def test_a_ctrl_c_at_the_terminal_ends_a_sweep_with_one_line(tmp_path):
    """A terminal's Ctrl-C reaches the whole process group: the workers ignore it (``worker_setup``) and
    the command line stops the sweep, ``interrupted`` and 130, the journal kept; the workers' tracebacks
    (30-45 lines after ``interrupted``) are gone.  Sent once designs are finishing."""
    import os
    import signal
    import time

    text = (ROOT / "samples" / "sweep" / "concave_round_lhs.toml").read_text()
    sweep = tmp_path / "s.toml"
    sweep.write_text(text.replace("samples = 40", "samples = 3000"), encoding="utf-8")
    assert "samples = 3000" in sweep.read_text()
    out = tmp_path / "out"
    p = subprocess.Popen([sys.executable, "-m", "tabletcad", "sweep", str(sweep), "--out", str(out), "--workers", "1",
                          "--quiet"], cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(ROOT)},
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    journal = out / JOURNAL
    t0 = time.monotonic()
    while time.monotonic() - t0 < 120 and not (journal.exists() and journal.stat().st_size > 0):
        time.sleep(0.2)
    assert journal.exists(), p.communicate(timeout=60)
    time.sleep(1.0)
    os.killpg(p.pid, signal.SIGINT)
    _, err = p.communicate(timeout=120)
    assert (p.returncode, err) == (130, "interrupted\n")
    assert journal.stat().st_size > 0


def test_a_resume_asking_for_files_an_earlier_run_did_not_write_builds_them(tmp_path):
    """The outputs are not part of a design's hash: a resume that adds ``stl`` to a report-only run
    builds each finished design again for its file (it had counted them done and written none)."""
    pytest.importorskip("OCP")
    base = {"tablet": {"family": "flat_face_round", "diameter": 8.0, "thickness": 3.0}}
    vary = {"tablet.thickness": [2.0, 4.0]}
    out = tmp_path / "o"
    run_sweep({"design": base, "sweep": {"vary": vary}}, out, workers=0, progress=False)
    assert not (out / "designs").exists()
    df = run_sweep({"design": base, "sweep": {"vary": vary, "outputs": ["report", "stl"]}}, out, workers=0,
                   progress=False, resume=True)
    stls = sorted(out.glob("designs/*/tablet.stl"))
    assert len(stls) == 2 and sorted(p.parent.name for p in stls) == sorted(df["design_hash"])
    assert list(df["status"]) == ["ok", "ok"]


def test_a_plot_column_none_in_the_first_design_is_left_to_the_end(tmp_path):
    """The tensile strength is None where eq 2.7 refuses a design (a band of 0.05 mm) and a number in
    the others: a --plot of it is not refused before the sweep, whatever the order of the rows."""
    from tabletcad.sweep.run import _check_plot_columns

    col = "design_report.tensile_strength.tensile_strength_MPa"
    for bands in ([0.05, 2.8], [2.8, 0.05]):
        spec = parse_sweep({"design": {"tablet": dict(family="concave_round", diameter=10.0, band=2.8, cup_depth=0.9),
                                       "report": {"breaking_force_N": 100.0}},
                            "sweep": {"vary": {"tablet.band": bands}}}, name="s")
        _check_plot_columns((col,), spec.designs()[0], spec)


def test_the_workers_drop_only_the_heartbeats_report_of_a_closed_scheduler(caplog):
    """A fresh clone's full run caught a Ctrl-C's ``interrupted`` followed by 30 lines: a worker's heartbeat
    in flight when the command line closed its scheduler ("Failed to communicate with scheduler during
    heartbeat", StreamClosedError).  The local workers' set-up drops that record, and only that one."""
    import logging
    import signal

    from tqdm import tqdm

    from tabletcad.worker_setup import dask_setup

    before = signal.getsignal(signal.SIGINT)
    logger = logging.getLogger("distributed.worker")
    kept = list(logger.filters)
    lock = tqdm.get_lock()  # (the workers' set-up gives tqdm another: this process keeps its own)
    try:
        dask_setup(None)
        dask_setup(None)  # (once per worker: the filter is not added twice)
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN and len(logger.filters) == len(kept) + 1
        with caplog.at_level(logging.ERROR, logger="distributed.worker"):
            logger.error("Failed to communicate with scheduler during heartbeat.")
            logger.error("Unexpected exception during heartbeat. Closing worker.")
        assert [r.getMessage() for r in caplog.records] == ["Unexpected exception during heartbeat. Closing worker."]
    finally:
        signal.signal(signal.SIGINT, before)
        logger.filters[:] = kept
        tqdm.set_lock(lock)


@pytest.mark.parametrize("guarded", [False, True])
def test_a_script_starting_local_workers_outside_its_main_guard_gets_one_error(tmp_path, guarded):
    """Local workers are spawned and import the calling script again: a script that starts a sweep from its
    top-level code outside ``if __name__ == "__main__":`` is refused before any worker starts, with one
    message naming the script and line (unguarded it printed about 490 lines of the workers' and nannies'
    tracebacks), and nothing is written; inside the guard the same call passes the check."""
    sample = ROOT / "samples" / "sweep" / "concave_round_grid.toml"
    out = tmp_path / "out"
    call = f"run_sweep({str(sample)!r}, {str(out)!r}, workers=2, progress=False)"
    if guarded:  # the check alone (a cluster would take seconds): it must refuse none of these guards
        body = ("import contextlib, sys\nfrom tabletcad.parallel import _check_main_guarded\n"
                "if __name__ == \"__main__\":\n    _check_main_guarded()\n"
                "if __name__ == \"__main__\" and len(sys.argv) >= 1:\n    _check_main_guarded()\n"
                "with contextlib.suppress(KeyboardInterrupt):\n    if \"__main__\" == __name__:\n"
                "        _check_main_guarded()\n"
                "if __name__ == \"__main__\":\n    print('passed')\n")
    else:
        body = f"import sys\nfrom tabletcad.sweep import run_sweep\n\n{call}\n"
    script = tmp_path / "script.py"
    script.write_text(body, encoding="utf-8")
    r = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    if guarded:
        assert r.returncode == 0 and r.stdout.strip() == "passed", r.stderr
        return
    last = r.stderr.strip().splitlines()[-1]
    assert r.returncode == 1 and len(r.stderr.splitlines()) < 30, r.stderr
    assert last == (f"RuntimeError: {script}, line 4: a sweep or batch on local worker processes must be started "
                    "under 'if __name__ == \"__main__\":' (the workers import the script again), or with workers=0 "
                    "to run in this process")
    assert r.stderr.count("Traceback") == 1 and not out.exists()  # Python's own report of the one error


@pytest.mark.cad
def test_a_report_only_row_has_the_fe_breaking_force_the_report_command_gives(tmp_path, capsys):
    """``[report] fe_breaking_force = true``: a report-only sweep's row holds the ``fe_breaking_force``
    figures of ``tabletcad report`` for the same design (a trial: the columns were missing unless the
    sweep also wrote files, and a --plot of them was refused)."""
    pytest.importorskip("skfem")
    report = dict(solid_fraction=0.85, true_density_mg_mm3=1.5, tensile_strength_MPa=2.0, fe_breaking_force=True)
    tablet = dict(family="concave_round", diameter=10.0, band=2.8, cup_depth=0.9, land=0.08)
    df = run_sweep({"design": {"tablet": tablet, "report": report}, "sweep": {"vary": {"tablet.cup_depth": [0.9]}}},
                   tmp_path / "s", workers=0, progress=False, plot=("fe_breaking_force.breaking_force_N",))
    assert list(df["status"]) == ["ok"]
    assert [q.name for q in (tmp_path / "s").glob("plot_*.png")] == ["plot_fe_breaking_force.breaking_force_N.png"]
    design = tmp_path / "d.toml"
    from tabletcad.pipeline.design import toml_text

    design.write_text(toml_text({"tablet": tablet, "report": report}), encoding="utf-8")
    assert main(["report", str(design), "--json-file", str(tmp_path / "r.json")]) == 0
    capsys.readouterr()
    fe = json.loads((tmp_path / "r.json").read_text())["fe_breaking_force"]
    row = df.iloc[0]
    assert row["fe_breaking_force.breaking_force_N"] == fe["breaking_force_N"] and 100.0 < fe["breaking_force_N"] < 200.0
    for key, value in fe.items():
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            assert row[f"fe_breaking_force.{key}"] == value, key


@pytest.mark.cad
def test_a_ctrl_c_during_file_builds_leaves_no_temporary_folder(tmp_path):
    """The workers make each design's files in a folder of the run's own, which the command line removes
    however the run ends (a trial: workers ended by a Ctrl-C left their build folders, 250-570 KB each,
    in /tmp); a run stopped before any design finished leaves no empty --out folder either."""
    import os
    import signal
    import time

    tmp = tmp_path / "tmp"
    tmp.mkdir()
    sweep = tmp_path / "s.toml"
    sweep.write_text('[design.tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 2.8\ncup_depth = 0.9\n'
                     '[sweep]\noutputs = ["report", "step", "stl", "glb"]\n[sweep.vary]\n'
                     '"tablet.cup_depth" = { min = 0.6, max = 1.2, num = 40 }\n', encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "TMPDIR": str(tmp)}
    for out, wait_for_journal in ((tmp_path / "early", False), (tmp_path / "late", True)):
        p = subprocess.Popen([sys.executable, "-m", "tabletcad", "sweep", str(sweep), "--out", str(out), "--workers", "2",
                              "--quiet"], cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True, start_new_session=True)
        t0 = time.monotonic()
        if wait_for_journal:  # then into the next designs' builds
            while time.monotonic() - t0 < 120 and not (out / JOURNAL).exists():
                time.sleep(0.1)
            time.sleep(0.4)
        else:  # the --out folder made (the cluster has started), no design finished yet
            while time.monotonic() - t0 < 120 and not out.exists():
                time.sleep(0.02)
        os.killpg(p.pid, signal.SIGINT)
        _, err = p.communicate(timeout=120)
        assert (p.returncode, err) == (130, "interrupted\n")  # (no worker traceback nor leaked-semaphore warning)
        # (Dask keeps its dask-scratch-space there, for every later cluster)
        assert [q for q in tmp.iterdir() if q.name != "dask-scratch-space"] == []
        if wait_for_journal:
            assert (out / JOURNAL).stat().st_size > 0
        else:
            assert not out.exists()


def test_a_designs_warnings_are_its_rows_not_lines_on_the_terminal(tmp_path):
    """An old family name warns once per design (FutureWarning): the row's ``warnings`` says it, the
    terminal does not, in the designs nor in the --plot check that builds the first one (a trial: each
    design printed Python's raw two-line warning, with the file and line, and the results kept none);
    a design without warnings has an empty cell, read back as written."""
    from tabletcad.pipeline.design import toml_text
    from tabletcad.sweep.results import read_results

    sw = {"design": {"tablet": {"family": "spherical", "diameter": 5.0}},
          "sweep": {"vary": {"tablet.diameter": [5.0, 6.0]}}}
    (tmp_path / "old.toml").write_text(toml_text(sw), encoding="utf-8")
    p = subprocess.run([sys.executable, "-m", "tabletcad", "sweep", "old.toml", "--out", "old", "--workers", "1", "--quiet",
                        "--plot", "volume_mm3"], cwd=tmp_path, capture_output=True, text=True, timeout=300,
                       env={**__import__("os").environ, "PYTHONPATH": str(ROOT)})
    assert (p.returncode, p.stderr) == (0, ""), p.stderr
    df = read_results(tmp_path / "old" / "results.csv")
    assert list(df["status"]) == ["ok", "ok"] and df.columns.tolist()[-4:] == ["warnings", "status", "error", "design_hash"]
    assert list(df["warnings"]) == ["family 'spherical' is now 'thesis.spherical'; the old name is accepted until "
                                    "tabletcad 0.3"] * 2
    sw["design"]["tablet"]["family"] = "thesis.spherical"
    assert run_sweep(sw, tmp_path / "new", workers=0, progress=False)["warnings"].tolist() == ["", ""]
    assert read_results(tmp_path / "new" / "results.csv")["warnings"].tolist() == ["", ""]


@pytest.mark.cad
def test_a_designs_picture_is_drawn_only_for_the_png_output(tmp_path, monkeypatch):
    """``tablet.png`` is the picture ``tabletcad build`` draws, and a design whose outputs leave it out
    does not draw it (it was 0.08 of a report-and-STL design's 0.1 CPU-s, and its worker's only
    reason to import Matplotlib)."""
    import tabletcad.pipeline.build as build
    from tabletcad.pipeline.plot import plot_tablet
    from tabletcad.sweep.engine import evaluate_design

    design = {"tablet": {"family": "flat_face_round", "diameter": 8.0, "thickness": 3.0}}
    res = evaluate_design(design, ("png",), name="p")
    assert res["status"] == "ok" and sorted(res["files"]) == ["tablet.png"], res["error"]
    plot_tablet(design_from_dict(design, default_name="p"), tmp_path / "own.png")
    assert res["files"]["tablet.png"] == (tmp_path / "own.png").read_bytes()

    def no_picture(*args, **kw):
        raise AssertionError("the picture was drawn")

    monkeypatch.setattr(build, "plot_tablet", no_picture)
    res = evaluate_design(design, ("report", "stl"), name="p")
    assert res["status"] == "ok" and sorted(res["files"]) == ["tablet.stl"], res["error"]
    assert res["values"]["volume_mm3"] == pytest.approx(math.pi * 16.0 * 3.0, rel=1e-6)


def test_a_tooling_output_holds_every_file_its_build_writes(tmp_path):
    """The "tooling" output of a design with complete punches (the TSM B sample's [tooling], here on a
    flat-faced round of the sample's diameter) holds what `tabletcad build` writes of it: the parts, and
    the tablet's and the punches' drawings in SVG, PDF and DXF (the PDFs and the punches' drawing had been
    left out of the sweep's folders)."""
    import tomllib

    from tabletcad.tooling.spec import parse_tooling
    from tabletcad.tooling.stage import tooling_outputs

    sample = tomllib.loads((ROOT / "samples" / "tooling" / "tsm_b_round.toml").read_text(encoding="utf-8"))
    # the files are the [tooling] table's, whatever the faces: flat ones build in 2.8 CPU-s, the sample's
    # concave cups in 5.5 (their closed-position check and drawings)
    sample["tablet"] = {"family": "flat_face_round", "diameter": sample["tablet"]["diameter"], "thickness": 3.0}
    sw = {"design": sample, "sweep": {"outputs": ["tooling"], "vary": {"tablet.thickness": [3.0]}}}
    df = run_sweep(sw, tmp_path / "out", workers=0, progress=False)
    assert df["status"].tolist() == ["ok"], df["error"].tolist()
    folder = tmp_path / "out" / "designs" / df["design_hash"][0]
    names = sorted(p.name for p in folder.iterdir())
    assert names == sorted(tooling_outputs(parse_tooling(sample["tooling"])))
    assert {"drawing.pdf", "tooling.pdf", "tooling.svg", "tooling.dxf"} <= set(names)
    assert (folder / "drawing.pdf").read_bytes().startswith(b"%PDF") and (folder / "tooling.pdf").read_bytes().startswith(b"%PDF")


def test_local_workers_keep_the_adaptive_malloc_trim_and_no_profiler():
    """distributed's MALLOC_TRIM_THRESHOLD_=65536 made the report cost 1.8x the CPU (bench_sweep.py); the
    event loops' latency tick (a measurement) runs every second, not every 20 ms."""
    import os

    import dask

    from tabletcad.sweep.engine import open_client

    with open_client(1) as client:
        env = client.run(lambda dask_worker: (os.environ.get("MALLOC_TRIM_THRESHOLD_"),
                                              dask.config.get("distributed.worker.profile.enabled"),
                                              dask_worker._tick_interval))  # (the latency tick, seconds)
        tick = client.run_on_scheduler(lambda dask_scheduler: dask_scheduler._tick_interval)
    assert list(env.values()) == [(None, False, 1.0)] and tick == 1.0
    assert dask.config.get("distributed.nanny.pre-spawn-environ")["MALLOC_TRIM_THRESHOLD_"] == 65536  # restored


def test_a_lost_worker_is_a_failed_row_not_the_end():
    """A task that kills its worker process (as a crash in a native library would) becomes an error result."""
    import os

    import dask
    from distributed import KilledWorker

    from tabletcad.sweep.engine import failed_design, map_tasks, open_client

    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), open_client(1) as client:
        res = map_tasks(os._exit, [3], client=client, progress=False, on_error=failed_design)
        assert res[0]["status"] == "error" and res[0]["error"].startswith("KilledWorker")
        client.wait_for_workers(1, timeout=120)  # the nanny restarts the worker
        with pytest.raises(KilledWorker):
            map_tasks(os._exit, [3], client=client, progress=False)
        assert map_tasks(abs, [-2, 5], client=client, progress=False) == [2, 5]


def test_a_plot_of_no_column_is_refused_before_any_design_is_built(tmp_path, capsys):
    """``--plot`` of a column the reports do not have: one line, exit 2, no folder, no cluster
    started (it used to run the whole sweep, then stop and leave results.csv, which a corrected
    rerun then refused); a right column of the report is accepted."""
    from tabletcad.sweep.run import _check_plot_columns

    sweep = ROOT / "samples" / "sweep" / "concave_round_grid.toml"
    rc = main(["sweep", str(sweep), "--out", str(tmp_path / "sw"), "--workers", "1", "--plot", "nonexistent_col"])
    err = capsys.readouterr().err
    assert rc == 2 and err.startswith("error: --plot = 'nonexistent_col' is not allowed: must be a report column")
    assert len(err.splitlines()) == 1 and "volume_mm3" in err
    assert list(tmp_path.iterdir()) == []
    spec = parse_sweep(__import__("tomllib").loads(sweep.read_text()), name="g")
    design = spec.designs()[0]
    _check_plot_columns(("volume_mm3", "design_report.weight_mg"), design, spec)  # columns of the report
    # a column of a section that another design may have (a flat face has no cup radius): left to the end
    _check_plot_columns(("design_report.cup_radii_mm.central",), design, spec)
    # a varied key, the status, no column, a table of columns, text (the same type in every row)
    for bad in ("tablet.band", "status", "nonexistent_col", "design_report.fda_size", "design.name",
                "design_report.tensile_strength.formula"):
        with pytest.raises(DesignError) as e:
            _check_plot_columns((bad,), design, spec)
        allowed = e.value.allowed.split(": ", 1)[1].split(", ")
        assert "volume_mm3" in allowed and "design_report.fda_size.ok" in allowed  # numbers and booleans
        assert "design.name" not in allowed and "status" not in allowed and "tablet.band" not in allowed


def test_a_varied_key_or_a_status_plot_is_refused_even_when_the_first_design_fails(tmp_path):
    """Whether the first design builds or not, a varied key or a status column is no report column: a sweep whose
    first design is refused (a band of 0) had built every design, written results.csv, and then refused them."""
    from tabletcad.sweep.run import _check_plot_columns

    sweep = ROOT / "samples" / "sweep" / "concave_round_grid.toml"
    data = __import__("tomllib").loads(sweep.read_text())
    data["sweep"]["vary"]["tablet.band"] = [0.0, 3.2]
    spec = parse_sweep(data, name="g")
    design = spec.designs()[0]
    assert design["tablet"]["band"] == 0.0
    for bad, why in (("tablet.band", "not a varied key"), ("status", "not a status column")):
        with pytest.raises(DesignError) as e:
            _check_plot_columns((bad,), design, spec)
        assert e.value.parameter == "--plot" and why in e.value.allowed
    _check_plot_columns(("volume_mm3",), design, spec)  # (a column: left to the end, the design failing here)


def test_a_resumed_sweep_keeps_a_users_file_under_a_plots_name(tmp_path):
    """``--resume --plot volume_mm3`` had written its plot over the user's own plot_volume_mm3.png, a file no earlier
    run of the sweep wrote (a first run into such a folder is refused): refused in one line, the file kept; the
    sweep's own plot (its PNG marked by the sweep) is replaced on the next resume."""
    from tabletcad.sweep.results import is_sweep_plot

    sweep = ROOT / "samples" / "sweep" / "concave_round_grid.toml"
    out = tmp_path / "sw"
    run_sweep(sweep, out, workers=0, progress=False)
    mine = out / "plot_volume_mm3.png"
    mine.write_text("my own figure")
    with pytest.raises(DesignError) as e:
        run_sweep(sweep, out, workers=0, progress=False, resume=True, plot=("volume_mm3",))
    assert str(e.value) == (f"--out = {str(out)!r} is not allowed: must not hold files under the names of this "
                            "sweep's plots that no sweep wrote (plot_volume_mm3.png; a sweep's plot carries 'Software: "
                            "tabletcad sweep' in its PNG, which tabletcad before 2026-12-07 did not write): move them "
                            "or write into another folder")
    assert mine.read_text() == "my own figure" and not is_sweep_plot(mine)
    mine.unlink()
    for _ in range(2):  # its own plot, then replaced by the next resume
        run_sweep(sweep, out, workers=0, progress=False, resume=True, plot=("volume_mm3",))
        assert is_sweep_plot(mine)


# The tests below use the module's local cluster (local_client), which lives until the module ends:
# the tests above, which do not, run before it starts (it had idled through them, ~40 s, 1 CPU-s)
@pytest.fixture(scope="module")
def local_results(local_client, tmp_path_factory):
    out = tmp_path_factory.mktemp("local") / "out"
    df = run_sweep(SWEEP, out, client=local_client, progress=False)
    return df, out


def test_rows_are_in_sweep_order_and_a_failing_design_is_a_row(local_results):
    df, out = local_results
    assert isinstance(df, pd.DataFrame)
    assert df[KEY].tolist() == [0.7, 9.0, 1.0]
    assert df["status"].tolist() == ["ok", "error", "ok"]
    with pytest.raises(DesignError) as exc:
        design_from_dict({"tablet": {**TABLET, "cup_depth": 9.0}})
    assert df["error"].tolist() == ["", str(exc.value), ""]
    assert df["design_hash"].tolist() == [design_hash(d) for d in parse_sweep(SWEEP).designs()]
    cols = df.columns.tolist()
    assert cols[0] == KEY and cols[-4:] == ["warnings", "status", "error", "design_hash"]
    for c in ("volume_mm3", "surface_area_mm2", "design_report.weight_mg",
              "design_report.tensile_strength.tensile_strength_MPa"):
        assert c in cols
    assert math.isnan(df.loc[1, "volume_mm3"])
    # each cup is a spherical cap of depth h over the land's inner circle (radius a): pi h (3 a^2 + h^2) / 6
    # (the report's quadrature agrees to 2.4e-6 relative), and two cups are all that changes the volume
    for i, h in ((0, 0.7), (2, 1.0)):
        a = 4.0 - 0.08
        cap = math.pi * h * (3 * a * a + h * h) / 6.0
        assert df.loc[i, "design_report.cup_volume_mm3"] == pytest.approx(cap, rel=1e-5)
    assert df.loc[2, "volume_mm3"] - df.loc[0, "volume_mm3"] == pytest.approx(
        2 * (df.loc[2, "design_report.cup_volume_mm3"] - df.loc[0, "design_report.cup_volume_mm3"]), rel=1e-9)
    # weight = volume x solid fraction x true density
    assert df["design_report.weight_mg"][[0, 2]].tolist() == pytest.approx((df["volume_mm3"][[0, 2]] * 0.85 * 1.5).tolist(),
                                                                            rel=1e-9)
    assert not (out / JOURNAL).exists()
    back = read_results(out / "results.csv")
    assert back.columns.tolist() == cols
    for c in cols:
        for a, b in zip(back[c], df[c]):
            assert (a is None and (b is pd.NA or b is None or (isinstance(b, float) and math.isnan(b))
                                   or b == "")) or (b is not pd.NA and a == b), c


def test_rows_equal_a_single_tabletcad_build_exactly(local_results, tmp_path):
    df, out = local_results
    design = tmp_path / "sweep.toml"  # the sweep's name is the tablet's name
    lines = ["[tablet]"] + [f"{k} = {v!r}" if not isinstance(v, str) else f'{k} = "{v}"' for k, v in TABLET.items()
                            if k != "cup_depth"]
    lines += ["cup_depth = 1.0", "[report]"] + [f"{k} = {v!r}" for k, v in REPORT.items()]
    design.write_text("\n".join(lines) + "\n", encoding="utf-8")
    assert main(["build", str(design), "--out", str(tmp_path / "b"), "--quiet"]) == 0
    built = flatten_report(json.loads((tmp_path / "b" / "report.json").read_text()))
    row = df.iloc[2].to_dict()
    compared = 0
    for k, v in row.items():
        if k in (KEY, "warnings", "status", "error", "design_hash"):  # (the sweep's own columns)
            continue
        assert k in built, k
        if built[k] is None:
            assert v is None or (isinstance(v, float) and math.isnan(v)), k
        else:
            assert v == built[k], k  # exactly: same floats, not approximately
        compared += 1
    assert compared > 50
    # and as written: a count as the report has it (9, not 9.0: another row failed, leaving its cell empty)
    with open(out / "results.csv", newline="", encoding="utf-8") as fh:
        written = list(csv.DictReader(fh))[2]
    counts = 0
    for k, v in built.items():
        if k in written and k not in (KEY, "warnings", "status", "error", "design_hash"):
            assert written[k] == ("" if v is None else repr(v) if isinstance(v, float) else str(v)), k
            counts += isinstance(v, int) and not isinstance(v, bool)
    assert counts >= 1


def test_results_do_not_depend_on_the_engine_or_the_number_of_workers(local_results, scheduler_address, tmp_path):
    _, out = local_results
    text = (out / "results.csv").read_text()
    assert main(["sweep", str(_sweep_file(tmp_path)), "--out", str(tmp_path / "remote"), "--scheduler", scheduler_address,
                 "--quiet"]) == 0
    assert (tmp_path / "remote" / "results.csv").read_text() == text
    run_sweep(SWEEP, tmp_path / "serial", workers=0, progress=False)
    assert (tmp_path / "serial" / "results.csv").read_text() == text


def _sweep_file(tmp_path):
    p = tmp_path / "sweep.toml"
    p.write_text("[design.tablet]\n" + "\n".join(
        f"{k} = {v!r}" if not isinstance(v, str) else f'{k} = "{v}"' for k, v in TABLET.items())
        + "\n[design.report]\n" + "\n".join(f"{k} = {v!r}" for k, v in REPORT.items())
        + '\n[sweep.vary]\n"tablet.cup_depth" = [0.7, 9.0, 1.0]\n', encoding="utf-8")
    return p


def test_resume_skips_finished_designs(local_results, local_client, tmp_path):
    df, out = local_results
    lines = (out / "results.csv").read_text().splitlines()
    # an interrupted run: the journal holds the first design (marked so that a recomputation would show)
    target = tmp_path / "out"
    target.mkdir()
    first = {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in df.iloc[0].to_dict().items()}
    first["volume_mm3"] = -1.0
    (target / JOURNAL).write_text(json.dumps(first) + "\n" + '{"design_hash": "cut sho', encoding="utf-8")
    with pytest.raises(DesignError, match="give --resume"):
        run_sweep(SWEEP, target, client=local_client, progress=False)
    res = run_sweep(SWEEP, target, client=local_client, progress=False, resume=True)
    assert res["volume_mm3"].tolist()[0] == -1.0  # not recomputed
    assert res["status"].tolist() == ["ok", "error", "ok"]
    new = (target / "results.csv").read_text().splitlines()
    assert new[0] == lines[0] and new[2:] == lines[2:]
    assert not (target / JOURNAL).exists()
    # a finished sweep resumed again computes nothing and rewrites the same file
    again = run_sweep(SWEEP, target, workers=0, progress=False, resume=True)
    assert (target / "results.csv").read_text().splitlines() == new
    assert again["volume_mm3"].tolist()[0] == -1.0


def test_file_outputs_come_back_as_bytes_or_go_to_a_store(local_client, tmp_path):
    sw = {"design": {"tablet": TABLET}, "sweep": {"outputs": ["step"], "vary": {"tablet.band": [2.6]}}}
    df = run_sweep(sw, tmp_path / "out", client=local_client, progress=False)
    assert df["status"].tolist() == ["ok"]
    h = df["design_hash"][0]
    step = (tmp_path / "out" / "designs" / h / "tablet.step").read_bytes()
    assert step.startswith(b"ISO-10303-21;")
    assert abs(df["brep.volume_mm3"][0] - df["volume_mm3"][0]) <= 1e-6 * df["volume_mm3"][0]
    store = tmp_path / "store"
    df2 = run_sweep(sw, tmp_path / "out2", client=local_client, progress=False, store=f"file://{store}")
    assert (store / h / "tablet.step").is_file() and not (tmp_path / "out2" / "designs").exists()
    assert df2["brep.volume_mm3"][0] == df["brep.volume_mm3"][0]
    # a first run owns only what it writes, in a store too (a trial: a file there was replaced): refused,
    # before any design, the file and the folders as they were
    (store / h / "tablet.step").write_text("mine", encoding="utf-8")
    with pytest.raises(DesignError, match=rf"^--store = 'file://{store}' is not allowed: must not hold a file this "
                                          rf"sweep would write \({h}/tablet.step\): move it, use another store, or "
                                          rf"give --resume with the --out folder of the run that wrote them$"):
        run_sweep(sw, tmp_path / "out3", client=local_client, progress=False, store=f"file://{store}")
    assert (store / h / "tablet.step").read_text() == "mine" and not (tmp_path / "out3").exists()


def test_tooling_batch_runs_on_the_cluster(local_client, tmp_path):
    from tabletcad.tooling import tooling_batch

    sizes = [dict(diameter=d, thickness=0.3 * d, band=0.2 * d) for d in (6.0, 8.0)]
    rows = tooling_batch("thesis.shallow_convex_round", sizes, {"clearance_mm": 0.02}, out_dir=tmp_path, progress=False,
                         check=False, drawing=False, client=local_client)
    assert [r["params"] for r in rows] == sizes
    for k, r in enumerate(rows):
        assert r["upper_punch_rel_diff_vs_quadrature"] == pytest.approx(0.0, abs=1e-8)
        assert (tmp_path / f"thesis.shallow_convex_round_{k:03d}" / "assembly.step").read_bytes().startswith(b"ISO-10303-21;")
    assert rows[1]["tablet_volume_mm3"] > rows[0]["tablet_volume_mm3"]


def test_a_plot_column_no_design_had_keeps_the_results_and_says_where(tmp_path, capsys, local_client):
    """A column left to the end (its section exists) that no design's report has: the sweep's results
    stay, the one line says where they are, and ``--resume`` plots another column without rebuilding.
    (On the module's cluster: a local one of its own cost a cluster start-up a command; the plot
    checks do not depend on the engine.)"""
    sweep = ROOT / "samples" / "sweep" / "concave_round_grid.toml"
    out = tmp_path / "sw"
    engine = ["--scheduler", local_client.scheduler.address]
    rc = main(["sweep", str(sweep), "--out", str(out), *engine, "--quiet", "--plot",
               "design_report.cup_radii_mm.central"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1
    assert err[0].startswith("error: --plot = 'design_report.cup_radii_mm.central' is not allowed: must be a report "
                             f"column of results.csv (the results are in {out / 'results.csv'}: plot another column with --resume): ")
    assert sorted(p.name for p in out.iterdir()) == ["results.csv"]
    assert main(["sweep", str(sweep), "--out", str(out), *engine, "--quiet", "--resume", "--plot",
                 "volume_mm3"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["plot_volume_mm3.png", "results.csv"]


def test_a_plot_column_every_design_leaves_empty_says_so(tmp_path, capsys, local_client):
    """A new user's ``--plot design_report.punch_tip_check.compaction_force_kN``: a column of every report,
    so accepted before the run, but empty in every row (the sweep's design gives no compaction force).
    The refusal had said it was no report column, listing it among those that are."""
    sweep = ROOT / "samples" / "sweep" / "concave_round_grid.toml"
    out = tmp_path / "sw"
    col = "design_report.punch_tip_check.compaction_force_kN"
    rc = main(["sweep", str(sweep), "--out", str(out), "--scheduler", local_client.scheduler.address, "--quiet",
               "--plot", col])  # (on the module's cluster, as above)
    err = capsys.readouterr().err.strip().splitlines()
    n = len(pd.read_csv(out / "results.csv"))
    assert rc == 2 and err == [f"error: --plot = '{col}' is not allowed: must be a report column with a number in "
                               f"some design: every one of the {n} designs that built leaves it empty in results.csv "
                               "(the input it needs is not in the sweep's design); the results are in "
                               f"{out / 'results.csv'}: plot another column with --resume"]
    assert sorted(p.name for p in out.iterdir()) == ["results.csv"]
