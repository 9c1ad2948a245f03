"""The comparison with the paper: one row per ``[[quantity]]`` of the reference file (`comparison`)."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pyarrow as pa

from ballcage import _native
from ballcage._links import link_tube_forces
from ballcage.paper.definitions import (
    DEFINITIONS,
    NOT_SWEPT,
    REFERENCE_FILE,
    SUSPECT_FALLBACK,
    SUSPECT_REASONS,
    SWEEP_DEFINITIONS,
    SWEEPS,
    TUBE_LINKS,
    reference,
)
from ballcage.paper.facts import SceneFacts, phases, scene_facts
from ballcage.paper.frames import argmax_where, frame_grid, frame_times
from ballcage.run import Run

__all__ = ["COMPARISON_SCHEMA", "comparison", "fmt"]

COMPARISON_SCHEMA = pa.schema(
    [
        pa.field("key", pa.string(), nullable=False, metadata={"description": "reference quantity key"}),
        pa.field("paper", pa.float64(), metadata={"description": "the paper's value", "unit": "see unit"}),
        pa.field("ours", pa.float64(), metadata={"description": "our value, null when not computed"}),
        pa.field("unit", pa.string(), metadata={"description": "unit of paper and ours"}),
        pa.field("ratio", pa.float64(), metadata={"description": "ours / paper, null when either is null or paper is 0"}),
        pa.field("note", pa.string(), metadata={"description": "suspect values, differing definitions, details"}),
    ]
)
#: A sweep row's key: ``sweep_<variant>_<what>_n``.
_SWEEP_KEY = re.compile(r"^sweep_(?P<variant>[A-Za-z0-9]+)_(?P<what>tube_mean_max|key_peak)_n$")


@dataclass
class _Value:
    """Our value of one reference quantity (``None`` when not computed) and the note on how."""

    ours: float | None
    note: str = ""


def comparison(run: Run, sweep_runs: Mapping[str, Run] | None = None) -> pa.Table:
    """The comparison with the paper: one row per ``[[quantity]]`` of the reference file.

    Columns ``key, paper, ours, unit, ratio, note`` (`COMPARISON_SCHEMA`);
    ``ours`` and ``ratio`` are null where a value is not computed. `run` is a
    run of the paper scene that recorded `PAPER_TABLES`; `sweep_runs` maps the
    `SWEEPS` ids (``"R1000"``, …) to runs of the variants.
    """
    facts = scene_facts(run)
    values = _baseline_values(run, facts)
    columns: dict[str, list[Any]] = {f.name: [] for f in COMPARISON_SCHEMA}
    for q in reference().get("quantity", []):
        for name, cell in _row(q, _value(q["key"], values, sweep_runs)).items():
            columns[name].append(cell)
    meta = {
        "ballcage.reference": REFERENCE_FILE,
        "ballcage.run_duration_s": repr(facts.duration),
        "ballcage.version": _native.__version__,
    }
    return pa.Table.from_pydict(columns, schema=COMPARISON_SCHEMA.with_metadata(meta))


def _value(key: str, values: Mapping[str, _Value], sweep_runs: Mapping[str, Run] | None) -> _Value:
    """Our value of the reference quantity `key`: a baseline value, a sweep variant's, or why there is none."""
    if key in values:
        return values[key]
    m = _SWEEP_KEY.match(key)
    if m is None:
        return _Value(None, "not computed: no definition of this quantity yet")
    variant = m.group("variant")
    if sweep_runs is None or variant not in sweep_runs:
        return _Value(None, NOT_SWEPT if variant in SWEEPS else f"not run: no sweep variant {variant!r}")
    return _sweep_value(sweep_runs[variant], variant, m.group("what"))


