"""Ctrl-C and SIGTERM held back over a step that must not be cut in two."""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Iterator

__all__ = ["signals_deferred"]


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
