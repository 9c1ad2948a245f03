"""``comparison.md``: the comparison table as Markdown, with the command line and what the columns mean."""

from __future__ import annotations

from collections.abc import Mapping

import pyarrow as pa

from ballcage.paper.compare import fmt
from ballcage.paper.definitions import EXTRA_ROWS, REFERENCE_FILE, SWEEPS
from ballcage.paper.facts import scene_facts
from ballcage.run import Run

__all__ = ["comparison_markdown"]


def comparison_markdown(
    table: pa.Table,
    *,
    command: str,
    run: Run | None = None,
    sweep_runs: Mapping[str, Run] | None = None,
) -> str:
    """``comparison.md``: a title, the command line, a short paragraph and the table."""
    duration = ""
    if run is not None:
        facts = scene_facts(run)
        duration = (
            f"This run simulated {facts.duration:g} s (the paper: 1.8 s) at {facts.rpm:g} rpm in a "
            f"R = {facts.curvature_radius:g} m guide tube. "
        )
    swept = ", ".join(SWEEPS[v][1] for v in (sweep_runs or {}) if v in SWEEPS)
    lines = [
        "# ballcage vs Zhu et al., Machines 2023, 11, 357",
        "",
        "```",
        command,
        "```",
        "",
        (
            f"{duration}Each row is one `[[quantity]]` of the shipped reference file "
            f"(`ballcage/data/{REFERENCE_FILE}`): the paper's value, ours from the recorded tables, and "
            f"ratio = ours / paper. {_extra_rows_sentence()} "
            "The note says how our definition is computed, where it differs from the "
            "paper's, and when the paper's own value is suspect (it contradicts other numbers of the paper, "
            "see docs/model.md §6): compare those as order of magnitude only. Empty cells were not computed. "
            + (f"Sweep variants run: {swept}." if swept else "Sweep rows need `--sweeps`.")
        ),
        "",
        "| key | paper | ours | unit | ratio | note |",
        "| --- | ---: | ---: | --- | ---: | --- |",
    ]
    for r in table.to_pylist():
        paper = "" if r["paper"] is None else fmt(r["paper"])
        ours = "" if r["ours"] is None else fmt(r["ours"])
        ratio = "" if r["ratio"] is None else f"{r['ratio']:.3f}"
        note = str(r["note"]).replace("|", "\\|")
        lines.append(f"| {r['key']} | {paper} | {ours} | {r['unit']} | {ratio} | {note} |")
    return "\n".join(lines) + "\n"


def _extra_rows_sentence() -> str:
    """Which rows are not in the reference file and where their paper value comes from."""
    parts = [
        f"`{e.key}` (paper value: that of `{e.paper_from}`)" if e.paper_from else f"`{e.key}` (the paper gives none)"
        for e in EXTRA_ROWS
    ]
    return (
        f"Rows the reference file lacks follow the row they belong to: {', '.join(parts)}; "
        "the per-phase rows of Table 3 (most deformed link, included angle at hinge k between link k and link k+1) "
        "list each phase in the note."
    )
