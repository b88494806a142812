"""The sweep engine: design dictionaries in, report scalars and file bytes out, on Dask.

Work crosses process boundaries only as plain data: a task receives a design
*dictionary* (the parsed TOML) and returns a dict of report scalars and, when
asked, the bytes of the files it wrote.  No OpenCascade object is pickled; a
worker builds its tablet and solids itself.  Nothing assumes a shared
filesystem: files come back to the client, or go to a storage URL (fsspec)
written by the worker.

:func:`map_tasks` is the machinery shared by :func:`tabletcad.sweep.run_sweep`
and :func:`tabletcad.tooling.tooling_batch`: it runs a function over items on a
local cluster of worker processes (``workers=N``), on an existing cluster
(``scheduler="tcp://host:port"`` or ``client=``), or in this process
(``workers=0``, the serial loop), with a bounded number of tasks in flight and
a progress bar showing designs done, failed and the rate.
"""

from __future__ import annotations

import contextlib
import functools
import itertools
import logging
import os
import tempfile
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

from tabletcad.errors import DesignError
from tabletcad.report import flatten_report
from tabletcad.sweep.spec import OUTPUTS

__all__ = ["evaluate_design", "sweep_task", "failed_design", "map_tasks", "open_client", "flatten_report", "CONNECT_TIMEOUT_S", "error_message"]

CONNECT_TIMEOUT_S = 10.0
"""Seconds to wait for a Dask scheduler to answer before the sweep stops with a one-line error."""

IN_FLIGHT_PER_WORKER = 4
"""Tasks queued per worker thread; keeps the scheduler's memory flat for sweeps of millions of designs."""


def error_message(exc: BaseException) -> str:
    """The one-line message of a failed design (a DesignError's own line, else ``Type: first line``)."""
    msg = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
    if isinstance(exc, DesignError):
        return msg
    return f"{type(exc).__name__}: {msg}" if msg else type(exc).__name__


def _files_of(folder: Path, names: Sequence[str]) -> dict[str, bytes]:
    return {n: (folder / n).read_bytes() for n in names if (folder / n).is_file()}


def _store_files(store: str, sub: str, files: dict[str, bytes]) -> list[str]:
    import fsspec

    fs, root = fsspec.core.url_to_fs(store)
    folder = f"{root.rstrip('/')}/{sub}"
    fs.makedirs(folder, exist_ok=True)
    for name, data in files.items():
        fs.pipe_file(f"{folder}/{name}", data)
    return sorted(files)


def evaluate_design(design: dict[str, Any], outputs: Sequence[str] = ("report",), *, name: str = "sweep",
                    store: str | None = None, folder: str = "") -> dict[str, Any]:
    """Build one design from its dictionary and return its results as plain data; never raises.

    Returns ``dict(values=..., status="ok"|"error", error=..., files=...)``:
    ``values`` holds every scalar of the report (:func:`flatten_report`) — the
    geometry report of :func:`tabletcad.report.geometry_report`, which is the
    ``report.json`` of ``tabletcad build``; with file outputs the report of
    :func:`tabletcad.build.build_tablet` itself.  ``files`` maps file names to
    bytes (empty when ``store`` is given: the worker then writes them to
    ``store/folder/`` through fsspec).
    """
    try:
        from tabletcad.design import design_from_dict

        tablet = design_from_dict(design, default_name=name)
        files: dict[str, bytes] = {}
        wanted = [f for o in outputs if o not in ("report", "tooling") for f in OUTPUTS[o]]
        with tempfile.TemporaryDirectory(prefix="tabletcad-sweep-") as tmp:
            if wanted:
                from tabletcad.build import build_tablet

                report = build_tablet(tablet, Path(tmp) / "build", progress=False)
                files.update(_files_of(Path(tmp) / "build", wanted))
            else:
                from tabletcad.report import geometry_report

                report = geometry_report(tablet)
            if "tooling" in outputs:
                from tabletcad.tooling.batch import tooling_for

                ts = tooling_for(tablet, dict(design.get("tooling") or {}), out_dir=Path(tmp) / "tooling")
                report["tooling"] = ts.report
                files.update(_files_of(Path(tmp) / "tooling", OUTPUTS["tooling"]))
        if store is not None and files:
            _store_files(store, folder, files)
            files = {}
        return dict(values=flatten_report(report), status="ok", error="", files=files)
    except Exception as exc:  # a failing design is a row, never the end of the sweep
        return failed_design(exc)


def failed_design(exc: BaseException) -> dict[str, Any]:
    """The result of a design that failed with ``exc`` (in the worker, or by losing its worker)."""
    return dict(values={}, status="error", error=error_message(exc), files={})


def sweep_task(item: tuple[dict[str, Any], str], **kw: Any) -> dict[str, Any]:
    """:func:`evaluate_design` of ``item = (design, design_hash)``; files go to the folder named by the hash."""
    design, key = item
    return evaluate_design(design, folder=key, **kw)


