"""Ctrl-C and SIGTERM held back over a step that must not be cut in two; SIGTERM made an exception
that clean-up code sees; Ctrl-C kept from the processes a thread starts."""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Iterator

__all__ = ["signals_deferred", "sigterm_raises", "sigint_blocked"]


@contextlib.contextmanager
def signals_deferred() -> Iterator[None]:
    """While inside (main thread), SIGINT and SIGTERM wait (publishing is all or nothing; a forked
    helper is recorded before a Ctrl-C can end its parent's set-up, :class:`tabletcad.io.forked.Forked`).

    Python runs signal handlers in the main thread whichever thread the system
    delivers to, so holding handlers are installed for the block (a signal mask
    would hold back only the main thread's deliveries); a signal that came
    meanwhile goes to the previous handler when the block ends.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []

    def hold(signum, frame):  # noqa: ARG001
        caught.append(signum)

    old = {s: signal.signal(s, hold) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, handler in old.items():
            signal.signal(s, handler if handler is not None else signal.SIG_DFL)
        for s in dict.fromkeys(caught):
            handler = old[s]
            if callable(handler):
                handler(s, None)  # Python's default_int_handler raises KeyboardInterrupt
            elif handler == signal.SIG_DFL or handler is None:
                os.kill(os.getpid(), s)


@contextlib.contextmanager
def sigterm_raises() -> Iterator[None]:
    """While inside (main thread), SIGTERM raises :class:`SystemExit` (status 143) so that clean-up runs.

    Python's default for SIGTERM ends the process at once: no ``finally`` block, no ``atexit`` handler
    (a build's staging folder, a sweep's empty ``--out`` folder and its cluster's semaphores were left).
    From the signal to the block's end the log records are turned off (as the command line does for a
    Ctrl-C): what the clean-up logs tells only of the termination itself (a sweep's in-process Dask
    scheduler logged "Couldn't gather keys" for the result the terminated client no longer fetched).

    Python runs the handler between any two bytecodes of the main thread, also in a garbage-collector
    callback or a ``__del__``, where an exception cannot be raised: it is printed as "Exception ignored
    in ..." and lost (distributed's ``GCDiagnosis`` callback: a sweep then ran to its end, status 0).
    Such a lost SystemExit is sent again as a SIGTERM to this process 50 ms later (from a timer thread:
    sent at once, it would be raised inside the callback again).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    import logging
    import sys

    disabled: list[int] = []  # the level of logging.disable before the signal, once it came
    raised: list[SystemExit] = []

    def handler(signum, frame):  # noqa: ARG001
        if not disabled:
            disabled.append(logging.root.manager.disable)
        logging.disable(logging.CRITICAL)
        raised.append(SystemExit(128 + signum))
        raise raised[-1]

    previous_hook = sys.unraisablehook

    def hook(unraisable) -> None:
        if any(unraisable.exc_value is exc for exc in raised):
            again = threading.Timer(0.05, os.kill, (os.getpid(), signal.SIGTERM))
            again.daemon = True
            again.start()
            return
        previous_hook(unraisable)

    old = signal.signal(signal.SIGTERM, handler)
    sys.unraisablehook = hook
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, old if old is not None else signal.SIG_DFL)
        if sys.unraisablehook is hook:
            sys.unraisablehook = previous_hook
        if disabled:  # (only what the handler turned off: a Ctrl-C's own turning off stays)
            logging.disable(disabled[0])


@contextlib.contextmanager
def sigint_blocked() -> Iterator[None]:
    """While inside, SIGINT is blocked in the calling thread's signal mask (POSIX; elsewhere nothing).

    A thread started inside keeps the mask, and so does every process it starts, across ``exec``:
    such a process is born deaf to a terminal's Ctrl-C, which a SIGINT handler installed after its
    start-up imports (a Dask worker's preload, :mod:`tabletcad.worker_setup`) came too late for.
    A SIGINT that arrives meanwhile for this process waits and is delivered when the block ends.
    """
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)
