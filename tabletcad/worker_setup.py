"""Set-up of the worker processes of tabletcad's local Dask cluster (a ``distributed`` preload).

A Ctrl-C at the terminal reaches every process of its group: the command line's, which stops the sweep
(``interrupted``, status 130, the journal kept) and closes the cluster, and each worker's, whose Python
raised KeyboardInterrupt inside Dask's event loop and printed 30-45 lines of tracebacks after
``interrupted``.  The workers ignore SIGINT; the cluster's closing ends them.  They are started with SIGINT
blocked (:func:`tabletcad.parallel.open_client`), so that one sent before this preload runs waits and is
dropped here.

A worker still busy when its run is stopped (an OpenCascade call holds the interpreter) is killed by its
nanny after a short grace (:func:`tabletcad.parallel._stop_workers`): a named semaphore it had made is then
never unlinked, and Python's resource tracker, which the workers share with the command line's process,
reported it after ``interrupted``.  The one a build made, tqdm's lock, has no name now
(:func:`_tqdm_lock_unnamed`); a build that made others (a multiprocessing queue or lock) would leave them.
"""

from __future__ import annotations


def dask_setup(worker) -> None:  # noqa: ARG001 - distributed's preload hook
    """Ignore SIGINT in this worker process (its parent stops it), and keep the heartbeat's lost-scheduler
    error out of the terminal: the scheduler lives in the command line's process, which closes it first on
    a Ctrl-C; a heartbeat in flight then logged 30 lines ("Failed to communicate with scheduler during
    heartbeat", StreamClosedError) after ``interrupted`` now and then (a fresh clone's full test run)."""
    import logging
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        if hasattr(signal, "pthread_sigmask"):  # born with SIGINT blocked (parallel._loop_deaf_to_ctrl_c):
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})  # ignored now, a held one is dropped
    _tqdm_lock_unnamed()
    logger = logging.getLogger("distributed.worker")
    if not any(isinstance(f, _LostScheduler) for f in logger.filters):
        logger.addFilter(_LostScheduler())


def _tqdm_lock_unnamed() -> None:
    """Give tqdm's progress bars in this process a lock that holds no named semaphore (POSIX).

    tqdm makes its lock at its first bar, a design's build's (hidden, but made) included: a
    ``multiprocessing.RLock`` of the process's start method, which in a spawned worker is ``spawn``: a
    semaphore with a name in the system, registered with the resource tracker and unlinked only when the
    process ends normally.  A worker killed in a build left it: "resource_tracker: There appear to be 1
    leaked semaphore objects to clean up at shutdown" after a sweep's ``interrupted`` (a loaded machine's
    test runs).  The lock given here is made in the ``fork`` context, whose semaphores are unlinked at
    once: still a lock across threads and the processes this one forks, with nothing to leave behind.
    On Windows a semaphore goes with its last handle, and nothing is changed.
    """
    import multiprocessing

    if "fork" not in multiprocessing.get_all_start_methods():
        return
    try:
        from tqdm import tqdm
    except ImportError:  # (a dependency of tabletcad; a remote worker's environment may lack it)
        return
    tqdm.set_lock(multiprocessing.get_context("fork").RLock())


class _LostScheduler:
    """A logging filter dropping the heartbeat's report of a scheduler gone (the local cluster's, which
    only goes with its sweep)."""

    def filter(self, record) -> bool:
        return not str(record.msg).startswith("Failed to communicate with scheduler during heartbeat")