@contextlib.contextmanager
def open_client(workers: int | None = None, scheduler: str | None = None,
                connect_timeout: float = CONNECT_TIMEOUT_S) -> Iterator[Any]:
    """A Dask client: to ``scheduler`` when given, else to a new local cluster of ``workers`` processes.

    The local cluster has one thread per worker process (OpenCascade and the
    quadrature hold the GIL) and no dashboard.  An unreachable scheduler raises
    :class:`~tabletcad.errors.DesignError` after ``connect_timeout`` seconds.
    """
    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=f"{connect_timeout}s", set_as_default=False)
        except (OSError, TimeoutError, ValueError) as exc:
            raise DesignError("--scheduler", scheduler,
                              f"no Dask scheduler answered within {connect_timeout:g} s ({type(exc).__name__})") from None
        try:
            yield client
        finally:
            client.close()
        return
    import dask

    n = workers if workers is not None else (os.cpu_count() or 1)
    # distributed sets MALLOC_TRIM_THRESHOLD_=65536 in every worker it spawns; glibc then maps and
    # unmaps every large NumPy array, which made the report take 1.8x the CPU time of this process
    # (benchmarks/bench_sweep.py).  The local workers keep glibc's adaptive default, and do not run
    # the statistical profiler (a thread sampling every worker's stack every 10 ms).
    env = {k: v for k, v in dask.config.get("distributed.nanny.pre-spawn-environ", {}).items()
           if k != "MALLOC_TRIM_THRESHOLD_"}
    # An earlier nanny in this process may have left its 65536 in os.environ, which workers inherit.
    inherited = os.environ.pop("MALLOC_TRIM_THRESHOLD_") if os.environ.get("MALLOC_TRIM_THRESHOLD_") == "65536" else None
    try:
        with dask.config.set({"distributed.nanny.pre-spawn-environ": env, "distributed.worker.profile.enabled": False}):
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                                   silence_logs=logging.ERROR)
    finally:
        if inherited is not None:
            os.environ["MALLOC_TRIM_THRESHOLD_"] = inherited
    with cluster, Client(cluster, set_as_default=False) as client:
        yield client


def map_tasks(func: Callable[..., Any], items: Sequence[Any], *, kwargs: dict[str, Any] | None = None,
              client: Any = None, workers: int | None = None, scheduler: str | None = None,
              connect_timeout: float = CONNECT_TIMEOUT_S, progress: bool = True, desc: str = "sweep",
              failed: Callable[[Any], bool] | None = None,
              on_result: Callable[[int, Any], None] | None = None,
              on_error: Callable[[BaseException], Any] | None = None) -> list[Any]:
    """``[func(item, **kwargs) for item in items]`` on Dask, results in the order of ``items``.

    ``func`` must be importable by the workers (a module-level function) and
    its items and results plain data.  ``client`` (an open
    :class:`distributed.Client`) wins over ``scheduler``, which wins over
    ``workers``; ``workers=0`` runs the loop in this process.  ``on_result(i,
    result)`` is called in this process as each result arrives (in completion
    order); ``failed(result)`` marks results counted as failed in the progress
    bar.  An exception raised by ``func`` (or a worker lost while running it,
    :class:`distributed.KilledWorker`) propagates, unless ``on_error(exc)`` is
    given: its return value then stands for that item's result.
    """
    from tqdm import tqdm

    kwargs = kwargs or {}
    results: list[Any] = [None] * len(items)
    bar = tqdm(total=len(items), desc=desc, unit="design", disable=not progress, dynamic_ncols=True)
    n_failed = 0
    bar.set_postfix(failed=0, refresh=False)

    def done(i: int, res: Any) -> None:
        nonlocal n_failed
        results[i] = res
        if failed is not None and failed(res):
            n_failed += 1
        if on_result is not None:
            on_result(i, res)
        bar.update(1)
        bar.set_postfix(failed=n_failed, refresh=False)

    try:
        if client is None and scheduler is None and workers == 0:
            for i, item in enumerate(items):
                done(i, func(item, **kwargs))
            return results
        with contextlib.ExitStack() as stack:
            if client is None:
                client = stack.enter_context(open_client(workers, scheduler, connect_timeout))
            _run_on(client, func, items, kwargs, done, on_error)
        return results
    finally:
        bar.close()


def _run_on(client: Any, func: Callable[..., Any], items: Sequence[Any], kwargs: dict[str, Any],
            done: Callable[[int, Any], None], on_error: Callable[[BaseException], Any] | None) -> None:
    from distributed import as_completed

    threads = max(1, sum(client.nthreads().values()))
    window = IN_FLIGHT_PER_WORKER * threads
    index: dict[str, int] = {}
    it = iter(enumerate(items))
    task = functools.partial(func, **kwargs) if kwargs else func

    def submit(n: int) -> list[Any]:
        futs = []
        for i, item in itertools.islice(it, n):
            fut = client.submit(task, item, pure=False)
            index[fut.key] = i
            futs.append(fut)
        return futs

    ac = as_completed(submit(window), loop=client.loop)
    for fut in ac:
        i = index.pop(fut.key)
        try:
            res = fut.result()
        except Exception as exc:
            if on_error is None:
                raise
            res = on_error(exc)
        fut.release()
        done(i, res)
        for nxt in submit(1):
            ac.add(nxt)
