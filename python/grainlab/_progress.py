"""The one progress display every long-running grainlab call uses: nothing (the
library's default), a ``tqdm`` bar on a terminal, or plain milestone lines in a
log (docs/cli.md); the count is clamped to ``[0, total]``.
"""

from __future__ import annotations

import sys
import time
from typing import Any, TextIO

_verbose = False

#: Fractions of the total at which a plain (non-terminal) line gets a milestone.
MILESTONES = (0.25, 0.5, 0.75, 1.0)
VERBOSE_MILESTONES = tuple(k / 10 for k in range(1, 11))


def set_verbose(verbose: bool) -> None:
    """Plain progress lines with more milestones and their postfix (``grainlab --verbose``)."""
    global _verbose
    _verbose = bool(verbose)


def _is_terminal(stream: TextIO) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # a closed or unusual stream
        return False


class _NoProgress:
    """What a disabled progress display is: nothing."""

    n = 0.0

    def update(self, n: float = 1) -> None:
        pass

    def moveto(self, n: float) -> None:
        """Sets the count to ``n`` (clamped to [0, total])."""
        self.update(n - self.n)

    def set_description_str(self, text: str) -> None:
        pass

    def set_postfix_str(self, text: str = "", refresh: bool = True) -> None:
        pass

    def close(self) -> None:
        pass

    def __enter__(self) -> _NoProgress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class _Bar(_NoProgress):
    """A tqdm bar on a terminal, with the count clamped to [0, total]."""

    def __init__(self, total: float, desc: str, unit: str, initial: float, stream: TextIO, bar_format: str | None):
        from tqdm import tqdm

        self.total = float(total)
        self.n = min(max(float(initial), 0.0), self.total)
        kwargs: dict[str, Any] = {"bar_format": bar_format} if bar_format else {}
        self._bar = tqdm(total=total, initial=self.n, desc=desc, unit=unit, leave=False, file=stream,
                         dynamic_ncols=True, **kwargs)

    def update(self, n: float = 1) -> None:
        new = min(max(self.n + n, 0.0), self.total)
        if new != self.n:
            self._bar.update(new - self.n)
            self.n = new

    def set_postfix_str(self, text: str = "", refresh: bool = True) -> None:
        self._bar.set_postfix_str(text, refresh=refresh)

    def set_description_str(self, text: str) -> None:
        self._bar.set_description_str(text)

    def close(self) -> None:
        self._bar.close()


class _Lines(_NoProgress):
    """One plain line per phase: the name, then milestones as they pass, then the time taken."""

    def __init__(self, total: float, desc: str, initial: float, stream: TextIO):
        self.total = float(total)
        self.n = min(max(float(initial), 0.0), self.total)
        self.desc = desc
        self.stream = stream
        self.started = time.perf_counter()
        self.postfix = ""
        marks = VERBOSE_MILESTONES if _verbose else MILESTONES
        self._marks = [m for m in marks if self.total > 0 and m * self.total > self.n]
        self._open = False
        self._closed = False

    def _write(self, text: str) -> None:
        if not self._open:
            text = f"{self.desc}: " + text
            self._open = True
        self.stream.write(text)
        self.stream.flush()

    def update(self, n: float = 1) -> None:
        self.n = min(max(self.n + n, 0.0), self.total)
        passed = [m for m in self._marks if self.n >= m * self.total - 1e-12 * self.total]
        if passed:
            self._marks = self._marks[len(passed):]
            text = f"{100 * passed[-1]:.0f} %"
            if _verbose and self.postfix:
                text += f" ({self.postfix})"
            self._write(text + " ... ")

    def set_postfix_str(self, text: str = "", refresh: bool = True) -> None:
        self.postfix = text

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        self._write(f"done in {time.perf_counter() - self.started:.1f} s\n")


def progress_bar(total: float, desc: str, *, enabled: bool = False, unit: str = "it", initial: float = 0,
                 stream: TextIO | None = None, bar_format: str | None = None) -> _NoProgress:
    """A progress display for one phase of ``total`` units (docs/cli.md).

    ``enabled`` False (every library call's default) shows nothing; otherwise a
    tqdm bar when ``stream`` (default ``sys.stderr``) is a terminal and plain
    lines when it is not.
    """
    if not enabled:
        return _NoProgress()
    stream = sys.stderr if stream is None else stream
    if _is_terminal(stream):
        return _Bar(total, desc, unit, initial, stream, bar_format)
    return _Lines(total, desc, initial, stream)


__all__ = ["progress_bar", "set_verbose", "MILESTONES", "VERBOSE_MILESTONES"]
