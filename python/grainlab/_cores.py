"""The number of cores this process may run on (``taskset`` and cgroup affinity
count, not the machine's): the ``auto`` thread count of a run and the default
worker count of a campaign."""

from __future__ import annotations

import os


def available_cores() -> int:
    """Cores this process may run on (at least 1)."""
    if hasattr(os, "sched_getaffinity"):
        return max(len(os.sched_getaffinity(0)), 1)
    return os.cpu_count() or 1
