"""The comparison with the paper: one row per ``[[quantity]]`` of the reference file (`comparison`)."""

from __future__ import annotations

import json
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
    EXTRA_ROWS,
    NOT_SWEPT,
    REFERENCE_FILE,
    SUSPECT_FALLBACK,
    SUSPECT_REASONS,
    SWEEP_DEFINITIONS,
    SWEEPS,
    TUBE_LINKS,
    reference,
)
from ballcage.paper.facts import Phase, SceneFacts, phases, scene_facts
from ballcage.paper.frames import argmax_where, frame_grid, frame_times
from ballcage.paper.motion import MostFrequent, centre_paths, last_revolution, most_frequent
from ballcage.run import Run

__all__ = ["COMPARISON_SCHEMA", "PHASES_KEY", "PhaseListing", "comparison", "fmt", "phase_listing"]

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
#: Schema metadata key of Table 3's phases in the run (`PhaseListing.to_json`: ``note``, the text the notes of
#: Table 3's rows end with, ``phases``, one line per phase, and ``outside``); absent when no phase lies in the run.
#: ``comparison.md`` prints the phases once, under the table, instead of in every note.
PHASES_KEY = "ballcage.phases"
#: Rows whose value is an index (a link number): a ratio of two indices means nothing.
INDEX_KEYS = frozenset({"most_deformed_joint"})
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
    ``ours`` and ``ratio`` are null where a value is not computed, ``paper``
    and ``ratio`` where the paper gives no value. The rows of `EXTRA_ROWS`
    (a second definition, a value the paper lacks) follow the reference
    quantity they belong to. `run` is a
    run of the paper scene that recorded `PAPER_TABLES`; `sweep_runs` maps the
    `SWEEPS` ids (``"R1000"``, …) to runs of the variants.
    """
    facts = scene_facts(run)
    values = _baseline_values(run, facts)
    listing = phase_listing(run, facts)
    columns: dict[str, list[Any]] = {f.name: [] for f in COMPARISON_SCHEMA}
    for spec in row_specs(reference().get("quantity", [])):
        for name, cell in _row(spec, _value(spec.key, values, sweep_runs)).items():
            columns[name].append(cell)
    meta = {
        "ballcage.reference": REFERENCE_FILE,
        "ballcage.run_duration_s": repr(facts.duration),
        "ballcage.version": _native.__version__,
    }
    if listing is not None:
        meta[PHASES_KEY] = listing.to_json()
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


@dataclass(frozen=True)
class RowSpec:
    """One row of the comparison: its key, the paper's value (None: the paper gives none), unit, suspect flag."""

    key: str
    paper: float | None
    unit: str
    suspect: bool = False


def row_specs(quantities: list[Mapping[str, Any]]) -> list[RowSpec]:
    """The comparison's rows: each reference ``[[quantity]]``, each `EXTRA_ROWS` row right after its `after` key."""
    by_key = {q["key"]: q for q in quantities}
    specs = []
    for q in quantities:
        specs.append(RowSpec(q["key"], float(q["value"]), str(q.get("unit", "")), bool(q.get("suspect", False))))
        for extra in (e for e in EXTRA_ROWS if e.after == q["key"]):
            source = by_key.get(extra.paper_from) if extra.paper_from is not None else None
            paper = float(source["value"]) if source is not None else None
            suspect = bool(source is not None and source.get("suspect", False))
            specs.append(RowSpec(extra.key, paper, extra.unit, suspect))
    return specs


def _row(spec: RowSpec, value: _Value) -> dict[str, Any]:
    """One comparison row from its `spec` and our `value`."""
    notes = []
    if spec.suspect:
        notes.append(SUSPECT_REASONS.get(spec.key, SUSPECT_FALLBACK))
    if value.note:
        notes.append(value.note)
    ours = value.ours if value.ours is not None and math.isfinite(value.ours) else None
    ratio = None
    if spec.key in INDEX_KEYS:
        notes.append("an index, not a magnitude: no ratio")
    elif ours is not None and spec.paper is not None:
        if spec.paper != 0.0:
            ratio = ours / spec.paper
        else:
            notes.append("paper value is 0: ratio undefined")
    note = "; ".join(notes)
    return {"key": spec.key, "paper": spec.paper, "ours": ours, "unit": spec.unit, "ratio": ratio, "note": note}


