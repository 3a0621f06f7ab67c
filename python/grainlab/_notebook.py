"""Figures that show in a Jupyter notebook, and none of pyplot's global state elsewhere.

grainlab draws on figures made without pyplot, so that a script or a test
changes nothing global and any backend works. A notebook, though, shows the
figures pyplot manages (the inline backend draws them at the end of the
cell): inside a Jupyter kernel :func:`new_figure` therefore makes the figure
through pyplot, so that ``StabilityIndex().compute(snap).plot()`` displays it.
"""

from __future__ import annotations

import sys
from typing import Any

from matplotlib.figure import Figure

__all__ = ["in_notebook", "new_figure", "prepare_notebook"]


def in_notebook() -> bool:
    """True inside a Jupyter kernel (an IPython shell with a kernel), False in scripts and terminals."""
    ipython = sys.modules.get("IPython")
    if ipython is None:
        return False
    shell = ipython.get_ipython()
    return shell is not None and getattr(shell, "kernel", None) is not None


def prepare_notebook() -> None:
    """In a notebook, load pyplot's backend now: call it outside any ``rc_context``.

    Loading the inline backend in a kernel switches matplotlib to interactive
    mode (an rcParam), which is what makes it show new figures; loaded by the
    first figure made inside ``mpl.rc_context`` (the paper style), that
    switch would be undone when the context ends, and every later figure
    would stay hidden. (pyplot loads its backend lazily, at the first figure;
    ``_get_backend_mod`` is the function it uses for that.)
    """
    if in_notebook():
        import matplotlib.pyplot as plt

        load = getattr(plt, "_get_backend_mod", None)
        if load is not None:
            load()


def new_figure(**kwargs: Any) -> Figure:
    """A new figure (``Figure(**kwargs)``), made through pyplot in a notebook so that it is shown."""
    if in_notebook():
        import matplotlib.pyplot as plt

        return plt.figure(**kwargs)
    return Figure(**kwargs)
