"""``comparison.md``: the comparison table as Markdown, with the command line and what the columns mean."""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

import pyarrow as pa

from ballcage.paper.compare import PHASES_KEY, fmt
from ballcage.paper.definitions import EXTRA_ROWS, REFERENCE_FILE, SWEEPS, reference
from ballcage.paper.places import place_lines
from ballcage.measures.phases import scene_facts
from ballcage.run import Run, Verification

__all__ = ["comparison_markdown", "duty_lines"]


def comparison_markdown(
    table: pa.Table,
    *,
    command: str,
    run: Run | None = None,
    sweep_runs: Mapping[str, Run] | None = None,
    section4: tuple[pa.Table, pa.Table] | None = None,
    unverified: str | None = None,
) -> str:
    """``comparison.md``: a title, the command line, a short paragraph, the table and, with `section4`
    (the sweep's summary and `ballcage.paper.trends.trend_table`), its cases and the paper's trends checked.

    With the columns of `ballcage.paper.compare.with_numerical_error` the table shows each row's measured
    numerical error, and a paragraph says how it was measured; `unverified` says why it was not (the
    verification run failed, or ``--no-verify``)."""
    duration = ""
    if run is not None:
        facts = scene_facts(run)
        duration = (
            f"This run simulated {facts.duration:g} s (the paper: 1.8 s) at {facts.rpm:g} rpm in a "
            f"R = {facts.curvature_radius:g} m guide tube. "
        )
    swept = ", ".join(SWEEPS[v].label for v in (sweep_runs or {}) if v in SWEEPS)
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
            + (f"Section-4 cases with reference values: {swept}." if swept else "Sweep rows need `--sweeps`.")
        ),
    ]
    errors = "numerical_error" in table.column_names
    if errors:
        lines += ["", _error_paragraph(table, run, unverified)]
    spread = "spread_min" in table.column_names
    if spread:
        lines += ["", _spread_paragraph(table)]
    extra = ("spread over unstated parameters | dominant parameter | ", "--- | --- | ") if spread else ("", "")
    error = ("numerical error | ", "---: | ") if errors else ("", "")
    header = f"| key | paper | ours | unit | ratio | {error[0]}{extra[0]}note |"
    lines += ["", header, f"| --- | ---: | ---: | --- | ---: | {error[1]}{extra[1]}--- |"]
    phases = json.loads((table.schema.metadata or {}).get(PHASES_KEY.encode(), b"{}"))
    for r in table.to_pylist():
        paper = "" if r["paper"] is None else fmt(r["paper"])
        ours = "" if r["ours"] is None else fmt(r["ours"])
        ratio = "" if r["ratio"] is None else f"{r['ratio']:.3f}"
        note = str(r["note"])
        if phases.get("note"):
            note = note.replace(phases["note"], "phases: listed under the table")
        note = note.replace("|", "\\|")
        cells = (_error_cell(r) if errors else "") + (_spread_cells(r) if spread else "")
        lines.append(f"| {r['key']} | {paper} | {ours} | {r['unit']} | {ratio} | {cells}{note} |")
    if run is not None and run.fallback_note is not None:
        lines[lines.index(header)] = f"**Warning: {run.fallback_note}.**\n\n{header}"
    lines += _phase_lines(phases)
    if run is not None:
        lines += place_lines(run)
    if run is not None and "wear" in run.tables:
        lines += duty_lines(run)
    if section4 is not None:
        from ballcage.paper.trends import trend_markdown  # deferred: it imports the sweep machinery

        lines += trend_markdown(*section4)
    return "\n".join(lines) + "\n"


def _error_cell(row: Mapping[str, Any]) -> str:
    """A row's numerical-error cell: relative in per cent, an index's difference as a count, "—" where not verified."""
    rel, difference = row["numerical_error_rel"], row["numerical_error"]
    if rel is not None:
        unconfirmed = " (not confirmed)" if row.get("numerical_error_confirmed") is False else ""
        return f"{fmt(100.0 * rel, 2)} %{unconfirmed} | "
    if difference is None:
        return "— | "
    if row["unit"] in ("", "1", None):  # an index: the runs agree or name another part
        return "0 | " if difference == 0 else f"another part, {fmt(difference)} apart | "
    return f"{fmt(difference)} {row['unit']} | "