def fmt(x: float, digits: int = 4) -> str:
    """`x` to `digits` significant digits."""
    return f"{x:.{digits}g}"


def _baseline_values(run: Run, facts: SceneFacts) -> dict[str, _Value]:
    values: dict[str, _Value] = {}
    values.update(_phase_values(run, facts))
    values.update(_tube_values(run))
    values.update(_internal_values(run))
    return values


_PHASE_KEYS = (
    "included_angle_min_deg",
    "included_angle_max_deg",
    "range_of_motion_mm",
    "range_of_motion_peak_to_peak_mm",
    "most_deformed_joint",
)


def _phase_values(run: Run, facts: SceneFacts) -> dict[str, _Value]:
    """Table 3's rows: included angles, the two ranges of motion and the most deformed joint."""
    if "links" not in run.tables:
        return {k: _Value(None, "not computed: the run did not record the links table") for k in _PHASE_KEYS}
    found, _ = phases(run, facts)
    if not found:
        return {k: _Value(None, "not computed: none of the four phases lies in the run") for k in _PHASE_KEYS}
    listing = phase_listing(run, facts)
    assert listing is not None  # a phase was found
    where = listing.note
    chosen = most_frequent([p.most_deformed for p in found], [p.offset_mm for p in found])
    angles = [p.included_angle for p in found]
    hinges = ", ".join(str(p.most_deformed) for p in found)
    angle_where = f"hinges {hinges} at the phases; {where}"
    if any(p.most_deformed == 12 for p in found):
        angle_where = f"hinge 12's next body is the lower connector, not a link; {angle_where}"
    clearance = (
        f"radial clearance {1e3 * facts.clearance:.1f} mm = (tube bore {2e3 * facts.tube_inner_radius:.0f} mm - "
        f"link diameter {2e3 * facts.link_radius:.0f} mm) / 2"
    )
    return {
        "included_angle_min_deg": _Value(min(angles), f"{DEFINITIONS['included_angle_min_deg']}; {angle_where}"),
        "included_angle_max_deg": _Value(max(angles), f"{DEFINITIONS['included_angle_max_deg']}; {angle_where}"),
        "range_of_motion_mm": _Value(
            max(p.offset_mm for p in found), f"{DEFINITIONS['range_of_motion_mm']}; {clearance}; {where}"
        ),
        "range_of_motion_peak_to_peak_mm": _excursion_value(run, facts, chosen, found, clearance),
        "most_deformed_joint": _Value(
            float(chosen.link), f"{DEFINITIONS['most_deformed_joint']}; {_choice_note(chosen, found)}; {where}"
        ),
    }


@dataclass(frozen=True)
class PhaseListing:
    """Table 3's phases in a run: one line per phase, which fall outside it, and the text the notes end with."""

    items: list[str]  # "0° t=1.350 s: link 11, 168.16 deg at hinge 11, 14.76 mm"
    outside: str  # "1 of 4 phases in the run (0°, 90°, 180° fall before t = 0)", or ""

    @property
    def note(self) -> str:
        """What the notes of Table 3's rows end with: ``phases (…)[; … fall before t = 0]``."""
        text = f"phases ({', '.join(self.items)})"
        return f"{text}; {self.outside}" if self.outside else text

    def to_json(self) -> str:
        return json.dumps({"note": self.note, "phases": self.items, "outside": self.outside}, ensure_ascii=False)


def phase_listing(run: Run, facts: SceneFacts) -> PhaseListing | None:
    """The phases of Table 3 found in the run; ``None`` without a links table or a phase in the run."""
    if "links" not in run.tables:
        return None
    found, skipped = phases(run, facts)
    if not found:
        return None
    items = [
        f"{p.label} t={p.t:.3f} s: link {p.most_deformed}, {p.included_angle:.2f} deg at hinge {p.most_deformed}, "
        f"{p.offset_mm:.2f} mm"
        for p in found
    ]
    outside = f"{len(found)} of 4 phases in the run ({', '.join(skipped)} fall before t = 0)" if skipped else ""
    return PhaseListing(items, outside)


