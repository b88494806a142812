"""Set-up of the worker processes of tabletcad's local Dask cluster (a ``distributed`` preload).

A Ctrl-C at the terminal reaches every process of its group: the command line's, which stops the sweep
(``interrupted``, status 130, the journal kept) and closes the cluster, and each worker's, whose Python
raised KeyboardInterrupt inside Dask's event loop and printed 30-45 lines of tracebacks after
``interrupted``.  The workers ignore SIGINT; the cluster's closing ends them.  They are started with SIGINT
blocked (:func:`tabletcad.parallel.open_client`), so that one sent before this preload runs waits and is
dropped here.
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
    logger = logging.getLogger("distributed.worker")
    if not any(isinstance(f, _LostScheduler) for f in logger.filters):
        logger.addFilter(_LostScheduler())


class _LostScheduler:
    """A logging filter dropping the heartbeat's report of a scheduler gone (the local cluster's, which
    only goes with its sweep)."""

    def filter(self, record) -> bool:
        return not str(record.msg).startswith("Failed to communicate with scheduler during heartbeat")
