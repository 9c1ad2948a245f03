"""Matplotlib without pyplot: bare figures that render with Agg and leave the global backend alone.

Imported only by the modules that draw (`ballcage.paper`, `ballcage.studies`), so
``import ballcage`` does not load matplotlib.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.colors import Colormap
    from matplotlib.figure import Figure

__all__ = ["colormap", "figure", "no_data"]


def figure(**kwargs: Any) -> Figure:
    """A new constrained-layout `Figure`; `kwargs` go to its constructor (``figsize`` in inches, …)."""
    from matplotlib.figure import Figure

    return Figure(layout="constrained", **kwargs)


def colormap(name: str) -> Colormap:
    """The registered matplotlib colormap `name` (e.g. ``"viridis"``)."""
    import matplotlib

    return matplotlib.colormaps[name]


def no_data(ax: Axes, text: str) -> None:
    """Writes `text` in the middle of an empty axes."""
    ax.text(0.5, 0.5, text, ha="center", va="center", transform=ax.transAxes)
