"""``tabletcad.io.signals``: SIGTERM as an exception clean-up code sees."""

from __future__ import annotations

import logging
import os
import signal

import pytest

from tabletcad.io.signals import sigterm_raises


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


def test_without_a_sigterm_the_logs_stay_as_they_were():
    """A Ctrl-C's turning off of the logs (the command line's) is not undone by the block's end."""
    logging.disable(logging.CRITICAL)
    try:
        with sigterm_raises():
            pass
        assert logging.root.manager.disable == logging.CRITICAL
    finally:
        logging.disable(logging.NOTSET)

