"""Every figure `ballcage paper` writes is readable: no two labels overlap and nothing is cut off (issue 24, item 10).

The figures are drawn from a run long enough to hold a whole revolution
(0.7 s at 100 rpm, so Table 3's four phases and their cross-sections are
drawn), on 3 joints to keep it short (~2 s). Each figure is rendered at the
PNG's resolution and the boxes of its texts are compared: titles, the
suptitle, axis labels, tick labels, colour-bar labels and legends. Text the
data places (the link numbers beside Table 3's points) is not compared.
`test_the_check_sees_the_old_overlapping_labels_of_table_3` shows the check
catches the overlap it was written for.
"""

from __future__ import annotations

from itertools import combinations
from pathlib import Path
from typing import Any

import pytest

import ballcage
import ballcage._files
import ballcage.paper.figures as paper_figures
import ballcage.paper.section4_figures as section4_figures
from ballcage._plot import figure
from ballcage.duty import write_loss_figure
from ballcage.paper import paper_scene
from ballcage.run import Run
from ballcage.studies.sweep_spec import DEFAULT_TABLES

#: A whole revolution of the upper connector at 100 rpm (0.6 s) after the start.
LONG_ENOUGH = ["pipe.joints=3", "simulation.duration=0.7"]
DPI = 120  # dots per inch of the PNGs (`ballcage._files.write_png`)
SLACK_PX = 1.0  # boxes that only touch within this many pixels do not overlap


@pytest.fixture(scope="module")
def figures(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """Every figure `ballcage paper --sweeps` writes, by file name (without ``.png``), as matplotlib Figures."""
    out = tmp_path_factory.mktemp("figures")
    run = ballcage.simulate(paper_scene(LONG_ENOUGH), progress=False)
    drawn: dict[str, Any] = {}

    def keep(fig: Any, path: Path) -> Path:
        drawn[Path(path).stem] = fig
        return Path(path)

    with pytest.MonkeyPatch.context() as patch:
        for module in (paper_figures, section4_figures, ballcage._files):
            patch.setattr(module, "write_png", keep)
        paper_figures.write_figures(run, out)
        write_loss_figure(run.tables["wear"], out / "losses.png")
        # The section-4 figures from the same run under four labels (the layout is what is checked),
        # with only the tables a sweep case records (no wear table), as `ballcage paper --sweeps` reads them.
        case = Run({t: run.tables[t] for t in DEFAULT_TABLES}, run.scene.to_toml(), scene=run.scene)
        radii = {r: case for r in (1.0, 1.5, 2.0, 2.5)}
        speeds = {s: case for s in (60.0, 80.0, 100.0, 120.0)}
        section4_figures.write_section4_figures(radii, speeds, out)
    return drawn


def _texts(fig: Any) -> list[tuple[str, Any]]:
    """(what, window extent in pixels) of every visible, non-empty label of `fig`, drawn at `DPI`."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # what savefig renders PNG with

    fig.set_dpi(DPI)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()  # runs the constrained layout
    renderer = canvas.get_renderer()
    found: list[tuple[str, Any]] = []

    def add(what: str, artist: Any) -> None:
        if artist is not None and artist.get_visible() and (not hasattr(artist, "get_text") or artist.get_text()):
            found.append((what, artist.get_window_extent(renderer)))

    add("suptitle", fig._suptitle)
    for legend in fig.legends:
        add("figure legend", legend)
    for i, ax in enumerate(fig.axes):
        for side, title in (("title", ax.title), ("left title", ax._left_title), ("right title", ax._right_title)):
            add(f"axes {i} {side}: {title.get_text()!r}", title)
        add(f"axes {i} x label: {ax.xaxis.label.get_text()!r}", ax.xaxis.label)
        add(f"axes {i} y label: {ax.yaxis.label.get_text()!r}", ax.yaxis.label)
        for name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            low, high = sorted(axis.get_view_interval())
            slack = 1e-9 * (high - low)
            for tick in axis.get_major_ticks():  # only the ticks inside the view are drawn
                if low - slack <= tick.get_loc() <= high + slack:
                    add(f"axes {i} {name} tick {tick.label1.get_text()!r}", tick.label1)
                    add(f"axes {i} {name} tick {tick.label2.get_text()!r}", tick.label2)
        add(f"axes {i} legend", ax.get_legend())
    return found


def layout_problems(fig: Any) -> list[str]:
    """Labels of `fig` that overlap another or reach past the figure's edge, in words; empty when it reads well."""
    texts = _texts(fig)
    width, height = fig.bbox.width, fig.bbox.height
    problems = [
        f"{what} is cut off: x {box.x0:.0f}..{box.x1:.0f} of {width:.0f} px, y {box.y0:.0f}..{box.y1:.0f} of {height:.0f}"
        for what, box in texts
        if box.x0 < -SLACK_PX or box.y0 < -SLACK_PX or box.x1 > width + SLACK_PX or box.y1 > height + SLACK_PX
    ]
    for (a, box_a), (b, box_b) in combinations(texts, 2):
        dx = min(box_a.x1, box_b.x1) - max(box_a.x0, box_b.x0)
        dy = min(box_a.y1, box_b.y1) - max(box_a.y0, box_b.y0)
        if dx > SLACK_PX and dy > SLACK_PX:
            problems.append(f"{a} overlaps {b} by {dx:.0f} x {dy:.0f} px")
    return problems


def test_paper_writes_the_figures_checked_here(figures: dict[str, Any]) -> None:
    expected = {*paper_figures.FIGURES, "losses", *section4_figures.SECTION4_FIGURES}
    assert set(figures) == expected


@pytest.mark.parametrize(
    "name", [*paper_figures.FIGURES, "losses", *section4_figures.SECTION4_FIGURES]
)
def test_no_label_overlaps_another_or_is_cut_off(figures: dict[str, Any], name: str) -> None:
    assert layout_problems(figures[name]) == []


def test_table_3_draws_its_four_cross_sections(figures: dict[str, Any]) -> None:
    """The run holds a whole revolution, so the check above saw the four phase panels with their points."""
    sections = [ax for ax in figures["table3_shape"].axes if ax.get_xlabel() == "links.offset_outward [mm]"]
    assert len(sections) == 4 and all(ax.collections for ax in sections)


def test_the_losses_by_radius_have_bars(figures: dict[str, Any]) -> None:
    """The right panel of losses_curvature.png is drawn from the cases' drive tables (they record no wear table)."""
    _, losses = figures["losses_curvature"].axes[:2]
    assert len(losses.patches) == 4 * len(section4_figures.FRICTION_COLUMNS)


def test_the_check_sees_the_old_overlapping_labels_of_table_3() -> None:
    """Table 3's sections as they were: a two-line x label under each of four panels 12 in wide."""
    fig = figure(figsize=(12, 7.5))
    grid = fig.add_gridspec(2, 4)
    for i in range(4):
        ax = fig.add_subplot(grid[0, i])
        ax.set_aspect("equal")
        ax.set(xlabel="links.offset_outward [mm]\n(in the bend plane, + toward the outer wall)",
               ylabel="links.offset_lateral [mm]", xlim=(-17, 17), ylim=(-17, 17))
    fig.add_subplot(grid[1, :])
    problems = layout_problems(fig)
    assert problems and all("x label" in p for p in problems), problems