def _error_paragraph(table: pa.Table, run: Run | None, unverified: str | None) -> str:
    """How the numerical-error column was measured, and its largest value; or why it is empty."""
    if unverified is not None:
        return f"**Numerical error: {unverified}.** The numerical error column is empty."
    meta = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}
    verification = run.verification if run is not None else None
    rows = [(r["numerical_error_rel"], r["key"]) for r in table.to_pylist() if r["numerical_error_rel"] is not None]
    largest = max(rows) if rows else None
    text = (
        "Numerical error: each row's |ours − ours of the same run repeated ten times tighter| "
        f"(at {meta.get('ballcage.verify.setting', '?')}: {', '.join(json.loads(meta.get('ballcage.verify.overrides', '[]')))}; "
        "the rule of `ballcage run --verify`, both values in `verify.parquet`), relative to the tighter run's value "
        "or the unit's floor (1 N, 0.1 deg, 1 mm). It is this run's measured error, not an assumed one; the "
        "sweep rows are not verified (their cases are not rerun). "
    )
    if largest is not None:
        text += f"The largest: {fmt(100.0 * largest[0], 2)} % on `{largest[1]}`"
        if verification is not None and verification.time_ratio is not None:
            text += f"; the verification took {fmt(verification.time_ratio, 2)}× the run's time"
        text += "."
    if verification is not None and verification.confirm_setting is not None:
        text += " " + _confirmation(verification)
    return text


def _confirmation(verification: Verification) -> str:
    """What the second verification run (``--verify 2``) says of the first, over every headline quantity of
    ``verify.parquet`` (the comparison rows and the per-link ones)."""
    first, second = verification.setting, verification.confirm_setting

    def percent(x: float | None) -> str:
        return "?" if x is None else f"{fmt(100.0 * x, 2)} %"

    own, largest = percent(verification.confirm_largest), percent(verification.largest)
    scope = f"over the {verification.table.num_rows} headline quantities of `verify.parquet`"
    if verification.confirmed:
        return (f"A second run at {second} confirms it: {scope} the {first} run is within {own} of it, at most a "
                f"third of the largest error it measures there ({largest}); a row marked \"not confirmed\" has "
                "too small an error for the second run to confirm on its own, and is still within the largest plus "
                f"the {first} run's own ({largest} + {own}).")  # fmt: skip
    return (f"**A second run at {second} does not confirm it**: {scope} the {first} run is itself {own} from it "
            f"(on `{verification.confirm_quantity}`), more than a third of the largest error it measures there "
            f"({largest}), so the column understates this run's error (docs/accuracy.md, \"A verification that "
            "checks itself\").")  # fmt: skip


def _spread_cells(row: Mapping[str, Any]) -> str:
    """A row's spread cells: ``min – max | parameter |``, ``— | — |`` where the study has no such quantity."""
    if row["spread_min"] is None and row["spread_dominant"] is None:
        return "— | — | "
    span = "—" if row["spread_min"] is None else f"{fmt(row['spread_min'], 5)} – {fmt(row['spread_max'], 5)}"
    dominant = f"`{row['spread_dominant']}`" if row["spread_dominant"] else "none moves it"
    if row["spread_dominant_below_error"]:
        dominant += " (below the numerical error)"
    return f"{span} | {dominant} | "


def _spread_paragraph(table: pa.Table) -> str:
    """Where the spread columns come from: the sensitivity study, its method, runs and command."""
    meta = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}
    matched = [r for r in table.to_pylist() if r["spread_min"] is not None]
    differ = [
        r["key"] for r in matched
        if r["ours"] is not None and r["spread_min"] is not None
        and not (r["spread_min"] - 1e-9 * abs(r["spread_min"]) <= r["ours"] <= r["spread_max"] + 1e-9 * abs(r["spread_max"]))
    ]  # fmt: skip
    text = (
        f"Spread over the unstated parameters: from `{meta.get('ballcage.sensitivity.source', '')}` "
        f"({meta.get('ballcage.sensitivity.method', '')}, {meta.get('ballcage.sensitivity.runs', '')} runs of "
        f"{meta.get('ballcage.sensitivity.duration_s', '')} s, {meta.get('ballcage.sensitivity.date', '')}: "
        f"`{meta.get('ballcage.sensitivity.command', '')}`): the smallest and largest value of the quantity over the "
        "study's runs and the parameter with the largest effect (its sensitivity.md ranks them all). "
        "— where the study has no such quantity (the section-4 rows are other scenes than the one it varies). "
    )
    if differ:
        text += (
            f"This run's value lies outside the study's range in {len(differ)} of {len(matched)} rows "
            f"({', '.join(differ[:4])}{', …' if len(differ) > 4 else ''}): the study ran another scene than this run "
            f"(its overrides: {meta.get('ballcage.sensitivity.overrides', '')})."
        )
    return text


