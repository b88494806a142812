"""A piece of a build run beside the rest in a forked process (Linux, two or more cores).

The build's slowest independent steps hold the GIL (OCC through OCP, matplotlib's PDF and SVG
writers, ezdxf), so threads would take turns; a forked child starts with the parent's memory
(modules, shapes, caches) at no cost, and runs on the other core.  The child returns a picklable
value (or its exception) through a pipe and leaves with ``os._exit``, so none of the parent's
clean-up runs twice.  It must not use OCC's thread pool, whose threads live only in the parent:
:data:`OCC_PARALLEL` is switched off in the child (:func:`tabletcad.cad.mesh.triangulate` and the
tooling's Booleans and distances read it).  The child freezes the heap it inherits (``gc.freeze``): its
garbage collector then walks only the objects the child makes, not the parent's hundreds of thousands,
whose pages a walk would also copy (it writes to each object's header).  The drawings' child of the
tooling sample had spent 0.32 s of CPU in two full collections of 330,000 objects that freed 10,000 of
its own.
"""

from __future__ import annotations

import gc
import os
import pickle
import signal
import sys
import traceback
import warnings
from typing import Any, Callable

from tabletcad.io.signals import signals_deferred

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
    """``(ok, value, traceback text)`` pickled; what cannot be pickled travels as text."""
    text = "" if ok else "".join(traceback.format_exception(type(value), value, value.__traceback__))
    try:
        data = pickle.dumps((ok, value, text))
        pickle.loads(data)  # an exception whose __init__ takes other arguments than its args fails here
        return data
    except Exception:  # noqa: BLE001 - anything unpicklable travels as text
        if ok:
            value = RuntimeError(f"the helper process's result could not be sent back: {value!r:.200}")
        else:
            value = RuntimeError(f"in the helper process: {type(value).__name__}: {value}\n{text}")
        return pickle.dumps((False, value, text))


def _flush() -> None:
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (AttributeError, OSError, ValueError):  # None, or closed (``>&-``)
            pass


def _die_with_parent(parent: int) -> None:
    """Linux: SIGKILL this process when its parent ends (a parent killed outright leaves no writer)."""
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL))  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # pragma: no cover - not Linux
        pass
    if os.getppid() != parent:  # the parent ended before the request took effect
        os._exit(1)


class Forked:
    """``work()`` running in a forked child; :meth:`result` waits for it, :meth:`cancel` stops it.

    The parent must call one of the two (``with`` calls :meth:`cancel` if neither was).  The child
    ignores Ctrl-C (the parent, which gets it too, cancels the child) and dies with its parent.
    When the system refuses the fork (memory, process limits), :meth:`result` runs ``work()`` in
    this process instead: the same result, one step after the other.
    """

    def __init__(self, work: Callable[[], Any]) -> None:
        self.pid: int | None = None  #: the child's process id (None when the fork was refused)
        self.refused: OSError | None = None  #: why the system refused the fork, if it did
        self._pid: int | None = None
        self._r: int | None = None
        self._work: Callable[[], Any] | None = None
        _flush()
        try:
            # a Ctrl-C or SIGTERM during the fork and set-up waits until the child is recorded: the system
            # may deliver it to any thread (OCC's pool, a test runner's), and Python would raise it in this
            # one at once, before the unmask below, with the child unrecorded and ignoring Ctrl-C, writing
            # on into a staging folder its parent is removing
            with signals_deferred():
                self._start(work)
        except BaseException:  # raised as the held signal is let through: the caller never gets this object
            self.cancel()
            raise

    def _start(self, work: Callable[[], Any]) -> None:
        """Fork the child that runs ``work`` (or keep ``work`` for :meth:`result` if the system refuses)."""
        parent = os.getpid()
        r, w = os.pipe()
        held = {signal.SIGINT, signal.SIGTERM}
        old_mask = signal.pthread_sigmask(signal.SIG_BLOCK, held)  # no handler runs between fork and set-up
        try:
            with warnings.catch_warnings():  # Python >= 3.12 warns about fork() in a process with threads
                warnings.simplefilter("ignore", DeprecationWarning)
                pid = os.fork()
        except OSError as exc:
            self.refused = exc
            signal.pthread_sigmask(signal.SIG_SETMASK, old_mask)
            os.close(r)
            os.close(w)
            self._work = work
            return
        if pid == 0:  # the child
            try:
                gc.freeze()  # the parent's objects: kept, never walked by this child's collector (see above)
                signal.signal(signal.SIGINT, signal.SIG_IGN)
                signal.signal(signal.SIGTERM, signal.SIG_DFL)
                _die_with_parent(parent)
                signal.pthread_sigmask(signal.SIG_SETMASK, old_mask)
                os.close(r)
                OCC_PARALLEL[0] = False
                try:
                    data = _payload(True, work())
                except BaseException as e:  # noqa: BLE001 - every failure goes back to the parent
                    data = _payload(False, e)
                with os.fdopen(w, "wb") as f:
                    f.write(data)
                _flush()
            finally:
                os._exit(0)
        os.close(w)
        self.pid = self._pid = pid
        self._r = r
        signal.pthread_sigmask(signal.SIG_SETMASK, old_mask)

    def result(self) -> Any:
        """The child's return value (waits for it); its exception is raised here, with the child's
        traceback as a note."""
        if self._work is not None:  # the fork was refused: the work runs here
            work, self._work = self._work, None
            return work()
        if self._pid is None:
            raise RuntimeError("the helper process was already waited for")
        r, self._r = self._r, None  # closed by the read below, whatever happens to it
        with os.fdopen(r, "rb") as f:
            data = f.read()
        _, status = os.waitpid(self._pid, 0)
        self._pid = None
        if not data:
            raise RuntimeError(f"the helper process ended without a result (wait status {status})")
        ok, value, text = pickle.loads(data)
        if not ok:
            if text and hasattr(value, "add_note"):
                value.add_note("raised in a forked helper process (tabletcad.io.forked):\n" + text.rstrip())
            raise value
        return value

    def cancel(self) -> None:
        """Stop the child (if still running) and wait for it."""
        self._work = None
        if self._r is not None:
            os.close(self._r)
            self._r = None
        if self._pid is None:
            return
        try:
            os.kill(self._pid, signal.SIGKILL)
        except ProcessLookupError:  # pragma: no cover - already gone
            pass
        os.waitpid(self._pid, 0)
        self._pid = None

    def __enter__(self) -> "Forked":
        return self

    def __exit__(self, *exc) -> None:
        self.cancel()
