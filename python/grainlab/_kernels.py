"""Which analysis kernels run: the compiled ones (default) or their NumPy references.

The contact detection of :func:`grainlab.snapshot.detect_contacts`, the
contact normals, the stability index, the rattlers and the fabric sums run in
the Rust engine crate (``grainlab._core``) on several threads; their NumPy
versions are kept as the reference the tests compare them with
(docs/analysis.md, "Speed"). Not public API.

>>> from grainlab import _kernels
>>> with _kernels.numpy_reference():
...     _kernels.compiled()
False
>>> _kernels.compiled()
True
"""

from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Iterator

_NUMPY = contextvars.ContextVar("grainlab_numpy_kernels", default=False)
_THREADS = contextvars.ContextVar("grainlab_kernel_threads", default=0)


def compiled() -> bool:
    """True when the compiled kernels run (outside :func:`numpy_reference`)."""
    return not _NUMPY.get()


def threads() -> int:
    """Threads of the compiled kernels; 0 means every core (rayon's default pool)."""
    return _THREADS.get()


@contextlib.contextmanager
def numpy_reference() -> Iterator[None]:
    """Run the NumPy reference implementations inside the ``with`` block."""
    token = _NUMPY.set(True)
    try:
        yield
    finally:
        _NUMPY.reset(token)


@contextlib.contextmanager
def kernel_threads(count: int) -> Iterator[None]:
    """Run the compiled kernels on ``count`` threads (>= 1) inside the ``with`` block.

    Results do not depend on the count; it only changes the speed.
    """
    if int(count) != count or count < 1:
        raise ValueError(f"threads: must be an integer >= 1, got {count!r}")
    token = _THREADS.set(int(count))
    try:
        yield
    finally:
        _THREADS.reset(token)
