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

__all__ = ["colormap", "figure", "no_data", "series_styles"]

#: Line styles and markers that `series_styles` combines with colours.
_LINE_STYLES = ("-", "--", "-.", ":")
_MARKERS = ("o", "s", "^", "v", "D", "P", "X", "*", "<", ">", "h", "p")


def figure(**kwargs: Any) -> Figure:
    """A new constrained-layout `Figure`; `kwargs` go to its constructor (``figsize`` in inches, …)."""
    from matplotlib.figure import Figure

    return Figure(layout="constrained", **kwargs)


def colormap(name: str) -> Colormap:
    """The registered matplotlib colormap `name` (e.g. ``"viridis"``)."""
    import matplotlib

    return matplotlib.colormaps[name]


def series_styles(count: int) -> list[dict[str, Any]]:
    """`count` plot styles (``color``, ``ls``, ``marker``) that tell that many lines apart.

    Colours come from the qualitative ``tab10`` palette; after every ten the
    line style changes, and each line has its own marker, so neighbours in
    the list never share a colour and no two share colour, style and marker.
    """
    colors = colormap("tab10").colors  # type: ignore[attr-defined]
    return [
        {
            "color": colors[k % len(colors)],
            "ls": _LINE_STYLES[(k // len(colors)) % len(_LINE_STYLES)],
            "marker": _MARKERS[k % len(_MARKERS)],
        }
        for k in range(count)
    ]


def no_data(ax: Axes, text: str) -> None:
    """Writes `text` in the middle of an empty axes."""
    ax.text(0.5, 0.5, text, ha="center", va="center", transform=ax.transAxes)
