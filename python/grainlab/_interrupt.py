"""Ctrl-C that is never lost.

A ``KeyboardInterrupt`` raised while a library runs a Python callback it guards
(h5py's clean-up of closed objects is one) is printed as "Exception ignored" and
dropped, so a run interrupted at such a moment would carry on to the end. Under
:func:`interrupts_recorded` (the command line installs it for every command) a
SIGINT is also recorded, and :func:`raise_if_interrupted`, called by the long
loops at points where what was written is consistent, raises it again.
Outside it, both are no-ops and Ctrl-C behaves as Python's default.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

__all__ = ["interrupts_recorded", "raise_if_interrupted"]

_received = threading.Event()


def _on_sigint(signum: int, frame: FrameType | None) -> None:
    _received.set()
    raise KeyboardInterrupt


@contextmanager
def interrupts_recorded() -> Iterator[None]:
    """Records every SIGINT for :func:`raise_if_interrupted` while the block runs
    (main thread only; elsewhere it changes nothing)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, _on_sigint)
    _received.clear()
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        _received.clear()


def raise_if_interrupted() -> None:
    """Raises ``KeyboardInterrupt`` if a SIGINT was recorded: one that a callback
    swallowed is delivered here, at a point the caller chose."""
    if _received.is_set():
        raise KeyboardInterrupt