def _choice_note(chosen: MostFrequent, found: list[Phase]) -> str:
    """How the most frequent link was chosen from the phases' links."""
    links = ", ".join(str(p.most_deformed) for p in found)
    text = f"per-phase most deformed links {links}: link {chosen.link} at {chosen.count} of {len(found)} phases"
    if chosen.tie:
        largest = max(p.offset_mm for p in found if p.most_deformed == chosen.link)
        tied = ", ".join(map(str, chosen.tied))
        text += (
            f"; tie between links {tied} ({chosen.count} each): link {chosen.link} has the largest offset "
            f"({largest:.2f} mm)"
        )
    return text


def _excursion_value(run: Run, facts: SceneFacts, chosen: MostFrequent, found: list[Phase], clearance: str) -> _Value:
    """Peak-to-peak excursion of the most deformed link's centre over the last revolution [mm]."""
    start, end = last_revolution(facts)
    paths = centre_paths(run, start, end)
    if paths is None:
        return _Value(None, "not computed: no frame of the links table in the last revolution")
    covered = f"last revolution {start:.3f}-{end:.3f} s, {paths.frames} frames"
    if paths.start > start + 0.5 * facts.output_interval + 1e-9:
        covered += f" (the run holds only {paths.end - paths.start:.3f} s of it)"
    k = chosen.link
    value = 1e3 * paths.peak_to_peak(k)
    phase_links = sorted({p.most_deformed for p in found})
    others = ", ".join(f"link {j}: {1e3 * paths.peak_to_peak(j):.2f} mm" for j in phase_links)
    widest = max(paths.links, key=lambda j: np.nan_to_num(paths.peak_to_peak(j), nan=-1.0))
    return _Value(
        value,
        f"{DEFINITIONS['range_of_motion_peak_to_peak_mm']}; link {k} over the {covered}: excursion {value:.2f} mm, "
        f"largest centre offset {1e3 * paths.largest_offset(k):.2f} mm ({clearance}); excursions of the phases' "
        f"links: {others}; largest of any link: link {widest} ({1e3 * paths.peak_to_peak(widest):.2f} mm)",
    )


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
    out.update(_cage_values(run, times))
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


def _cage_values(run: Run, times: np.ndarray) -> dict[str, _Value]:
    """Peak cage-seat and cage-head normal forces over hinges and frames [N]."""
    specs = {"seat_cage_normal_peak_n": "cage_seat_normal", "head_cage_normal_peak_n": "cage_head_normal"}
    hinges = run.tables.get("hinges")
    if hinges is None:
        return {k: _Value(None, "not computed: the run did not record the hinges table") for k in specs}
    if run.scene.value("pipe.hinge") != "ball-keys":
        why = f"not computed: pipe.hinge = {run.scene.value('pipe.hinge')!r} has no cages"
        return {k: _Value(None, why) for k in specs}
    grids = frame_grid(hinges, times, ["hinge"], list(specs.values()))
    peaks = {key: argmax_where(grids[column], times) for key, column in specs.items()}
    out = {}
    for key, (v, ids, t) in peaks.items():
        where = f"; at hinge {ids[0]:02d}, t = {t:.4g} s" if ids else ""
        other = "head_cage_normal_peak_n" if key == "seat_cage_normal_peak_n" else "seat_cage_normal_peak_n"
        side = "head" if other.startswith("head") else "seat"
        out[key] = _Value(v, f"{DEFINITIONS[key]}{where}; the cage-{side} peak is {fmt(peaks[other][0])} N ({other})")
    return out


def _sweep_value(run: Run, variant: str, what: str) -> _Value:
    label = SWEEPS[variant].label if variant in SWEEPS else variant
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
