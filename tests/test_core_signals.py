"""``tabletcad.io.signals``: SIGTERM as an exception clean-up code sees, and SIGINT kept from the
processes a thread starts (the sweep's local workers)."""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import threading

import pytest

from tabletcad.io.signals import sigint_blocked, sigterm_raises

posix = pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="POSIX signal masks")


def test_a_sigterm_inside_raises_systemexit_143_with_the_logs_off_until_the_block_ends():
    before = signal.getsignal(signal.SIGTERM)
    logged: list[bool] = []
    with pytest.raises(SystemExit) as info:
        with sigterm_raises():
            try:
                os.kill(os.getpid(), signal.SIGTERM)
                for _ in range(1000):  # (the handler runs at the next bytecode boundary)
                    pass
            finally:  # the clean-up: what it logs tells only of the termination
                logged.append(logging.getLogger("distributed.scheduler").isEnabledFor(logging.CRITICAL))
    assert info.value.code == 143 and logged == [False]
    assert logging.root.manager.disable == logging.NOTSET  # turned on again after the block
    assert signal.getsignal(signal.SIGTERM) == before


class _TerminatedOnCollection:
    """An object whose ``__del__`` receives a SIGTERM: the handler runs there, where Python cannot raise."""

    def __del__(self) -> None:
        os.kill(os.getpid(), signal.SIGTERM)
        for _ in range(1000):  # (the handler runs at the next bytecode boundary: inside this method)
            pass


def test_a_sigterm_handled_where_python_cannot_raise_is_sent_again():
    """A SystemExit raised in a garbage-collector callback or ``__del__`` (distributed's ``GCDiagnosis``
    while a sweep ran) was printed as "Exception ignored in ..." and lost: the sweep ran to its end,
    status 0.  It is sent again 50 ms later and ends the block."""
    import time

    t0 = time.monotonic()
    with pytest.raises(SystemExit) as info:
        with sigterm_raises():
            _TerminatedOnCollection()  # collected at once
            time.sleep(5)  # (the SIGTERM sent again interrupts the sleep)
    assert info.value.code == 143 and time.monotonic() - t0 < 2
    assert logging.root.manager.disable == logging.NOTSET


def test_without_a_sigterm_the_logs_stay_as_they_were():
    """A Ctrl-C's turning off of the logs (the command line's) is not undone by the block's end."""
    logging.disable(logging.CRITICAL)
    try:
        with sigterm_raises():
            pass
        assert logging.root.manager.disable == logging.CRITICAL
    finally:
        logging.disable(logging.NOTSET)


@posix
def test_a_process_started_from_a_thread_begun_with_sigint_blocked_is_born_deaf_to_it():
    """The mask goes to a thread started inside and, across exec, to the processes it starts; the
    calling thread's own mask is restored."""
    seen: list[str] = []

    def start() -> None:
        out = subprocess.run([sys.executable, "-c", "import signal; print(int(signal.SIGINT in "
                              "signal.pthread_sigmask(signal.SIG_BLOCK, set())))"], capture_output=True, text=True)
        seen.append(out.stdout.strip())

    with sigint_blocked():
        thread = threading.Thread(target=start)
        thread.start()
    thread.join()
    assert seen == ["1"]
    assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, set())
