"""The comparison with the paper: one row per ``[[quantity]]`` of the reference file (`comparison`)."""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

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
from ballcage.measures.phases import SceneFacts, scene_facts
from ballcage.measures.quantities import (
    CAGE_PEAKS,
    KEY_PEAKS,
    Peak,
    Table3Motion,
    column_peaks,
    race_peak,
    table3_motion,
)
from ballcage.measures.places import peak_place, tube_profile
from ballcage.measures.shape import BendRanking
from ballcage.paper.places import distribution_row, key_place_text, link12_text
from ballcage.run import Run

if TYPE_CHECKING:
    from ballcage.run import Verification
    from ballcage.studies.sensitivity_report import Spread

__all__ = [
    "COMPARISON_SCHEMA",
    "ERROR_FIELDS",
    "PHASES_KEY",
    "SPREAD_FIELDS",
    "PhaseListing",
    "comparison",
    "fmt",
    "phase_listing",
    "sensitivity_quantity",
    "with_numerical_error",
    "with_spread",
]

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
#: A per-joint tube row's key (the paper's joint NN is our link NN): ``tube_normal_peak_joint10_n``.
_JOINT_KEY = re.compile(r"^tube_(?P<kind>normal|tangential)_(?P<stat>mean|peak)_joint(?P<link>\d+)_n$")
#: The columns `with_spread` adds, in the row's unit: name -> (Arrow type, description).
SPREAD_FIELDS: dict[str, tuple[pa.DataType, str]] = {
    "spread_min": (pa.float64(), "smallest value of the quantity over the sensitivity study's runs (the unstated "
                   "parameters over their ranges; unit as unit); null when the study has no such quantity"),
    "spread_max": (pa.float64(), "largest value over the sensitivity study's runs; null as spread_min"),
    "spread_dominant": (pa.string(), "the parameter with the largest effect on the quantity in the sensitivity study; "
                        "null when none moves it or the study has no such quantity"),
    "spread_dominant_below_error": (pa.bool_(), "the dominant parameter's effect is below the study's numerical "
                                    "error; null without an estimate"),
}  # fmt: skip
#: The columns `with_numerical_error` adds: name -> (Arrow type, unit, description).
ERROR_FIELDS: dict[str, tuple[pa.DataType, str, str]] = {
    "numerical_error": (pa.float64(), "see unit", "the run's measured numerical error of ours: |ours - ours of the "
                        "same run repeated ten times tighter| (ballcage run --verify's setting and rule, verify.parquet; "
                        "unit as unit); null where not verified (a sweep row, or --no-verify)"),
    "numerical_error_rel": (pa.float64(), "1", "numerical_error / max(|ours of the tighter run|, the unit's floor) "
                            "(verify.parquet's rel_difference); null where numerical_error is, and for an index"),
    "numerical_error_confirmed": (pa.bool_(), "", "with --verify 2: whether a run a hundred times tighter confirms "
                                  "numerical_error_rel, the tighter run's own error at most a third of it "
                                  "(verify.parquet's confirmed); null with one verification run and where "
                                  "numerical_error_rel is"),
}  # fmt: skip


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
    "included_angle_projected_min_deg",
    "included_angle_projected_max_deg",
    "range_of_motion_mm",
    "range_of_motion_peak_to_peak_mm",
    "most_deformed_joint",
)


def _phase_values(run: Run, facts: SceneFacts) -> dict[str, _Value]:
    """Table 3's rows: the most deformed joint k, the included angles at hinge k and link k's ranges of motion."""
    if "links" not in run.tables:
        return {k: _Value(None, "not computed: the run did not record the links table") for k in _PHASE_KEYS}
    motion = table3_motion(run, facts)
    if motion is None:
        return {k: _Value(None, "not computed: none of the four phases lies in the run") for k in _PHASE_KEYS}
    listing = phase_listing(run, facts, motion)
    assert listing is not None  # a phase was found
    where = listing.note
    k, ours = motion.joint, motion.values()
    angle_where = f"hinge {k} at every phase; {where}"
    if k == 12:
        angle_where = f"hinge 12's next body is the lower connector, not a link; {angle_where}"
    angles = {key: _Value(ours[key], f"{DEFINITIONS[key]}; {angle_where}") for key in _PHASE_KEYS[:4]}
    for key in _PHASE_KEYS[2:4]:
        if ours[key] is None:
            angles[key] = _Value(None, "not computed: hinge 12's projection needs the lower connector's axis (bodies)")
    clearance = (
        f"radial clearance {1e3 * facts.clearance:.1f} mm = (tube bore {2e3 * facts.tube_inner_radius:.0f} mm - "
        f"link diameter {2e3 * facts.link_radius:.0f} mm) / 2"
    )
    return {
        **angles,
        "range_of_motion_mm": _Value(
            ours["range_of_motion_mm"], f"{DEFINITIONS['range_of_motion_mm']}; link {k}; {clearance}; {where}"
        ),
        "range_of_motion_peak_to_peak_mm": _excursion_value(facts, motion, clearance),
        "most_deformed_joint": _Value(float(k), f"{DEFINITIONS['most_deformed_joint']}; {_choice_note(motion)}"),
    }


