"""Running one function over many items: in this process, on a local Dask cluster, or on a remote one.

:func:`map_tasks` is the machinery shared by :func:`tabletcad.sweep.run_sweep`
and :func:`tabletcad.tooling.tooling_batch`: it runs a function over items on a
local cluster of worker processes (``workers=N``), on an existing cluster
(``scheduler="tcp://host:port"`` or ``client=``), or in this process
(``workers=0``, the serial loop), with a bounded number of tasks in flight and
a progress bar showing items done, failed and the rate.  Dask ``distributed``
(the ``sweep`` extra) is imported only when a cluster is used.
"""

from __future__ import annotations

import contextlib
import functools
import itertools
import logging
import os
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from tabletcad.errors import DesignError
from tabletcad.io.signals import sigint_blocked, signals_deferred

__all__ = ["map_tasks", "open_client", "CONNECT_TIMEOUT_S", "IN_FLIGHT_PER_WORKER"]

CONNECT_TIMEOUT_S = 10.0
"""Seconds to wait for a Dask scheduler to answer before the sweep stops with a one-line error."""

IN_FLIGHT_PER_WORKER = 4
"""Tasks queued per worker thread; keeps the scheduler's memory flat for sweeps of millions of designs."""


def check_scheduler_address(scheduler: str) -> None:
    """Refuse (:class:`~tabletcad.errors.DesignError`) an address that is not ``[tcp|tls|ws|wss]://host:port``
    or ``host:port``, before any connection is tried (a malformed one waited twice the timeout, and
    Dask's half-made client printed a traceback when it was collected)."""
    import re

    m = re.fullmatch(r"(?:(tcp|tls|ws|wss)://)?(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):(\d{1,5})", str(scheduler).strip())
    if m is None or not 0 < int(m.group(3)) < 65536:
        raise DesignError("--scheduler", scheduler, "must be a Dask scheduler address: [tcp://]host:port "
                          "(or tls://, ws://, wss://), the port from 1 to 65535")


def _check_main_guarded() -> None:
    """Refuse (:class:`RuntimeError`, one message) to start local worker processes from a script's top-level
    code outside ``if __name__ == "__main__":``.

    The workers are spawned: each imports the script again and, unguarded, would start a cluster of its
    own; Python's refusal of that then came back as about 490 lines of tracebacks from the workers and
    their nannies.  Read from the script's own text: the line of the call in its top-level code must lie
    inside such an ``if`` block.  Interactive sessions, notebooks and ``python -c`` have no script to import.
    """
    import ast
    import sys

    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    if main is None or not path or not str(path).endswith(".py") or os.path.basename(str(path)) == "__main__.py":
        return  # (a package's __main__.py is never imported again by the workers)
    name = getattr(getattr(main, "__spec__", None), "name", None)
    if name is not None and (name == "__main__" or name.endswith(".__main__")):  # python -m package: not
        return  # imported again by the workers (multiprocessing.spawn skips a package's __main__)
    frame, line = sys._getframe(1), None
    while frame is not None:
        if frame.f_globals is main.__dict__ and frame.f_code.co_name == "<module>":
            line = frame.f_lineno
            break
        frame = frame.f_back
    if line is None:  # called from a function the script calls under its guard (or from another module)
        return
    try:
        tree = ast.parse(open(path, encoding="utf-8").read())
    except (OSError, SyntaxError, ValueError):
        return

    main_test = {ast.dump(ast.Name("__name__", ast.Load())), ast.dump(ast.Constant("__main__"))}

    def names_main(t: ast.AST) -> bool:  # `__name__ == "__main__"`, alone or in an `and`
        if isinstance(t, ast.BoolOp) and isinstance(t.op, ast.And):
            return any(names_main(x) for x in t.values)
        return (isinstance(t, ast.Compare) and len(t.ops) == 1 and isinstance(t.ops[0], ast.Eq)
                and {ast.dump(t.left), ast.dump(t.comparators[0])} == main_test)

    # any such `if` (at the top level, or inside a top-level `with` or `try`) whose body holds the line
    if any(isinstance(n, ast.If) and names_main(n.test) and n.body
           and n.body[0].lineno <= line <= (n.body[-1].end_lineno or n.body[-1].lineno) for n in ast.walk(tree)):
        return
    raise RuntimeError(f"{path}, line {line}: a sweep or batch on local worker processes must be started under "
                       "'if __name__ == \"__main__\":' (the workers import the script again), or with workers=0 "
                       "to run in this process")


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
        check_scheduler_address(scheduler)
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

    _check_main_guarded()
    n = workers if workers is not None else (os.cpu_count() or 1)
    # distributed sets MALLOC_TRIM_THRESHOLD_=65536 in every worker it spawns; glibc then maps and
    # unmaps every large NumPy array, which made the report take 1.8x the CPU time of this process
    # (benchmarks/bench_sweep.py).  The local workers keep glibc's adaptive default, and do not run
    # the statistical profiler (a thread sampling every worker's stack every 10 ms).  The event loops'
    # latency tick (a measurement only: a log line above 3 s, a dashboard figure) runs every second, not
    # every 20 ms: idle, a 2-worker cluster's scheduler and nannies took 0.30 CPU-s in 10 s with the 20 ms
    # tick, 0.16 with 1 s, and its two workers 0.33 and 0.15.
    env = {k: v for k, v in dask.config.get("distributed.nanny.pre-spawn-environ", {}).items()
           if k != "MALLOC_TRIM_THRESHOLD_"}
    # An earlier nanny in this process may have left its 65536 in os.environ, which workers inherit.
    inherited = os.environ.pop("MALLOC_TRIM_THRESHOLD_") if os.environ.get("MALLOC_TRIM_THRESHOLD_") == "65536" else None
    with contextlib.ExitStack() as stack:
        # the start is not cut in two by a Ctrl-C or SIGTERM (held until the cluster is up, then closing
        # it): one during the start had left the half-started cluster unclosed, its workers running on and
        # its nannies' multiprocessing queues never released (Python's resource tracker then printed
        # "There appear to be 12 leaked semaphore objects to clean up at shutdown" after ``interrupted``)
        with signals_deferred():
            loop = stack.enter_context(_loop_deaf_to_ctrl_c())
            try:
                with dask.config.set({"distributed.nanny.pre-spawn-environ": env,
                                      "distributed.worker.profile.enabled": False,
                                      "distributed.admin.tick.interval": "1s"}):
                    # no dashboard; the scheduler's own HTTP server (health, metrics) on a free local port, not
                    # 8787 (taken by another sweep or notebook: "Port 8787 is already in use" on every run)
                    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                                           scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"},
                                           silence_logs=logging.ERROR, loop=loop,
                                           preload=["tabletcad.worker_setup"])  # workers ignore the terminal's Ctrl-C
            finally:
                if inherited is not None:
                    os.environ["MALLOC_TRIM_THRESHOLD_"] = inherited
            stack.enter_context(cluster)
            client = stack.enter_context(Client(cluster, set_as_default=False))
        try:
            yield client
        except BaseException:  # a Ctrl-C, or an error: the workers' tasks are not waited for
            _stop_workers(cluster)
            raise


