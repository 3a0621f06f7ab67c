"""A Ctrl-C that a guarded callback swallows is raised again at the next safe point."""

from __future__ import annotations

import os
import signal
import sys

import pytest

from grainlab._interrupt import interrupts_recorded, raise_if_interrupted


def _swallowing_callback():
    """As h5py's clean-up does: a KeyboardInterrupt raised inside is caught and dropped."""
    try:
        os.kill(os.getpid(), signal.SIGINT)
        for _ in range(1000):  # the handler runs at the next bytecode boundary
            pass
    except KeyboardInterrupt:
        return "swallowed"
    return "not delivered"


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_a_swallowed_interrupt_is_raised_at_the_next_safe_point():
    before = signal.getsignal(signal.SIGINT)  # Python's default, or SIG_IGN under a background launch
    with interrupts_recorded():
        assert _swallowing_callback() == "swallowed"
        with pytest.raises(KeyboardInterrupt):
            raise_if_interrupted()
    raise_if_interrupted()  # outside: forgotten, and a no-op
    assert signal.getsignal(signal.SIGINT) == before  # the handler it found is back


def test_without_an_interrupt_the_safe_point_does_nothing():
    with interrupts_recorded():
        raise_if_interrupted()
