"""Helpers for tests of forked processes (:mod:`tabletcad.io.forked`)."""

import os


def gone(pid: int) -> bool:
    """True when ``pid`` is no child of this process any more (reaped: no zombie left)."""
    try:
        os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        return True
    return False
