"""A piece of a build run beside the rest in a forked process (Linux, two or more cores).

The build's slowest independent steps hold the GIL (OCC through OCP, matplotlib's PDF and SVG
writers, ezdxf), so threads would take turns; a forked child starts with the parent's memory
(modules, shapes, caches) at no cost, and runs on the other core.  The child returns a picklable
value (or its exception) through a pipe and leaves with ``os._exit``, so none of the parent's
clean-up runs twice.  It must not use OCC's thread pool, whose threads live only in the parent:
:data:`OCC_PARALLEL` is switched off in the child (:func:`tabletcad.cad.mesh.triangulate` and the
tooling's Booleans and distances read it).
"""

from __future__ import annotations

import os
import pickle
import signal
import sys
import traceback
import warnings
from typing import Any, Callable

__all__ = ["OCC_PARALLEL", "Forked", "can_fork"]

#: Whether OCC algorithms may use OCC's thread pool (``[True]``; ``[False]`` in a forked child).
OCC_PARALLEL = [True]


def can_fork() -> bool:
    """True on Linux with two or more usable cores: where :class:`Forked` gains time."""
    if not sys.platform.startswith("linux") or not hasattr(os, "fork"):
        return False
    try:
        return len(os.sched_getaffinity(0)) >= 2
    except (AttributeError, OSError):  # pragma: no cover - Linux has sched_getaffinity
        return (os.cpu_count() or 1) >= 2


def _payload(ok: bool, value: Any) -> bytes:
    try:
        data = pickle.dumps((ok, value))
        pickle.loads(data)  # an exception whose __init__ takes other arguments than its args fails here
        return data
    except Exception:  # noqa: BLE001 - anything unpicklable travels as text
        if ok:
            value = RuntimeError(f"the helper process's result could not be sent back: {value!r:.200}")
        else:
            text = "".join(traceback.format_exception(type(value), value, value.__traceback__))
            value = RuntimeError(f"in the helper process: {type(value).__name__}: {value}\n{text}")
        return pickle.dumps((False, value))


class Forked:
    """``work()`` running in a forked child; :meth:`result` waits for it, :meth:`cancel` stops it.

    The parent must call one of the two (``with`` calls :meth:`cancel` if neither was).
    """

    def __init__(self, work: Callable[[], Any]) -> None:
        sys.stdout.flush()
        sys.stderr.flush()
        r, w = os.pipe()
        with warnings.catch_warnings():  # Python >= 3.12 warns about fork() in a process with threads
            warnings.simplefilter("ignore", DeprecationWarning)
            pid = os.fork()
        if pid == 0:  # the child
            try:
                os.close(r)
                OCC_PARALLEL[0] = False
                try:
                    data = _payload(True, work())
                except BaseException as e:  # noqa: BLE001 - every failure goes back to the parent
                    data = _payload(False, e)
                with os.fdopen(w, "wb") as f:
                    f.write(data)
                sys.stdout.flush()
                sys.stderr.flush()
            finally:
                os._exit(0)
        os.close(w)
        self.pid = pid  #: the child's process id
        self._pid, self._r = pid, r

    def result(self) -> Any:
        """The child's return value (waits for it); its exception is raised here."""
        if self._pid is None:
            raise RuntimeError("the helper process was already waited for")
        with os.fdopen(self._r, "rb") as f:
            data = f.read()
        _, status = os.waitpid(self._pid, 0)
        self._pid = None
        if not data:
            raise RuntimeError(f"the helper process ended without a result (wait status {status})")
        ok, value = pickle.loads(data)
        if not ok:
            raise value
        return value

    def cancel(self) -> None:
        """Stop the child (if still running) and wait for it."""
        if self._pid is None:
            return
        try:
            os.kill(self._pid, signal.SIGKILL)
        except ProcessLookupError:  # pragma: no cover - already gone
            pass
        os.waitpid(self._pid, 0)
        os.close(self._r)
        self._pid = None

    def __enter__(self) -> "Forked":
        return self

    def __exit__(self, *exc) -> None:
        self.cancel()