def _row(q: Mapping[str, Any], value: _Value) -> dict[str, Any]:
    """One comparison row from a reference ``[[quantity]]`` `q` and our `value`."""
    key = q["key"]
    paper = float(q["value"])
    notes = []
    if q.get("suspect", False):
        notes.append(SUSPECT_REASONS.get(key, SUSPECT_FALLBACK))
    if value.note:
        notes.append(value.note)
    ours = value.ours if value.ours is not None and math.isfinite(value.ours) else None
    ratio = None
    if ours is not None:
        if paper != 0.0:
            ratio = ours / paper
        else:
            notes.append("paper value is 0: ratio undefined")
    return {"key": key, "paper": paper, "ours": ours, "unit": str(q.get("unit", "")), "ratio": ratio, "note": "; ".join(notes)}


def fmt(x: float, digits: int = 4) -> str:
    """`x` to `digits` significant digits."""
    return f"{x:.{digits}g}"


def _baseline_values(run: Run, facts: SceneFacts) -> dict[str, _Value]:
    values: dict[str, _Value] = {}
    values.update(_phase_values(run, facts))
    values.update(_tube_values(run))
    values.update(_internal_values(run))
    return values


def _phase_values(run: Run, facts: SceneFacts) -> dict[str, _Value]:
    keys = ("included_angle_min_deg", "included_angle_max_deg", "range_of_motion_mm", "most_deformed_joint")
    if "links" not in run.tables:
        return {k: _Value(None, "not computed: the run did not record the links table") for k in keys}
    found, skipped = phases(run, facts)
    if not found:
        return {k: _Value(None, "not computed: none of the four phases lies in the run") for k in keys}
    listing = ", ".join(
        f"{p.label} t={p.t:.3f} s: link {p.most_deformed}, {p.included_angle:.2f} deg, {p.offset_mm:.2f} mm"
        for p in found
    )
    where = f"phases ({listing})"
    if skipped:
        where += f"; {len(found)} of 4 phases in the run ({', '.join(skipped)} fall before t = 0)"
    angles = [p.included_angle for p in found]
    return {
        "included_angle_min_deg": _Value(min(angles), f"{DEFINITIONS['included_angle_min_deg']}; {where}"),
        "included_angle_max_deg": _Value(max(angles), f"{DEFINITIONS['included_angle_max_deg']}; {where}"),
        "range_of_motion_mm": _Value(max(p.offset_mm for p in found), f"{DEFINITIONS['range_of_motion_mm']}; {where}"),
        "most_deformed_joint": _Value(
            float(round(sum(p.most_deformed for p in found) / len(found))),
            f"{DEFINITIONS['most_deformed_joint']}; {where}",
        ),
    }


def _tube_values(run: Run) -> dict[str, _Value]:
    keys = (
        "tube_normal_peak_joint10_n",
        "tube_normal_mean_joint10_n",
        "tube_normal_mean_joint12_n",
        "tube_normal_mean_all_n",
        "tube_tangential_mean_all_n",
    )
    tube = link_tube_forces(run)
    if tube is None or not tube.normal_mean:
        return {k: _Value(None, "not computed: the run did not record the links table") for k in keys}
    span = f"summary window {tube.start:.3g}-{tube.end:.3g} s, {tube.frames} frames"
    in_plot = [k for k in TUBE_LINKS if k in tube.normal_peak]
    peak_link = max(in_plot, key=lambda k: tube.normal_peak[k]) if in_plot else None
    mean_link = max(tube.normal_mean, key=lambda k: tube.normal_mean[k])

    def row(link: int, values: Mapping[int, float], key: str, extra: str = "") -> _Value:
        if link not in values:
            return _Value(None, f"not computed: the pipe has no link {link}")
        return _Value(values[link], f"{DEFINITIONS[key]} ({span}){extra}")

    peak_extra = (
        f"; largest peak of links {', '.join(map(str, TUBE_LINKS))}: link {peak_link} "
        f"({fmt(tube.normal_peak[peak_link])} N)"
        if peak_link is not None
        else ""
    )
    mean_extra = f"; largest per-link mean: link {mean_link} ({fmt(tube.normal_mean[mean_link])} N)"
    out = {
        "tube_normal_peak_joint10_n": row(10, tube.normal_peak, "tube_normal_peak_joint10_n", peak_extra),
        "tube_normal_mean_joint10_n": row(10, tube.normal_mean, "tube_normal_mean_joint10_n", mean_extra),
        "tube_normal_mean_joint12_n": row(12, tube.normal_mean, "tube_normal_mean_joint12_n"),
    }
    for kind, means in (("normal", tube.normal_mean), ("tangential", tube.tangential_mean)):
        key = f"tube_{kind}_mean_all_n"
        total = sum(means.values())
        out[key] = _Value(
            total,
            f"{DEFINITIONS[key]} ({span}); reading 2, the mean over the {len(means)} links, is {fmt(total / len(means))} N",
        )
    return out