@contextlib.contextmanager
def _loop_deaf_to_ctrl_c() -> Iterator[Any]:
    """A running Tornado IO loop of its own thread, started with SIGINT blocked in that thread.

    A local cluster's nannies start the worker processes from that thread (and threads it starts), and a
    process keeps its starter's signal mask across ``exec``: the workers are born deaf to the terminal's
    Ctrl-C, which reaches the whole process group.  Their own handler (:mod:`tabletcad.worker_setup`, which
    then ignores SIGINT) runs only once Dask is imported, and a Ctrl-C in their first 1.5 s had printed
    their import tracebacks after ``interrupted`` and killed them while their nannies waited for them.
    This process's main thread keeps its Ctrl-C.

    Python's multiprocessing resource tracker is started first, here: started by the nannies' first queue,
    in the loop's thread, it unblocks SIGINT in the thread that starts it (``resource_tracker.ensure_running``
    unblocks the signals it had blocked rather than restoring the mask; CPython 3.11), and the workers
    were born with SIGINT unblocked again."""
    from multiprocessing import resource_tracker

    from distributed.utils import LoopRunner

    if hasattr(resource_tracker, "ensure_running"):  # (POSIX only)
        resource_tracker.ensure_running()
    runner = LoopRunner()
    try:
        with sigint_blocked():
            runner.start()
        yield runner.loop
    finally:
        runner.stop()  # (nothing when it had not started)


WORKER_STOP_GRACE_S = 0.5
"""Seconds a local worker is given to stop when its run ends by an exception (a Ctrl-C) before it is terminated."""


def _stop_workers(cluster: Any, grace: float = WORKER_STOP_GRACE_S) -> None:
    """Stop the worker processes of a local ``cluster`` within about ``grace`` seconds each, their running
    tasks abandoned.

    Dask's own closing of the cluster gives each worker 4 s to finish the task it is running before
    terminating it: a Ctrl-C during a sweep's file builds (or its first task's imports of OpenCascade)
    waited 2-4 s for results nobody would read.  Closed here, the cluster's closing then finds them
    gone; whatever fails here is left to it.

    Parameters
    ----------
    cluster : distributed.LocalCluster
        The cluster :func:`open_client` started.
    grace : float
        Seconds each worker has to stop by itself before its nanny terminates it.
    """
    import asyncio

    async def stop() -> None:
        await asyncio.gather(*(w.close(timeout=grace, reason="tabletcad-run-ended")
                               for w in list(cluster.workers.values())), return_exceptions=True)

    with contextlib.suppress(Exception):
        cluster.sync(stop)


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
