"""Set-up of the worker processes of tabletcad's local Dask cluster (a ``distributed`` preload).

A Ctrl-C at the terminal reaches every process of its group: the command line's, which stops the sweep
(``interrupted``, status 130, the journal kept) and closes the cluster, and each worker's, whose Python
raised KeyboardInterrupt inside Dask's event loop and printed 30-45 lines of tracebacks after
``interrupted``.  The workers ignore SIGINT; the cluster's closing ends them.
"""

from __future__ import annotations


def dask_setup(worker) -> None:  # noqa: ARG001 - distributed's preload hook
    """Ignore SIGINT in this worker process (its parent stops it)."""
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