def _internal_values(run: Run) -> dict[str, _Value]:
    out: dict[str, _Value] = {}
    times = frame_times(run)
    hinges = run.tables.get("hinges")
    if hinges is None:
        out["seat_cage_normal_peak_n"] = _Value(None, "not computed: the run did not record the hinges table")
    else:
        grid = frame_grid(hinges, times, ["hinge"], ["cage_seat_normal"])["cage_seat_normal"]
        v, ids, t = argmax_where(grid, times)
        where = f"; at hinge {ids[0]:02d}, t = {t:.4g} s" if ids else ""
        out["seat_cage_normal_peak_n"] = _Value(v, f"{DEFINITIONS['seat_cage_normal_peak_n']}{where}")
    keys = run.tables.get("keys")
    specs = {
        "cage_key_normal_peak_n": "window_normal",
        "seat_key_normal_peak_n": "outer_normal",
        "seat_key_tangential_peak_n": "outer_tangential",
    }
    if keys is None:
        for key in specs:
            out[key] = _Value(None, "not computed: the run did not record the keys table")
        return out
    grids = frame_grid(keys, times, ["hinge", "key"], list(specs.values()))
    for key, column in specs.items():
        v, ids, t = argmax_where(grids[column], times)
        where = f"; at hinge {ids[0]:02d} key {ids[1]}, t = {t:.4g} s" if ids else ""
        out[key] = _Value(v, f"{DEFINITIONS[key]}{where}")
    return out


def _sweep_value(run: Run, variant: str, what: str) -> _Value:
    label = SWEEPS.get(variant, (variant, variant))[1]
    definition = SWEEP_DEFINITIONS[what].format(label=label)
    if what == "tube_mean_max":
        tube = link_tube_forces(run)
        if tube is None or not tube.normal_mean:
            return _Value(None, "not computed: the sweep run did not record the links table")
        link = max(tube.normal_mean, key=lambda k: tube.normal_mean[k])
        links = run.tables["links"]
        mask = links.column("link").to_numpy() == link
        incl = f", mean inclination {float(np.mean(links.column('inclination_deg').to_numpy()[mask])):.1f} deg"
        return _Value(tube.normal_mean[link], f"{definition}; at link {link}{incl}")
    keys = run.tables.get("keys")
    if keys is None:
        return _Value(None, "not computed: the sweep run did not record the keys table")
    times = frame_times(run)
    grids = frame_grid(keys, times, ["hinge", "key"], ["inner_normal", "outer_normal"])
    best: tuple[float, tuple[int, ...], float, str] = (math.nan, (), math.nan, "")
    for column, race in (("inner_normal", "head race"), ("outer_normal", "seat race")):
        v, ids, t = argmax_where(grids[column], times)
        if math.isfinite(v) and not (v <= best[0]):
            best = (v, ids, t, race)
    v, ids, t, race = best
    where = f"; at hinge {ids[0]:02d} key {ids[1]} ({race}), t = {t:.4g} s" if ids else ""
    return _Value(v, f"{definition}{where}")
