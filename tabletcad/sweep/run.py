"""``run_sweep``: a sweep file in, a pandas DataFrame (and ``results.csv``) out."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path
from typing import Any

from tabletcad.errors import DesignError
from tabletcad.io.signals import sigterm_raises
from tabletcad.sweep.engine import CONNECT_TIMEOUT_S, failed_design, map_tasks, open_client, sweep_task
from tabletcad.sweep.results import (JOURNAL, RESULTS_CSV, TAIL_COLUMNS, append_journal, is_sweep_plot, plot_column_error,
                                     plot_names, plot_results, read_done, results_frame, write_results)
from tabletcad.sweep.spec import SweepSpec, design_hash, load_sweep, parse_sweep

__all__ = ["run_sweep"]


def _spec(sweep: Any) -> SweepSpec:
    if isinstance(sweep, SweepSpec):
        return sweep
    if isinstance(sweep, dict):
        return parse_sweep(sweep)
    return load_sweep(sweep)


def max_local_workers() -> int:
    """The most worker processes a local cluster may have: 4 per CPU of this machine."""
    return 4 * (os.cpu_count() or 1)


def run_sweep(sweep: Any, out_dir: str | Path | None = None, *, workers: int | None = None,
              scheduler: str | None = None, client: Any = None, resume: bool = False, progress: bool = True,
              store: str | None = None, plot: tuple[str, ...] = (),
              connect_timeout: float = CONNECT_TIMEOUT_S):
    """Run a sweep and return its results as a :class:`pandas.DataFrame` (one row per design).

    Parameters
    ----------
    sweep : path, dict or SweepSpec
        The sweep file (see :mod:`tabletcad.sweep.spec`), its parsed TOML or a parsed spec.
    out_dir : path, optional
        Folder for ``results.csv``, the resume journal, the files of file
        outputs (``designs/<design_hash>/``) and plots.  Without it nothing is written.
    workers, scheduler, client
        The engine: a local cluster of ``workers`` processes (default: one per
        CPU; ``0`` runs in this process), an existing scheduler's address, or an
        open :class:`distributed.Client`.
    resume : bool
        Skip designs whose hash is already in ``out_dir/results.csv`` (or the journal).
    store : str, optional
        fsspec URL or folder the workers write file outputs to (overrides the
        file's ``[sweep] store``); then no file bytes travel to the client.
    plot : tuple of str
        Report columns to plot against every varied key (``plot_<column>.png``).

    Every check of the sweep file, the options and the scheduler connection
    happens before any design is built; a failure raises
    :class:`~tabletcad.errors.DesignError` and writes nothing.  A run ended by an
    exception, a Ctrl-C or a SIGTERM (in the main thread: :class:`SystemExit` 143) keeps
    the rows written so far (the journal) and removes the ``out_dir`` folders it made
    while they are empty.
    """
    spec = _spec(sweep)
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 0):
        raise DesignError("--workers", workers, "must be an integer >= 1 (0 runs the designs in this process)")
    if workers is not None and (scheduler is not None or client is not None):
        raise DesignError("--workers", workers, "give either --workers or --scheduler, not both")
    if workers is not None and workers > max_local_workers():  # (a typo of 100000 would start one per design)
        raise DesignError("--workers", workers, f"must be at most {max_local_workers()} (4 per CPU of this machine: a "
                          "local worker is a process of 130-340 MB, and more than the CPUs only wait)")
    if store is not None or spec.store is not None:
        _check_store(store if store is not None else spec.store, "--store" if store is not None else "[sweep] store",
                     local=scheduler is None)
    store_given = store is not None
    store = store if store is not None else spec.store
    files_wanted = any(o != "report" for o in spec.outputs)
    out = Path(out_dir) if out_dir is not None else None
    if out is None:
        if resume:
            raise DesignError("--resume", True, "needs the --out folder of the earlier run")
        if files_wanted and store is None:
            raise DesignError("[sweep] outputs", ", ".join(spec.outputs), "file outputs need an --out folder or a store")
        if plot:
            raise DesignError("--plot", ", ".join(plot), "plots need an --out folder")
    elif out.exists() and not out.is_dir():
        raise DesignError("--out", str(out), "must be a folder")
    designs = spec.designs()
    if plot and out is not None:
        _check_plot_columns(plot, designs[0], spec)
    hashes = [design_hash(d) for d in designs]
    done: dict[str, dict[str, Any]] = {}
    if out is not None and out.is_dir() and ((out / RESULTS_CSV).exists() or (out / JOURNAL).exists()):
        if not resume:  # named as the file it holds (a journal alone, of a stopped run, is no results.csv)
            held = " and ".join(f for f in (RESULTS_CSV, JOURNAL) if (out / f).exists())
            raise DesignError("--out", str(out), f"already holds {held}, the name a sweep writes its results under; give --resume to "
                              "go on with that sweep, or another folder")
        done = read_done(out)
        foreign = set(done) - set(hashes)
        if foreign:
            raise DesignError("--resume", str(out / RESULTS_CSV),
                              f"holds {len(foreign)} designs that are not in this sweep file; use another --out folder")
        if files_wanted:  # outputs asked for now that an earlier run did not write: those designs run again
            done = {h: r for h, r in done.items() if r.get("status") != "ok" or _has_files(out, store, h, spec.outputs)}
        theirs = [n for n in plot_names(plot) if (out / n).exists() and not is_sweep_plot(out / n)]
        if theirs:  # (a resumed run replaces its own plots only: it had written over the user's file of that name)
            raise DesignError("--out", str(out), f"must not hold files under the names of this sweep's plots that no "
                              f"sweep wrote ({', '.join(theirs)}; a sweep's plot carries 'Software: tabletcad sweep' in "
                              "its PNG, which tabletcad before 2026-12-07 did not write): move them or write into "
                              "another folder")
    elif out is not None and out.is_dir():  # a first run into a used folder: it owns only what it writes
        theirs = [n for n in plot_names(plot) if (out / n).exists()]
        if files_wanted and (out / "designs").exists():
            theirs.append("designs")
        if theirs:
            raise DesignError("--out", str(out), f"must not hold files this sweep writes that no earlier run of it "
                              f"wrote ({', '.join(theirs)}): move them or write into another folder")

    todo: dict[str, dict[str, Any]] = {}
    for h, d in zip(hashes, designs):
        if h not in done and h not in todo:
            todo[h] = d
    if store is not None and files_wanted and not resume:  # a first run owns only what it writes, a store too
        clash = _held_files(store, list(todo), spec.outputs)
        if clash:
            again = ("give --resume with the --out folder of the run that wrote them" if out is not None else
                     "a run without --out cannot be resumed")
            raise DesignError("--store" if store_given else "[sweep] store", store,
                              f"must not hold a file this sweep would write ({clash}): move it, use another store, "
                              f"or {again}")
    items = [(d, h) for h, d in todo.items()]
    values = dict(zip(hashes, spec.points()))
    results: dict[str, dict[str, Any]] = {}

    def row_of(h: str, res: dict[str, Any]) -> dict[str, Any]:
        return {**dict(zip(spec.keys, values[h])), **res["values"], "warnings": res.get("warnings", ""),
                "status": res["status"], "error": res["error"], "design_hash": h}

    def on_result(i: int, res: dict[str, Any]) -> None:
        h = items[i][1]
        row = row_of(h, res)
        results[h] = row
        if out is None:
            return
        if res["files"]:
            folder = out / "designs" / h
            folder.mkdir(parents=True, exist_ok=True)
            for name, data in res["files"].items():
                (folder / name).write_bytes(data)
        append_journal(out / JOURNAL, row)

    kw = dict(outputs=spec.outputs, name=spec.name, store=store)
    common = dict(kwargs=kw, progress=progress, desc=spec.name, failed=lambda r: r["status"] != "ok",
                  on_result=on_result, on_error=failed_design)
    created = _missing_folders(out) if out is not None else []
    try:
        with contextlib.ExitStack() as stack:
            stack.enter_context(sigterm_raises())  # a SIGTERM cleans up as a Ctrl-C does (it had ended the process)
            if files_wanted and scheduler is None and client is None:
                # the builds' temporary folders in one of this run's own, removed below once the workers are
                # gone however the run ends (a trial: a Ctrl-C left the killed workers' folders in /tmp)
                kw["tmp_root"] = stack.enter_context(tempfile.TemporaryDirectory(prefix="tabletcad-sweep-",
                                                                                 ignore_cleanup_errors=True))
            if items and client is None and workers != 0:  # connect first: an unreachable scheduler writes nothing
                n = None if scheduler is not None else min(workers or os.cpu_count() or 1, len(items))
                client = stack.enter_context(open_client(n, scheduler, connect_timeout))
            if out is not None:
                try:
                    out.mkdir(parents=True, exist_ok=True)
                except OSError as exc:  # (/proc/sweep): named as the option
                    raise DesignError("--out", str(out), f"cannot be written: {(exc.strerror or str(exc)).lower()}") from None
            map_tasks(sweep_task, items, client=client, workers=0 if client is None else None, **common)
    except BaseException:
        _remove_empty(created)  # stopped before any design: no empty folder left (a folder given stays)
        raise

    rows = [results.get(h) or _restored(done[h], spec.keys, values[h]) for h in hashes]
    df = results_frame(spec.keys, rows)
    if out is not None:
        write_results(df, out / RESULTS_CSV)
        (out / JOURNAL).unlink(missing_ok=True)
        if plot:
            try:
                plot_results(df, spec.keys, plot, out)
            except DesignError as exc:  # a column no design's report had, or none filled: the results stay, and say so
                where = f"the results are in {out / RESULTS_CSV}: plot another column with --resume"
                allowed = exc.allowed.replace("of results.csv:", f"of results.csv ({where}):", 1) \
                    if "of results.csv:" in exc.allowed else f"{exc.allowed}; {where}"
                raise DesignError(exc.parameter, exc.value, allowed) from None
    return df


def _missing_folders(out: Path) -> list[Path]:
    """The folders that making ``out`` would create: ``out`` and its missing parents, innermost first."""
    missing = []
    p = out.absolute()
    while not p.exists() and p != p.parent:
        missing.append(p)
        p = p.parent
    return missing


def _remove_empty(folders: list[Path]) -> None:
    """Remove each of ``folders`` (innermost first) that is an empty folder, stopping at the first that is not:
    a run stopped before it wrote anything leaves none of the folders it made."""
    for folder in folders:
        try:
            folder.rmdir()  # (only an empty folder: never what another process put there meanwhile)
        except FileNotFoundError:
            continue
        except OSError:
            return


def _held_files(store: str, keys: list[str], outputs) -> str:
    """The first file of ``outputs`` that ``store`` already holds for one of the designs ``keys``
    (``store/key/name``), or ``""``: from one listing of the store.  A store whose fsspec library this
    machine lacks (a remote cluster's workers may have it) or that cannot be listed here is not looked at."""
    from tabletcad.sweep.spec import OUTPUTS

    try:
        import fsspec

        fs, root = fsspec.core.url_to_fs(store)
        root = root.rstrip("/")
        held = {p.rstrip("/")[len(root) + 1:] for p in fs.find(root)} if fs.exists(root) else set()
    except (ImportError, OSError, ValueError):
        return ""
    names = [f for o in outputs for f in OUTPUTS[o]]
    return next((f"{key}/{n}" for key in keys for n in names if f"{key}/{n}" in held), "")


def _has_files(out: Path, store: str | None, key: str, outputs) -> bool:
    """Whether the files of ``outputs`` of the design ``key`` are where this run would write them
    (``out/designs/key/``, or ``store/key/``)."""
    from tabletcad.sweep.spec import OUTPUTS

    names = [f for o in outputs for f in OUTPUTS[o]]
    if store is None:
        return all((out / "designs" / key / n).is_file() for n in names)
    import fsspec

    fs, root = fsspec.core.url_to_fs(store)
    return all(fs.exists(f"{root.rstrip('/')}/{key}/{n}") for n in names)


def _check_plot_columns(plot: tuple[str, ...], design: dict[str, Any], spec) -> None:
    """Refuse a ``--plot`` name before any design is built when no design's report can have it: a
    varied key, a status column, or a name outside every section of the first design's report (built
    here, in this process, without files).  Within a section the columns differ between designs (a
    flat face has no cup radius), so such a name is left to the end, as are the sections only a build
    with files adds (``brep``, ``mesh``, ``tooling``...) when the sweep asks for files, and every name
    when the first design does not build."""
    from tabletcad.pipeline.design import Design
    from tabletcad.pipeline.report import flatten_report, geometry_report

    import warnings

    try:
        with warnings.catch_warnings():  # (the design's warnings are its row's, not this check's)
            warnings.simplefilter("ignore", UserWarning)
            warnings.simplefilter("ignore", FutureWarning)
            d = Design.from_dict(design, default_name=spec.name)
            cols = flatten_report(geometry_report(d.build(), d.report_options))
    except Exception:  # noqa: BLE001 - a design that fails is the sweep's row, not a reason to stop here
        for o in plot:  # (no design needed to know these: they had been refused only after the whole sweep)
            if o in spec.keys or o in TAIL_COLUMNS:
                raise DesignError("--plot", o, "must be a report column of results.csv, not " + (
                    "a varied key (each plot is drawn against the varied keys)" if o in spec.keys else "a status column"))
        return
    files = any(o != "report" for o in spec.outputs)
    sections = {c.split(".")[0] for c in cols}
    if d.report_options is not None and d.report_options.fe_breaking_force:  # (added after the geometry report)
        sections.add("fe_breaking_force")
    numeric = [c for c, v in cols.items() if _plottable(v) or v is None]
    for o in plot:
        unknown = o not in cols and o.split(".")[0] not in sections and not files
        table = o not in cols and any(c.startswith(o + ".") for c in cols)  # a table of columns, never one
        # text (a name, a family, a formula: text in every row); None (a strength eq 2.7 refused for this
        # design) may be a number in another: left to the end
        text = o in cols and isinstance(cols[o], str)
        if o in spec.keys or o in TAIL_COLUMNS or unknown or table or text:
            raise plot_column_error(o, numeric, spec.keys)


def _plottable(value: Any) -> bool:
    """Whether a report value can be plotted: a number or a boolean (0/1), not text or None."""
    return isinstance(value, (int, float))


def _check_store(store: str, name: str, local: bool) -> None:
    """Refuse a store that no worker could write (every row had failed, exit 0): an unknown fsspec
    protocol, one whose library is missing here when the workers run here (``local``), a local path
    that is a file or lies below one."""
    import fsspec

    try:
        fs, root = fsspec.core.url_to_fs(store)
    except ValueError as exc:
        raise DesignError(name, store, f"must be a folder or an fsspec URL ({exc})") from None
    except ImportError as exc:  # a remote cluster's workers may have the library this client lacks
        if local:
            raise DesignError(name, store, f"must be a folder or an fsspec URL the workers can write ({exc})") from None
        return
    if isinstance(fs, fsspec.implementations.local.LocalFileSystem):
        p = Path(root)
        while not p.exists() and p != p.parent:
            p = p.parent
        if not p.is_dir():
            raise DesignError(name, store, f"must be a folder: {p} is a file")


def _restored(row: dict[str, Any], keys: tuple[str, ...], values: tuple[Any, ...]) -> dict[str, Any]:
    """A row of an earlier run; the varied values are taken from the sweep (identical by the hash)."""
    rest = {k: v for k, v in row.items() if k not in keys and k not in TAIL_COLUMNS}
    return {**dict(zip(keys, values)), **rest, "warnings": row.get("warnings") or "", "status": row.get("status"),
            "error": row.get("error") or "", "design_hash": row.get("design_hash")}