@dataclass(frozen=True)
class PhaseListing:
    """Table 3's phases in a run: one line per phase, which fall outside it, and the text the notes end with."""

    items: list[str]  # "0° t=1.350 s: link 10, 168.16 deg at hinge 10 (169.02 deg projected ...), 14.76 mm; ..."
    outside: str  # "1 of 4 phases in the run (0°, 90°, 180° fall before t = 0)", or ""

    @property
    def note(self) -> str:
        """What the notes of Table 3's rows end with: ``phases (…)[; … fall before t = 0]``."""
        text = f"phases ({', '.join(self.items)})"
        return f"{text}; {self.outside}" if self.outside else text

    def to_json(self) -> str:
        return json.dumps({"note": self.note, "phases": self.items, "outside": self.outside}, ensure_ascii=False)


def phase_listing(run: Run, facts: SceneFacts, motion: Table3Motion | None = None) -> PhaseListing | None:
    """The phases of Table 3 found in the run, with the most deformed joint's values at each.

    ``None`` without a links table, a phase in the run or a bend in the last
    revolution. `motion` is `table3_motion` of the run, computed when not given.
    """
    motion = motion if motion is not None else table3_motion(run, facts)
    if motion is None:
        return None
    k = motion.joint
    items = [
        f"{p.label} t={p.t:.3f} s: link {k}, {angle:.2f} deg at hinge {k} ({projected:.2f} deg projected on the "
        f"bend plane), {offset:.2f} mm; furthest out: link {p.furthest} ({p.furthest_offset_mm:.2f} mm)"
        for p, angle, projected, offset in zip(motion.found, motion.angles, motion.projected, motion.offsets_mm, strict=True)
    ]
    skipped = motion.skipped
    outside = f"{len(motion.found)} of 4 phases in the run ({', '.join(skipped)} fall before t = 0)" if skipped else ""
    return PhaseListing(items, outside)


def _ranking_text(ranking: BendRanking, what: str) -> str:
    """``what start-end s (n frames): hinge a 11.07 deg, hinge b …, margin …`` of a `BendRanking`."""
    top = ", ".join(f"hinge {h} {ranking.mean_bend[h]:.2f} deg" for h in ranking.order[:3])
    text = f"{what} {ranking.start:.3f}-{ranking.end:.3f} s ({ranking.frames} frames): {top}"
    if ranking.runner_up is not None:
        text += f"; margin over the runner-up {ranking.margin:.3f} deg"
    return text


def _choice_note(motion: Table3Motion) -> str:
    """How the most deformed joint was chosen: the leading mean bends, the margin, the revolution before."""
    text = _ranking_text(motion.ranking, "mean bends over the last revolution")
    if motion.before is not None and motion.before.winner is not None:
        text += f"; {_ranking_text(motion.before, 'over the revolution before')}"
    furthest = ", ".join(str(p.furthest) for p in motion.found)
    return f"{text}; the link centres furthest out at the phases: links {furthest}"


