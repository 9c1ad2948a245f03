"""The paper's ``[[trend]]`` claims checked on the section-4 sweep (`trend_table`, ``DIR/trends.parquet``).

A claim "q falls (rises) as p grows" is checked on its series (§4.2 for the
curvature radius, §4.3 for the speed), against a tolerance: the larger of
the run-to-run spread, the range (max − min) of q over the baseline and its
two copies with R moved by ± 1 µm, and twice the numerical error, the
largest |q − q of the case's run ten times tighter| over those cases (when
the sweep verified its cases: ``<q>_error``; a change of two values each
off by up to that much). The verdict:

- ``holds``: q changes end to end in the claimed direction by more than the
  tolerance, and no step between neighbouring cases goes against it by more
  than the tolerance;
- ``holds end to end, not monotone``: as above, but some step goes against it;
- ``flat``: the end-to-end change is within the tolerance;
- ``reversed``: q changes end to end against the claim by more than the tolerance;
- ``not checked: ...``: q is missing (a case did not finish, or the hinge model
  has no keys), or the reference file has a trend this module has no rule for.

``normal_exceeds_tangential`` holds when, in every finished case, each normal
force of `NORMAL_TANGENTIAL_PAIRS` is at least `MUCH_LARGER` times its
tangential partner. The paper's own numbers for the same claim (the
reference file's ``sweep_*`` values, with its baseline) get the same verdict
with no spread, which shows where the paper contradicts itself.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import pyarrow as pa

from ballcage.paper.compare import fmt
from ballcage.paper.definitions import (
    BASELINE_RADIUS,
    BASELINE_RPM,
    MUCH_LARGER,
    NORMAL_TANGENTIAL_PAIRS,
    SWEEPS,
    TREND_RULES,
    reference,
)
from ballcage.paper.section4 import RADIUS_KEY, RPM_KEY, series_rows, spread_rows

__all__ = ["TRENDS_SCHEMA", "trend_markdown", "trend_table", "verdict"]

TRENDS_SCHEMA = pa.schema(
    [
        pa.field("key", pa.string(), nullable=False, metadata={"description": "the reference file's [[trend]] key"}),
        pa.field("claim", pa.string(), metadata={"description": "the paper's claim, as the reference file words it"}),
        pa.field("quantity", pa.string(), metadata={"description": "the summary.parquet column the claim is checked on"}),
        pa.field("parameter", pa.string(), metadata={"description": "the swept scene key (empty: every case)"}),
        pa.field("ours", pa.string(), metadata={"description": "our values along the series, parameter: value"}),
        pa.field("change", pa.float64(), metadata={"description": "last minus first value of the series", "unit": "see quantity"}),
        pa.field("change_percent", pa.float64(), metadata={"description": "change / baseline value", "unit": "%"}),
        pa.field("spread", pa.float64(), metadata={"description": "run-to-run spread: max - min over the baseline and "
                                                   "its two copies with R moved by +-1 um", "unit": "see quantity"}),
        pa.field("spread_percent", pa.float64(), metadata={"description": "spread / baseline value", "unit": "%"}),
        pa.field("numerical_error", pa.float64(), metadata={"description": "the largest numerical error of the quantity "
                                                            "over the series and the spread's cases, |value - value "
                                                            "ten times tighter|; null when not verified",
                                                            "unit": "see quantity"}),
        pa.field("numerical_error_percent", pa.float64(), metadata={"description": "numerical_error / baseline value",
                                                                    "unit": "%"}),
        pa.field("verdict", pa.string(), metadata={"description": "holds, holds end to end (not monotone), flat, "
                                                   "reversed, or not checked (why), against the larger of the spread "
                                                   "and twice the numerical error"}),
        pa.field("other_windows", pa.string(), metadata={"description": "the verdict with the quantities averaged "
                                                         "over other windows (label: verdict; null: none given)"}),
        pa.field("paper", pa.string(), metadata={"description": "the paper's own numbers for the claim"}),
        pa.field("paper_verdict", pa.string(), metadata={"description": "the same verdict on the paper's numbers, "
                                                         "with no spread"}),
    ]
)
#: Reference keys of the paper's baseline values: the largest per-joint mean tube force (joint 10) and the key peak.
_PAPER_BASELINE = {"tube_normal_mean_max_n": "tube_normal_mean_joint10_n", "key_peak_n": "seat_key_normal_peak_n"}
_PAPER_WHAT = {"tube_normal_mean_max_n": "tube_mean_max", "key_peak_n": "key_peak"}
#: Units of the swept values, as printed in the ``ours`` and ``paper`` columns.
_PARAMETER_UNIT = {RADIUS_KEY: "m", RPM_KEY: "rpm"}


def verdict(xs: Sequence[float], ys: Sequence[float], direction: int, spread: float) -> str:
    """The verdict on "y rises (`direction` +1) or falls (-1) as x grows" for points sorted by x."""
    if len(ys) < 2:
        return "not checked: fewer than two cases finished"
    total = ys[-1] - ys[0]
    if abs(total) <= spread:
        return "flat"
    if total * direction < 0:
        return "reversed"
    against = [b - a for a, b in zip(ys, ys[1:], strict=False) if (b - a) * direction < -spread]
    return "holds end to end, not monotone" if against else "holds"


def trend_table(summary: pa.Table, windows: Mapping[str, Sequence[Mapping[str, Any]]] | None = None) -> pa.Table:
    """One row per ``[[trend]]`` of the reference file, checked on the section-4 sweep's `summary`.

    `windows` maps a label (``"0.3-1.8 s"``) to the sweep's rows with their
    quantities over another averaging window (`Section4.window_rows`); the
    verdict under each goes in the ``other_windows`` column, to show whether a
    verdict hinges on the window (``record.summary_window``) we chose.
    """
    rows = summary.to_pylist()
    units = {f.name: (f.metadata or {}).get(b"unit", b"").decode() for f in summary.schema}
    out = []
    for trend in reference().get("trend", []):
        key, claim = str(trend["key"]), str(trend.get("what", ""))
        row = _trend(key, claim, rows, units)
        others = [f"{label}: {_trend(key, claim, list(alt), units)['verdict']}" for label, alt in (windows or {}).items()]
        out.append({**row, "other_windows": "; ".join(others) or None})
    columns = {f.name: [r.get(f.name) for r in out] for f in TRENDS_SCHEMA}
    return pa.Table.from_pydict(columns, schema=TRENDS_SCHEMA)


def _trend(key: str, claim: str, rows: Sequence[Mapping[str, Any]], units: Mapping[str, str]) -> dict[str, Any]:
    if key in TREND_RULES:
        return _series_trend(key, claim, rows, units)
    if key == "normal_exceeds_tangential":
        return _ratio_trend(key, claim, rows)
    return _row(key, claim, verdict="not checked: no rule for this trend key")


def _series_trend(key: str, claim: str, rows: Sequence[Mapping[str, Any]], units: Mapping[str, str]) -> dict[str, Any]:
    quantity, parameter, direction = TREND_RULES[key]
    series = series_rows(rows, parameter)
    points = [(float(r[parameter]), r.get(quantity)) for r in series]
    known = [(x, float(y)) for x, y in points if y is not None]
    paper, paper_verdict = _paper_series(quantity, parameter, direction)
    base: dict[str, Any] = dict(quantity=quantity, parameter=parameter, paper=paper, paper_verdict=paper_verdict)
    unit = units.get(quantity, "")
    if len(known) < len(points) or len(known) < 2:
        missing = [f"{x:g}" for x, y in points if y is None]
        why = f"{quantity} is missing at {parameter} = {', '.join(missing)}" if missing else "fewer than two cases"
        return _row(key, claim, **base, verdict=f"not checked: {why}")
    spread_values = [float(r[quantity]) for r in spread_rows(rows) if r.get(quantity) is not None]
    spread = max(spread_values) - min(spread_values) if len(spread_values) >= 2 else 0.0
    errors = [float(e) for r in (*series, *spread_rows(rows)) if (e := r.get(quantity + "_error")) is not None]
    error = max(errors) if errors else None
    xs, ys = [p[0] for p in known], [p[1] for p in known]
    baseline = _baseline(known, parameter)
    change = ys[-1] - ys[0]
    return _row(
        key,
        claim,
        **base,
        ours=_points(known, parameter, unit),
        change=change,
        change_percent=100.0 * change / baseline if baseline else None,
        spread=spread,
        spread_percent=100.0 * spread / baseline if baseline else None,
        numerical_error=error,
        numerical_error_percent=100.0 * error / baseline if baseline and error is not None else None,
        verdict=verdict(xs, ys, direction, max(spread, 2.0 * error) if error is not None else spread),
    )


def _ratio_trend(key: str, claim: str, rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    ok = [r for r in rows if r["status"] == "ok"]
    parts, smallest = [], []
    for normal, tangential in NORMAL_TANGENTIAL_PAIRS:
        ratios = [float(r[normal]) / float(r[tangential]) for r in ok
                  if r.get(normal) is not None and r.get(tangential) not in (None, 0.0)]
        if not ratios:
            return _row(key, claim, quantity=normal, verdict=f"not checked: {normal} / {tangential} in no finished case")
        smallest.append(min(ratios))
        parts.append(f"{normal} / {tangential}: {min(ratios):.3g}-{max(ratios):.3g}")
    holds = min(smallest) >= MUCH_LARGER
    return _row(
        key, claim,
        quantity=", ".join(n for n, _ in NORMAL_TANGENTIAL_PAIRS),
        ours="; ".join(parts) + f" over {len(ok)} cases",
        verdict=("holds" if holds else "does not hold") + f" (our reading: every ratio >= {MUCH_LARGER:g}; "
                f"smallest {min(smallest):.3g})",
    )


def _paper_series(quantity: str, parameter: str, direction: int) -> tuple[str | None, str | None]:
    """The paper's values along the series (its baseline and the reference's sweep values) and their verdict."""
    quantities = reference().get("quantity", [])
    values = {q["key"]: float(q["value"]) for q in quantities}
    units = {q["key"]: str(q.get("unit", "")) for q in quantities}
    which = 0 if parameter == RADIUS_KEY else 1
    baseline_x = (BASELINE_RADIUS, BASELINE_RPM)[which]
    points = [(baseline_x, values.get(_PAPER_BASELINE.get(quantity, "")))]
    for vid, v in SWEEPS.items():
        x = (v.radius, v.rpm)[which]
        if x != baseline_x:
            points.append((x, values.get(f"sweep_{vid}_{_PAPER_WHAT.get(quantity, '')}_n")))
    known = sorted((x, y) for x, y in points if y is not None)
    if len(known) < 2:
        return None, None
    text = _points(known, parameter, units.get(_PAPER_BASELINE.get(quantity, ""), ""))
    return text, verdict([x for x, _ in known], [y for _, y in known], direction, 0.0)


def _points(points: list[tuple[float, float]], parameter: str, unit: str) -> str:
    """``1 m: 2101 N; 1.5 m: 1278 N``: each swept value with its unit and the quantity."""
    return "; ".join(f"{x:g} {_PARAMETER_UNIT.get(parameter, '')}: {fmt(y)} {unit}".replace("  ", " ") for x, y in points)


def _baseline(points: list[tuple[float, float]], parameter: str) -> float | None:
    x0 = BASELINE_RADIUS if parameter == RADIUS_KEY else BASELINE_RPM if parameter == RPM_KEY else None
    return next((y for x, y in points if x0 is not None and abs(x - x0) < 1e-9), None)


def _row(key: str, claim: str, **cells: Any) -> dict[str, Any]:
    return {"key": key, "claim": claim, **cells}


#: Columns of the section-4 case table in ``comparison.md``: summary column, heading.
_CASE_COLUMNS: tuple[tuple[str, str], ...] = (
    ("tube_normal_mean_max_n", "largest per-link mean tube force [N]"),
    ("tube_normal_mean_all_n", "sum of per-link mean tube forces [N]"),
    ("key_peak_n", "key peak [N]"),
    ("seat_cage_normal_peak_n", "seat-cage peak [N]"),
    ("efficiency", "efficiency [1]"),
    ("wall_time_s", "wall time [s]"),
)


def trend_markdown(summary: pa.Table, table: pa.Table) -> list[str]:
    """``comparison.md``'s section on §4: the cases of the sweep's `summary`, then the trends of `table`."""
    lines = [
        "",
        "## The paper's section 4 as a sweep (`sweeps/summary.parquet`)",
        "",
        "| R [m] | speed [rpm] | status | " + " | ".join(h for _, h in _CASE_COLUMNS) + " |",
        "| ---: | ---: | --- | " + " | ".join("---:" for _ in _CASE_COLUMNS) + " |",
    ]
    for r in summary.to_pylist():
        cells = [f"{r[RADIUS_KEY]:.7g}", f"{r[RPM_KEY]:g}", str(r["status"])]
        cells += ["" if r.get(c) is None else fmt(float(r[c])) for c, _ in _CASE_COLUMNS]
        lines.append("| " + " | ".join(cells) + " |")
    lines += [
        "",
        "## The paper's trends (`[[trend]]`), checked on the section-4 sweep",
        "",
        "The spread is the range of the quantity over the baseline and two copies with R moved by ±1 µm; the "
        "numerical error is its largest difference to the same case run ten times tighter (empty with --no-verify); "
        "a change within the larger of the spread and twice the error is `flat`. The other windows' verdicts weigh "
        "the spread only. `paper` is the same check on the paper's own numbers (its baseline and §4 values).",
        "",
        "| trend | ours | change | spread | numerical error | verdict | verdict over other windows | paper | "
        "paper's verdict |",
        "| --- | --- | ---: | ---: | ---: | --- | --- | --- | --- |",
    ]
    for r in table.to_pylist():
        change = "" if r["change_percent"] is None else f"{r['change_percent']:+.1f} %"
        spread = "" if r["spread_percent"] is None else f"{r['spread_percent']:.2g} %"
        error = "" if r["numerical_error_percent"] is None else f"{r['numerical_error_percent']:.2g} %"
        cells = [r["key"], r["ours"] or "", change, spread, error, r["verdict"], r["other_windows"] or "",
                 r["paper"] or "", r["paper_verdict"] or ""]
        lines.append("| " + " | ".join(str(c).replace("|", "\\|") for c in cells) + " |")
    return lines
