"""Worker processes that end with the process that started them.

:func:`die_with_parent` is a worker pool's initializer: on Linux it asks the
kernel (``prctl(PR_SET_PDEATHSIG, SIGKILL)``) to kill the worker when its parent
ends, however the parent ends (a crash, ``kill -9``), so that a killed command
leaves no worker behind writing into its folders. Elsewhere it does nothing.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import signal
import sys

__all__ = ["die_with_parent"]

#: prctl option: the signal a process gets when its parent ends (linux/prctl.h).
_PR_SET_PDEATHSIG = 1


def die_with_parent(parent: int) -> None:
    """Have this process killed when process ``parent`` ends (Linux); exits at once
    when ``parent`` has already ended."""
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
        if os.getppid() != parent:  # ended before the request was made
            os._exit(1)