def duty_lines(run: Run) -> list[str]:
    """Beyond the paper: the paper's seat–key peak against the static contact-stress limit, this run's
    smallest pressure margin, its friction loss by contact and the first 0.1 mm of wear (`ballcage.duty`)."""
    from ballcage.duty import loss_breakdown, margin_line, pressure_at, wear_line

    wear = run.tables["wear"]
    lines = ["", "## Contact pressure, wear and losses (beyond the paper)", ""]
    peak = next(q for q in reference()["quantity"] if q["key"] == "seat_key_normal_peak_n")
    outer = pressure_at(wear, "outer-race", peak["value"])
    inner = pressure_at(wear, "inner-race", peak["value"])
    allowable = float(run.scene.value("materials.pipe_steel.allowable_pressure"))
    bearing = float(run.scene.value("materials.key_steel.allowable_pressure"))
    if outer is not None:
        verdict = "within" if outer <= allowable else "beyond"
        inner_text = f", {inner / 1e6:.0f} MPa on an inner race" if inner is not None else ""
        lines.append(
            f"- The paper's {peak['value'] / 1e3:g} kN seat–key peak (`{peak['key']}`) is **{verdict} the static "
            f"contact-stress limit**: Hertz p0 = {outer / 1e6:.0f} MPa on an outer race{inner_text}, "
            f"{outer / allowable:.1f}× the {allowable / 1e6:.0f} MPa the races' 35CrMo may carry "
            f"(`materials.pipe_steel.allowable_pressure`, first yield) and {outer / bearing:.1f}× the "
            f"{bearing / 1e6:.0f} MPa static rating of bearing steel (`materials.key_steel`)."
        )
    for line in (margin_line(wear), wear_line(wear)):
        if line is not None:
            lines.append(f"- This run: {line}.")
    losses = loss_breakdown(wear)
    total = sum(losses.values())
    if total > 0.0:
        lines += ["", "| friction loss | mean power [W] | share |", "| --- | ---: | ---: |"]
        lines += [f"| {g} | {w:.1f} | {100 * w / total:.1f} % |" for g, w in losses.items()]
        lines.append(f"| all | {total:.1f} | 100 % |")
    return lines


def _phase_lines(phases: Mapping[str, Any]) -> list[str]:
    """Table 3's phases (`PHASES_KEY`), listed once under the table."""
    if not phases.get("phases"):
        return []
    lines = [
        "",
        "Phases of Table 3, the upper connector's angle in its last revolution (the rows above marked "
        '"phases: listed under the table"): at each, the most deformed joint k (the hinge with the largest mean '
        "bend over the last revolution), the included angle at hinge k, in 3-D and projected on the bend plane, "
        "link k's centre offset, and the link whose centre is furthest out there.",
        "",
    ]
    lines += [f"- {item}" for item in phases["phases"]]
    if phases.get("outside"):
        lines += ["", f"Only {phases['outside']}."]
    return lines


def _extra_rows_sentence() -> str:
    """Which rows are not in the reference file and where their paper value comes from."""
    parts = [
        f"`{e.key}` (paper value: that of `{e.paper_from}`)" if e.paper_from else f"`{e.key}` (the paper gives none)"
        for e in EXTRA_ROWS
    ]
    return (
        f"Rows the reference file lacks follow the row they belong to: {', '.join(parts)}; "
        "the phases behind Table 3's rows (the most deformed joint k, the included angle at hinge k between link k "
        "and link k+1, link k's range of motion) are listed once, under the table."
    )