def _excursion_value(facts: SceneFacts, motion: Table3Motion, clearance: str) -> _Value:
    """Peak-to-peak excursion of the most deformed link's centre over the last revolution [mm]."""
    (start, end), paths = motion.window, motion.paths
    if paths is None:
        return _Value(None, "not computed: no frame of the links table in the last revolution")
    covered = f"last revolution {start:.3f}-{end:.3f} s, {paths.frames} frames"
    if paths.start > start + 0.5 * facts.output_interval + 1e-9:
        covered += f" (the run holds only {paths.end - paths.start:.3f} s of it)"
    k = motion.joint
    value = 1e3 * paths.peak_to_peak(k)
    widest = max(paths.links, key=lambda j: np.nan_to_num(paths.peak_to_peak(j), nan=-1.0))
    return _Value(
        value,
        f"{DEFINITIONS['range_of_motion_peak_to_peak_mm']}; link {k} over the {covered}: excursion {value:.2f} mm, "
        f"largest centre offset {1e3 * paths.largest_offset(k):.2f} mm ({clearance}); largest excursion of any "
        f"link: link {widest} ({1e3 * paths.peak_to_peak(widest):.2f} mm)",
    )


def _tube_values(run: Run) -> dict[str, _Value]:
    keys = (
        "tube_normal_peak_joint10_n",
        "tube_normal_mean_joint10_n",
        "tube_normal_mean_joint12_n",
        "tube_normal_mean_all_n",
        "tube_tangential_mean_all_n",
        "tube_normal_mean_max_inclination_deg",
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
        "tube_normal_mean_joint12_n": row(12, tube.normal_mean, "tube_normal_mean_joint12_n", link12_text(run)),
        "tube_normal_mean_max_inclination_deg": _Value(*distribution_row(run)),
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
    """Peak cage and key forces over hinges, keys and frames [N] (`ballcage.measures.quantities.column_peaks`)."""
    out = _cage_values(run)
    peaks = column_peaks(run, "keys", ["hinge", "key"], KEY_PEAKS)
    if peaks is None:
        out.update({key: _Value(None, "not computed: the run did not record the keys table") for key in KEY_PEAKS})
        return out
    for key, peak in peaks.items():
        where = f"; at hinge {peak.ids[0]:02d} key {peak.ids[1]}, t = {peak.t:.4g} s" if peak.ids else ""
        place = peak_place(run, peak.column) if key == "seat_key_normal_peak_n" and peak.ids else None
        if place is not None:
            where = f"; {key_place_text(place)}"
        out[key] = _Value(peak.value, f"{DEFINITIONS[key]}{where}")
    return out


def _cage_values(run: Run) -> dict[str, _Value]:
    """Peak cage-seat and cage-head normal forces over hinges and frames [N]."""
    if "hinges" not in run.tables:
        return {k: _Value(None, "not computed: the run did not record the hinges table") for k in CAGE_PEAKS}
    peaks: dict[str, Peak] | None = None
    if run.has_ball_keys:
        peaks = column_peaks(run, "hinges", ["hinge"], CAGE_PEAKS)
    if peaks is None:
        why = f"not computed: pipe.hinge = {run.scene.value('pipe.hinge')!r} has no cages"
        return {k: _Value(None, why) for k in CAGE_PEAKS}
    out = {}
    for key, peak in peaks.items():
        where = f"; at hinge {peak.ids[0]:02d}, t = {peak.t:.4g} s" if peak.ids else ""
        other = "head_cage_normal_peak_n" if key == "seat_cage_normal_peak_n" else "seat_cage_normal_peak_n"
        side = "head" if other.startswith("head") else "seat"
        text = f"{DEFINITIONS[key]}{where}; the cage-{side} peak is {fmt(peaks[other].value)} N ({other})"
        out[key] = _Value(peak.value, text)
    return out


def _sweep_value(run: Run, variant: str, what: str) -> _Value:
    label = SWEEPS[variant].label if variant in SWEEPS else variant
    definition = SWEEP_DEFINITIONS[what].format(label=label)
    if what == "tube_mean_max":
        tube = link_tube_forces(run)
        if tube is None or not tube.normal_mean:
            return _Value(None, "not computed: the sweep run did not record the links table")
        profile = tube_profile(run)
        link = max(tube.normal_mean, key=lambda k: tube.normal_mean[k])
        incl = f", mean inclination {profile.inclination[link]:.1f} deg" if profile is not None else ""
        return _Value(tube.normal_mean[link], f"{definition}; at link {link}{incl}")
    peak = race_peak(run)
    if peak is None:
        return _Value(None, "not computed: the sweep run did not record the keys table")
    race = {"inner_normal": "head race", "outer_normal": "seat race"}.get(peak.column, "")
    where = f"; at hinge {peak.ids[0]:02d} key {peak.ids[1]} ({race}), t = {peak.t:.4g} s" if peak.ids else ""
    return _Value(peak.value, f"{definition}{where}")


def sensitivity_quantity(key: str) -> str | None:
    """The quantity of a sensitivity study (`ballcage.studies.sensitivity_run`) and of a run's verification
    (`ballcage.verify.headline`) that comparison row `key` is.

    The same name (the comparison and the sweep plug-in share their
    quantities), except the paper's per-joint tube forces, which are our
    per-link ones (``tube_normal_peak_joint10_n`` → ``tube_normal_peak_link_10_n``);
    ``None`` for a section-4 row (``sweep_*``), a value of another scene
    than the one the study varies.
    """
    if _SWEEP_KEY.match(key):
        return None
    m = _JOINT_KEY.match(key)
    if m is not None:
        return f"tube_{m['kind']}_{m['stat']}_link_{int(m['link']):02d}_n"
    return key


def with_spread(table: pa.Table, spreads: Mapping[str, Spread], meta: Mapping[str, str]) -> pa.Table:
    """The comparison `table` with the spread of a sensitivity study: `SPREAD_FIELDS`, null where no quantity matches.

    A row matches the study's quantity `sensitivity_quantity` names when their
    units agree (``""``, ``"1"`` and ``"-"`` all mean a pure number). `meta`
    (the study's source and settings) goes into the schema metadata.
    """
    columns: dict[str, list[Any]] = {name: [] for name in SPREAD_FIELDS}
    for row in table.select(["key", "unit"]).to_pylist():
        name = sensitivity_quantity(row["key"])
        spread = spreads.get(name) if name is not None else None
        if spread is not None and _plain_unit(spread.unit) != _plain_unit(row["unit"] or ""):
            spread = None
        columns["spread_min"].append(spread.low if spread is not None else None)
        columns["spread_max"].append(spread.high if spread is not None else None)
        columns["spread_dominant"].append(spread.dominant if spread is not None else None)
        columns["spread_dominant_below_error"].append(spread.below_error if spread is not None and spread.dominant else None)
    for name, (kind, description) in SPREAD_FIELDS.items():
        field = pa.field(name, kind, metadata={"description": description, "unit": "see unit" if kind == pa.float64() else ""})
        table = table.append_column(field, pa.array(columns[name], type=kind))
    return table.replace_schema_metadata({**(table.schema.metadata or {}), **meta})


def with_numerical_error(table: pa.Table, verification: Verification | None) -> pa.Table:
    """The comparison `table` with each row's measured numerical error from the run's `verification`: `ERROR_FIELDS`.

    A row takes the difference ``verify.parquet`` holds for the quantity
    `sensitivity_quantity` names when their units agree; null where none
    does (a sweep row: the section-4 cases are not rerun) and for every row
    without a `verification`. The verification's setting goes into the
    schema metadata (``ballcage.verify.setting``, ``ballcage.verify.overrides``).
    """
    rows = {r["quantity"]: r for r in verification.table.to_pylist()} if verification is not None else {}
    columns: dict[str, list[float | bool | None]] = {name: [] for name in ERROR_FIELDS}
    for row in table.select(["key", "unit"]).to_pylist():
        name = sensitivity_quantity(row["key"])
        found = rows.get(name) if name is not None else None
        if found is not None and _plain_unit(found["unit"] or "") != _plain_unit(row["unit"] or ""):
            found = None
        columns["numerical_error"].append(found["abs_difference"] if found is not None else None)
        columns["numerical_error_rel"].append(found["rel_difference"] if found is not None else None)
        columns["numerical_error_confirmed"].append(found.get("confirmed") if found is not None else None)
    for name, (kind, unit, description) in ERROR_FIELDS.items():
        field = pa.field(name, kind, metadata={"description": description, "unit": unit})
        table = table.append_column(field, pa.array(columns[name], type=kind))
    if verification is None:
        return table
    meta = {"ballcage.verify.setting": verification.setting, "ballcage.verify.overrides": json.dumps(verification.overrides)}
    if verification.confirm_setting is not None:
        meta["ballcage.verify.confirm_setting"] = verification.confirm_setting
    return table.replace_schema_metadata({**(table.schema.metadata or {}), **meta})


def _plain_unit(unit: str) -> str:
    return "" if unit in ("", "1", "-") else unit
