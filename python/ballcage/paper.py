"""The paper's run: Zhu et al., *Machines* 2023, 11, 357, reproduced and compared.

`run_paper` runs the embedded drill-pipe scene (`ballcage.default_scene`) with
every table recorded, and writes into one directory:

- ``<table>.parquet`` and ``scene.toml`` (`Run.write`);
- the paper's figures as PNG: ``fig09_included_angles``, ``fig10_tube_normal``,
  ``fig11_tube_tangential``, ``fig12_key_normal``, ``fig13_key_tangential``
  and ``table3_shape``;
- ``comparison.parquet`` and ``comparison.md``: one row per ``[[quantity]]``
  of the shipped reference file ``ballcage/data/paper-2023.toml``, with the
  paper's value, ours, their ratio and a note on how our definition differs
  and on values the paper itself contradicts (``suspect``).

With ``sweeps=True`` it also runs the curvature (R = 1.0, 2.5 m) and speed
(60, 120 rpm) variants of §4.2–4.3 and fills the ``sweep_*`` rows.

`comparison(run)` builds the comparison table from any run of the paper scene,
so it can be checked on a short run. Everything is computed from the recorded
tables (``links``, ``hinges``, ``keys``, ``summary``, ``contacts``); the
definitions are in `DEFINITIONS` and are repeated in each row's note.
"""

from __future__ import annotations

import math
import os
import re
import shlex
import sys
import tomllib
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pyarrow as pa

from ballcage import _native
from ballcage.run import Run, _write_atomically, simulate
from ballcage.scene import default_scene

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "COMPARISON_SCHEMA",
    "FIGURES",
    "PAPER_TABLES",
    "SWEEPS",
    "comparison",
    "comparison_markdown",
    "reference",
    "run_paper",
    "write_figures",
]

#: Tables the paper run records.
PAPER_TABLES: tuple[str, ...] = ("bodies", "contacts", "summary", "links", "hinges", "keys", "drive")
#: Tables the sweep variants record (enough for their comparison rows).
SWEEP_TABLES: tuple[str, ...] = ("summary", "links", "keys")
#: Sweep variants of §4.2 (curvature) and §4.3 (speed): id → (override, label).
#: The id is the one in the reference keys, ``sweep_<id>_...``.
SWEEPS: dict[str, tuple[str, str]] = {
    "R1000": ("borehole.curvature_radius=1.0", "R = 1.0 m"),
    "R2500": ("borehole.curvature_radius=2.5", "R = 2.5 m"),
    "rpm60": ("drive.speed_rpm=60", "60 rpm"),
    "rpm120": ("drive.speed_rpm=120", "120 rpm"),
}
#: Figure files (without ``.png``), in the order they are written.
FIGURES: tuple[str, ...] = (
    "fig09_included_angles",
    "fig10_tube_normal",
    "fig11_tube_tangential",
    "fig12_key_normal",
    "fig13_key_tangential",
    "table3_shape",
)
#: Links whose tube forces the paper plots (Figs. 10–11).
TUBE_LINKS: tuple[int, ...] = (2, 4, 6, 8, 10)
#: Bodies whose ball-key forces the paper plots (Figs. 12–13): connectors and links.
KEY_BODIES: tuple[str | int, ...] = ("upper", 1, 3, 6, 9, 12, "lower")
#: Phase labels of Table 3 (upper connector angle in the last revolution).
PHASES: tuple[str, ...] = ("0°", "90°", "180°", "270°")

REFERENCE_FILE = "paper-2023.toml"

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

#: How we compute each reference quantity; repeated in the row's note.
DEFINITIONS: dict[str, str] = {
    "included_angle_min_deg": (
        "ours: at each phase, links.included_angle_deg (angle between the link's axis and the next body's) "
        "of the most deformed link (largest links.radial_offset); smallest over the phases"
    ),
    "included_angle_max_deg": (
        "ours: at each phase, links.included_angle_deg of the most deformed link (largest "
        "links.radial_offset); largest over the phases"
    ),
    "range_of_motion_mm": (
        "differs: ours is the most deformed link's centre-of-mass offset from the tube centreline "
        "(links.radial_offset, mm), largest over the phases; the paper's exact definition of range of motion "
        "is unclear (its Table 3 gives 23.6 / 24.5 / 25.0 / 25.3 mm)"
    ),
    "most_deformed_joint": (
        "ours: the link with the largest links.radial_offset at each phase; reported as the rounded mean "
        "over the phases (the paper's four phases give 4, 6, 5, 4 and it reports 5)"
    ),
    "tube_normal_peak_joint10_n": (
        "ours: summary.normal_peak of pair link10/tube (largest per-frame total normal force over the run)"
    ),
    "tube_normal_mean_joint10_n": (
        "ours: summary.normal_mean of pair link10/tube (mean per-frame total normal force over the whole run, "
        "frames without contact count as 0)"
    ),
    "tube_normal_mean_joint12_n": "ours: summary.normal_mean of pair link12/tube over the whole run",
    "tube_normal_mean_all_n": (
        "differs: ours is the SUM over links 1-12 of summary.normal_mean of the linkNN/tube pairs "
        "(reading 1: a sum, the only reading that can exceed a single joint's peak)"
    ),
    "tube_tangential_mean_all_n": (
        "differs: ours is the SUM over links 1-12 of summary.tangential_mean of the linkNN/tube pairs "
        "(magnitude of the per-frame summed friction vector; reading 1: a sum)"
    ),
    "seat_cage_normal_peak_n": "ours: maximum of hinges.cage_seat_normal over all hinges and frames",
    "cage_key_normal_peak_n": (
        "ours: maximum of keys.window_normal (cage window faces, both window pairs of one key summed) "
        "over all keys and frames"
    ),
    "seat_key_normal_peak_n": (
        "ours: maximum of keys.outer_normal (seat race, both flanks of one key summed) over all keys and frames"
    ),
    "seat_key_tangential_peak_n": (
        "ours: maximum of keys.outer_tangential (seat race friction magnitude) over all keys and frames"
    ),
}
SWEEP_DEFINITIONS: dict[str, str] = {
    "tube_mean_max": (
        "ours: largest summary.normal_mean over the linkNN/tube pairs of the {label} variant (whole run)"
    ),
    "key_peak": (
        "differs: ours is the maximum race normal force on one key, max of keys.inner_normal and "
        "keys.outer_normal over all keys and frames of the {label} variant; the paper does not say which race"
    ),
}
#: Why the paper's value is suspect (physics.md §6), for the keys the reference marks `suspect`.
SUSPECT_REASONS: dict[str, str] = {
    "tube_normal_mean_all_n": (
        "suspect (physics.md §6.1): an average of 7.1 kN exceeds every joint's peak (<= 5952.9 N) and is 8x the "
        "largest per-joint average (876.8 N); it can only be a sum over about 8-12 joints or a typo for 0.71 kN; "
        "compare as order of magnitude only"
    ),
    "tube_tangential_mean_all_n": (
        "suspect (physics.md §6.1): same reading question as the 7.1 kN normal average (sum over joints or "
        "typo); the ratio 1.4/7.1 = 0.20 is plausible against mu(450 mm/s) = 0.233; order of magnitude only"
    ),
    "sweep_R2500_key_peak_n": (
        "suspect (physics.md §6.3): 36.8 kN at R = 2.5 m exceeds the 33.5 kN baseline at R = 1.5 m, "
        "contradicting the paper's claim that the key peak falls as R grows; order of magnitude only"
    ),
    "sweep_rpm60_key_peak_n": (
        "suspect (physics.md §6.3): 36.7 kN at 60 rpm exceeds the 33.5 kN baseline at 100 rpm, "
        "contradicting the paper's claim that the key peak rises with speed; order of magnitude only"
    ),
}
SUSPECT_FALLBACK = (
    "suspect: the reference marks this value as contradicting other values of the same paper "
    "(physics.md §6); compare as order of magnitude only"
)
NOT_SWEPT = "not run: pass --sweeps"

_SWEEP_KEY = re.compile(r"^sweep_(?P<variant>[A-Za-z0-9]+)_(?P<what>tube_mean_max|key_peak)_n$")


# --------------------------------------------------------------------------- reference


def reference() -> dict[str, Any]:
    """The shipped reference numbers (``ballcage/data/paper-2023.toml``), parsed."""
    text = resources.files("ballcage").joinpath("data", REFERENCE_FILE).read_text(encoding="utf-8")
    return tomllib.loads(text)


def reference_keys() -> list[str]:
    """The ``[[quantity]]`` keys of the reference, in file order."""
    return [q["key"] for q in reference().get("quantity", [])]


# --------------------------------------------------------------------------- running


def run_paper(
    out_dir: str | os.PathLike[str],
    overrides: Iterable[str] = (),
    sweeps: bool = False,
    progress: bool | None = None,
) -> dict[str, Path]:
    """Runs the paper scene and writes tables, figures and the comparison into `out_dir`.

    `overrides` (``dotted.key=value``, on the drill-pipe TOML of
    `ballcage.default_scene_toml`) apply to the main run and to every sweep
    variant; a sweep's own key is applied last. `progress` is as for
    `ballcage.simulate`; unless it is ``False``, a line on stderr also names
    each sweep variant. Every scene is validated before anything runs.

    Returns the written paths: one per table (``"bodies"``, …), ``"scene"``,
    one per figure (``"fig09_included_angles"``, …), ``"comparison"``,
    ``"comparison_md"`` and, with `sweeps`, ``"sweep_<id>"`` (a directory with
    that variant's tables). Raises `ballcage.SceneError` for an invalid
    override and `ballcage.SimulationError` when a run diverges.
    """
    if isinstance(overrides, str):
        raise TypeError("overrides is a list of 'key=value' strings, not one string")
    user = list(overrides)
    out = Path(out_dir)
    main_scene = _paper_scene(user)
    variants = {vid: _paper_scene(user, sweep=vid) for vid in SWEEPS} if sweeps else {}

    run = simulate(main_scene, progress=progress)
    written = run.write(out)
    sweep_runs: dict[str, Run] = {}
    for n, (vid, scene) in enumerate(variants.items(), start=1):
        if progress is not False:
            print(f"ballcage: sweep {SWEEPS[vid][1]} ({n}/{len(variants)})", file=sys.stderr, flush=True)
        sweep_runs[vid] = simulate(scene, progress=progress)
        sweep_dir = out / "sweeps" / vid
        sweep_runs[vid].write(sweep_dir)
        written[f"sweep_{vid}"] = sweep_dir

    written.update(write_figures(run, out))
    table = comparison(run, sweep_runs if sweeps else None)
    comparison_path = out / "comparison.parquet"

    def write_parquet(tmp: Path) -> None:
        import pyarrow.parquet as pq

        pq.write_table(table, str(tmp), compression="zstd")

    _write_atomically(comparison_path, write_parquet)
    written["comparison"] = comparison_path
    command = _command_line(out, user, sweeps)
    md = comparison_markdown(table, command=command, run=run, sweep_runs=sweep_runs)
    md_path = out / "comparison.md"
    _write_atomically(md_path, lambda tmp: tmp.write_text(md, encoding="utf-8"))
    written["comparison_md"] = md_path
    return written


def _paper_scene(overrides: Sequence[str], sweep: str | None = None) -> _native.Scene:
    """The default scene recording `PAPER_TABLES` (or `SWEEP_TABLES`), user overrides, then the sweep key."""
    tables = SWEEP_TABLES if sweep else PAPER_TABLES
    record = "record.tables=[" + ", ".join(f'"{t}"' for t in tables) + "]"
    patches = [record, *overrides]
    if sweep is not None:
        patches.append(SWEEPS[sweep][0])
    scene = default_scene(patches)
    missing = [t for t in tables if t not in scene.table_names]
    if missing:
        reason = f"must include {', '.join(missing)} for the paper's figures and comparison"
        error = _native.SceneError(f"scene field `record.tables` = {scene.table_names}: {reason}")
        error.path, error.value, error.reason = "record.tables", str(scene.table_names), reason
        raise error
    return scene


def _command_line(out: Path, overrides: Sequence[str], sweeps: bool) -> str:
    args = ["ballcage", "paper", "--out", str(out)]
    for o in overrides:
        args += ["--set", o]
    if sweeps:
        args.append("--sweeps")
    return shlex.join(args)


# --------------------------------------------------------------------------- scene facts


@dataclass(frozen=True)
class _SceneFacts:
    """What the analysis needs from a run's drill-pipe scene."""

    duration: float
    output_interval: float
    rpm: float
    curvature_radius: float
    build_angle_deg: float
    tube_inner_radius: float
    link_radius: float
    tube_start: np.ndarray
    tube_direction: np.ndarray
    tube_bend: np.ndarray

    @property
    def clearance(self) -> float:
        """Radial play of a link's centre in the tube [m]."""
        return self.tube_inner_radius - self.link_radius

    def phase_times(self) -> list[tuple[str, float]]:
        """Table 3's phases: 0°, 90°, 180°, 270° of the last revolution, ending at the duration."""
        quarter = 15.0 / self.rpm if self.rpm > 0 else math.inf
        return [(label, self.duration - (3 - i) * quarter) for i, label in enumerate(PHASES)]


def _scene_facts(run: Run) -> _SceneFacts:
    """Reads the run's drill-pipe scene (the short form `Scene.to_toml` writes)."""
    scene = tomllib.loads(run.scene_toml)
    if scene.get("kind") != "drill-pipe":
        raise ValueError("the paper analysis needs a drill-pipe scene (kind = \"drill-pipe\")")
    sim = scene["simulation"]
    borehole = scene["borehole"]
    return _SceneFacts(
        duration=float(sim["duration"]),
        output_interval=float(sim["output_interval"]),
        rpm=float(scene["drive"]["speed_rpm"]),
        curvature_radius=float(borehole["curvature_radius"]),
        build_angle_deg=float(borehole["build_angle_deg"]),
        tube_inner_radius=float(borehole["inner_diameter"]) / 2.0,
        link_radius=float(scene["pipe"]["link_diameter"]) / 2.0,
        # The drill-pipe scene's fixed frame: the tube starts at the origin going down (-z)
        # and bends toward +x (crates/ballcage-core/src/drillpipe).
        tube_start=np.zeros(3),
        tube_direction=np.array([0.0, 0.0, -1.0]),
        tube_bend=np.array([1.0, 0.0, 0.0]),
    )


def _unit(v: np.ndarray) -> np.ndarray:
    n = float(np.linalg.norm(v))
    return v / n if n > 0 else v


def _centreline_offsets(facts: _SceneFacts, com: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """In-plane (+ toward the outer wall of the bend) and lateral offsets [m] of points `com` (…, 3).

    The centreline is the straight entry along the tube direction, the arc,
    and the straight extension past the arc's end (as for links.radial_offset).
    """
    d = facts.tube_direction
    b = _unit(facts.tube_bend - facts.tube_bend.dot(d) * d)
    n = np.cross(b, d)
    r = facts.curvature_radius
    angle = math.radians(facts.build_angle_deg)
    centre = facts.tube_start + r * b
    u = com - centre
    theta = np.arctan2(u @ d, u @ -b)
    inplane = np.stack([u @ -b, u @ d], axis=-1)
    on_arc_radial = np.linalg.norm(inplane, axis=-1) - r
    lateral = u @ n
    # Before the arc: the straight entry; the outward normal there is -b.
    before = (com - facts.tube_start) @ -b
    # Past the arc: the straight exit; outward normal -b cos A + d sin A.
    end = centre + r * (-b * math.cos(angle) + d * math.sin(angle))
    after = (com - end) @ (-b * math.cos(angle) + d * math.sin(angle))
    radial = np.where(theta < 0.0, before, np.where(theta > angle, after, on_arc_radial))
    return radial, lateral


# --------------------------------------------------------------------------- table access


def _frame_times(run: Run) -> np.ndarray:
    for name in ("links", "drive", "hinges", "keys", "bodies"):
        table = run.tables.get(name)
        if table is not None and table.num_rows:
            return np.unique(table.column("t").to_numpy())
    return np.zeros(0)


def _frame_index(times: np.ndarray, t: np.ndarray) -> np.ndarray:
    idx = np.searchsorted(times, t)
    return np.clip(idx, 0, max(len(times) - 1, 0))


def _grid(table: pa.Table, times: np.ndarray, row_cols: Sequence[str], value_cols: Sequence[str]) -> dict[str, np.ndarray]:
    """Per-frame arrays ``[frame, *row ids]`` of `value_cols` (NaN where a row is missing)."""
    fi = _frame_index(times, table.column("t").to_numpy())
    ids = [table.column(c).to_numpy().astype(np.int64) for c in row_cols]
    shape = (len(times), *[(int(i.max()) + 1 if len(i) else 0) for i in ids])
    out = {}
    for col in value_cols:
        arr = np.full(shape, np.nan)
        arr[(fi, *ids)] = table.column(col).to_numpy()
        out[col] = arr
    return out


def _pair_forces(run: Run, names: Sequence[str], times: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per-frame total normal force and |summed tangential vector| of each named pair (0 without contact)."""
    out: dict[str, tuple[np.ndarray, np.ndarray]] = {
        name: (np.zeros(len(times)), np.zeros(len(times))) for name in names
    }
    contacts = run.tables.get("contacts")
    if contacts is None or contacts.num_rows == 0:
        return out
    pair = contacts.column("pair").combine_chunks()
    if isinstance(pair, pa.DictionaryArray):
        dictionary = pair.dictionary.to_pylist()
        codes = pair.indices.to_numpy(zero_copy_only=False)
    else:  # a plain string column
        dictionary, codes = np.unique(np.asarray(pair.to_pylist(), dtype=object), return_inverse=True)
        dictionary = list(dictionary)
    fi = _frame_index(times, contacts.column("t").to_numpy())
    normal = contacts.column("normal_force").to_numpy()
    tangential = np.stack([contacts.column(f"tangential_force_{a}").to_numpy() for a in "xyz"], axis=-1)
    for name in names:
        if name not in dictionary:
            continue
        mask = codes == dictionary.index(name)
        n = np.bincount(fi[mask], weights=normal[mask], minlength=len(times))
        t = np.stack(
            [np.bincount(fi[mask], weights=tangential[mask, a], minlength=len(times)) for a in range(3)], axis=-1
        )
        out[name] = (n, np.linalg.norm(t, axis=-1))
    return out


def _summary_rows(run: Run) -> dict[str, dict[str, float]]:
    summary = run.tables.get("summary")
    if summary is None:
        return {}
    pairs = summary.column("pair").cast(pa.string()).to_pylist()
    cols = {c: summary.column(c).to_numpy() for c in summary.column_names if c not in ("pair", "pair_id")}
    return {p: {c: float(v[i]) for c, v in cols.items()} for i, p in enumerate(pairs)}


def _tube_pairs(summary: Mapping[str, Mapping[str, float]]) -> dict[int, Mapping[str, float]]:
    out = {}
    for name, row in summary.items():
        m = re.fullmatch(r"link(\d+)/tube", name)
        if m:
            out[int(m.group(1))] = row
    return dict(sorted(out.items()))


@dataclass(frozen=True)
class _Phase:
    label: str
    t: float
    frame: int
    most_deformed: int  # link number
    included_angle: float  # deg
    offset_mm: float


def _phases(run: Run, facts: _SceneFacts) -> tuple[list[_Phase], list[str]]:
    """Table 3's phases present in the run, and the labels of those outside it."""
    links = run.tables.get("links")
    times = _frame_times(run)
    if links is None or links.num_rows == 0 or len(times) == 0:
        return [], list(PHASES)
    grid = _grid(links, times, ["link"], ["radial_offset", "included_angle_deg"])
    tol = max(facts.output_interval, 1e-9) * 0.5 + 1e-9
    found, skipped = [], []
    for label, t in facts.phase_times():
        if not math.isfinite(t) or t < times[0] - tol:
            skipped.append(label)
            continue
        f = int(np.argmin(np.abs(times - t)))
        if abs(times[f] - t) > tol:
            skipped.append(label)
            continue
        offsets = grid["radial_offset"][f, 1:]
        k = int(np.nanargmax(offsets)) + 1
        found.append(
            _Phase(label, float(times[f]), f, k, float(grid["included_angle_deg"][f, k]), 1e3 * float(offsets[k - 1]))
        )
    return found, skipped


# --------------------------------------------------------------------------- comparison


@dataclass
class _Value:
    ours: float | None
    note: str = ""


def comparison(run: Run, sweep_runs: Mapping[str, Run] | None = None) -> pa.Table:
    """The comparison with the paper: one row per ``[[quantity]]`` of the reference file.

    Columns ``key, paper, ours, unit, ratio, note`` (`COMPARISON_SCHEMA`);
    ``ours`` and ``ratio`` are null where a value is not computed. `run` is a
    run of the paper scene that recorded `PAPER_TABLES`; `sweep_runs` maps the
    `SWEEPS` ids (``"R1000"``, …) to runs of the variants.
    """
    facts = _scene_facts(run)
    values = _baseline_values(run, facts)
    rows: dict[str, list[Any]] = {f.name: [] for f in COMPARISON_SCHEMA}
    for q in reference().get("quantity", []):
        key = q["key"]
        paper = float(q["value"])
        m = _SWEEP_KEY.match(key)
        if key in values:
            value = values[key]
        elif m:
            variant = m.group("variant")
            if sweep_runs is None or variant not in sweep_runs:
                value = _Value(None, NOT_SWEPT if variant in SWEEPS else f"not run: no sweep variant {variant!r}")
            else:
                value = _sweep_value(sweep_runs[variant], variant, m.group("what"))
        else:
            value = _Value(None, "not computed: no definition of this quantity yet")
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
        rows["key"].append(key)
        rows["paper"].append(paper)
        rows["ours"].append(ours)
        rows["unit"].append(str(q.get("unit", "")))
        rows["ratio"].append(ratio)
        rows["note"].append("; ".join(notes))
    meta = {
        "ballcage.reference": REFERENCE_FILE,
        "ballcage.run_duration_s": repr(facts.duration),
        "ballcage.version": _native.__version__,
    }
    return pa.Table.from_pydict(rows, schema=COMPARISON_SCHEMA.with_metadata(meta))


def _fmt(x: float, digits: int = 4) -> str:
    return f"{x:.{digits}g}"


def _baseline_values(run: Run, facts: _SceneFacts) -> dict[str, _Value]:
    values: dict[str, _Value] = {}
    values.update(_phase_values(run, facts))
    values.update(_tube_values(run))
    values.update(_internal_values(run))
    return values


def _phase_values(run: Run, facts: _SceneFacts) -> dict[str, _Value]:
    keys = ("included_angle_min_deg", "included_angle_max_deg", "range_of_motion_mm", "most_deformed_joint")
    if "links" not in run.tables:
        return {k: _Value(None, "not computed: the run did not record the links table") for k in keys}
    phases, skipped = _phases(run, facts)
    if not phases:
        return {k: _Value(None, "not computed: none of the four phases lies in the run") for k in keys}
    listing = ", ".join(
        f"{p.label} t={p.t:.3f} s: link {p.most_deformed}, {p.included_angle:.2f} deg, {p.offset_mm:.2f} mm"
        for p in phases
    )
    where = f"phases ({listing})"
    if skipped:
        where += f"; {len(phases)} of 4 phases in the run ({', '.join(skipped)} fall before t = 0)"
    angles = [p.included_angle for p in phases]
    return {
        "included_angle_min_deg": _Value(min(angles), f"{DEFINITIONS['included_angle_min_deg']}; {where}"),
        "included_angle_max_deg": _Value(max(angles), f"{DEFINITIONS['included_angle_max_deg']}; {where}"),
        "range_of_motion_mm": _Value(max(p.offset_mm for p in phases), f"{DEFINITIONS['range_of_motion_mm']}; {where}"),
        "most_deformed_joint": _Value(
            float(round(sum(p.most_deformed for p in phases) / len(phases))),
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
    tube = _tube_pairs(_summary_rows(run))
    if not tube:
        return {k: _Value(None, "not computed: the run did not record the summary table") for k in keys}
    window = next(iter(tube.values()))
    span = f"summary window {window['window_start']:.3g}-{window['window_end']:.3g} s, {int(window['frames'])} frames"
    in_plot = {k: tube[k] for k in TUBE_LINKS if k in tube}
    peak_link = max(in_plot, key=lambda k: in_plot[k]["normal_peak"]) if in_plot else None
    mean_link = max(tube, key=lambda k: tube[k]["normal_mean"])

    def row(link: int, column: str, key: str, extra: str = "") -> _Value:
        if link not in tube:
            return _Value(None, f"not computed: no pair link{link:02d}/tube")
        return _Value(tube[link][column], f"{DEFINITIONS[key]} ({span}){extra}")

    peak_extra = (
        f"; largest peak of links {', '.join(map(str, TUBE_LINKS))}: link {peak_link} "
        f"({_fmt(in_plot[peak_link]['normal_peak'])} N)"
        if peak_link is not None
        else ""
    )
    mean_extra = f"; largest per-link mean: link {mean_link} ({_fmt(tube[mean_link]['normal_mean'])} N)"
    out = {
        "tube_normal_peak_joint10_n": row(10, "normal_peak", "tube_normal_peak_joint10_n", peak_extra),
        "tube_normal_mean_joint10_n": row(10, "normal_mean", "tube_normal_mean_joint10_n", mean_extra),
        "tube_normal_mean_joint12_n": row(12, "normal_mean", "tube_normal_mean_joint12_n"),
    }
    for kind in ("normal", "tangential"):
        key = f"tube_{kind}_mean_all_n"
        total = sum(r[f"{kind}_mean"] for r in tube.values())
        per_link = total / len(tube)
        out[key] = _Value(
            total,
            f"{DEFINITIONS[key]} ({span}); reading 2, the mean over the {len(tube)} links, is {_fmt(per_link)} N",
        )
    return out


def _argmax_where(grid: np.ndarray, times: np.ndarray) -> tuple[float, tuple[int, ...], float]:
    """Largest finite value of a per-frame grid, its (row ids) and its time."""
    if grid.size == 0 or not np.isfinite(grid).any():
        return math.nan, (), math.nan
    flat = int(np.nanargmax(grid))
    idx = np.unravel_index(flat, grid.shape)
    return float(grid[idx]), tuple(int(i) for i in idx[1:]), float(times[idx[0]])


def _internal_values(run: Run) -> dict[str, _Value]:
    out: dict[str, _Value] = {}
    times = _frame_times(run)
    hinges = run.tables.get("hinges")
    if hinges is None:
        out["seat_cage_normal_peak_n"] = _Value(None, "not computed: the run did not record the hinges table")
    else:
        grid = _grid(hinges, times, ["hinge"], ["cage_seat_normal"])["cage_seat_normal"]
        v, ids, t = _argmax_where(grid, times)
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
    grids = _grid(keys, times, ["hinge", "key"], list(specs.values()))
    for key, column in specs.items():
        v, ids, t = _argmax_where(grids[column], times)
        where = f"; at hinge {ids[0]:02d} key {ids[1]}, t = {t:.4g} s" if ids else ""
        out[key] = _Value(v, f"{DEFINITIONS[key]}{where}")
    return out


def _sweep_value(run: Run, variant: str, what: str) -> _Value:
    label = SWEEPS.get(variant, (variant, variant))[1]
    definition = SWEEP_DEFINITIONS[what].format(label=label)
    if what == "tube_mean_max":
        tube = _tube_pairs(_summary_rows(run))
        if not tube:
            return _Value(None, "not computed: the sweep run did not record the summary table")
        link = max(tube, key=lambda k: tube[k]["normal_mean"])
        incl = ""
        links = run.tables.get("links")
        if links is not None and links.num_rows:
            mask = links.column("link").to_numpy() == link
            incl = f", mean inclination {float(np.mean(links.column('inclination_deg').to_numpy()[mask])):.1f} deg"
        return _Value(tube[link]["normal_mean"], f"{definition}; at link {link}{incl}")
    keys = run.tables.get("keys")
    if keys is None:
        return _Value(None, "not computed: the sweep run did not record the keys table")
    times = _frame_times(run)
    grids = _grid(keys, times, ["hinge", "key"], ["inner_normal", "outer_normal"])
    best: tuple[float, tuple[int, ...], float, str] = (math.nan, (), math.nan, "")
    for column, race in (("inner_normal", "head race"), ("outer_normal", "seat race")):
        v, ids, t = _argmax_where(grids[column], times)
        if math.isfinite(v) and not (v <= best[0]):
            best = (v, ids, t, race)
    v, ids, t, race = best
    where = f"; at hinge {ids[0]:02d} key {ids[1]} ({race}), t = {t:.4g} s" if ids else ""
    return _Value(v, f"{definition}{where}")


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
        facts = _scene_facts(run)
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
            "ratio = ours / paper. The note says how our definition is computed, where it differs from the "
            "paper's, and when the paper's own value is suspect (it contradicts other numbers of the paper, "
            "see physics.md §6): compare those as order of magnitude only. Empty cells were not computed. "
            + (f"Sweep variants run: {swept}." if swept else "Sweep rows need `--sweeps`.")
        ),
        "",
        "| key | paper | ours | unit | ratio | note |",
        "| --- | ---: | ---: | --- | ---: | --- |",
    ]
    for r in table.to_pylist():
        ours = "" if r["ours"] is None else _fmt(r["ours"])
        ratio = "" if r["ratio"] is None else f"{r['ratio']:.3f}"
        note = str(r["note"]).replace("|", "\\|")
        lines.append(f"| {r['key']} | {_fmt(r['paper'])} | {ours} | {r['unit']} | {ratio} | {note} |")
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- figures


def write_figures(run: Run, out_dir: str | os.PathLike[str]) -> dict[str, Path]:
    """Writes the paper's figures (`FIGURES`) as PNG into `out_dir`; returns their paths by name."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    facts = _scene_facts(run)
    times = _frame_times(run)
    makers: dict[str, Callable[[], Figure]] = {
        "fig09_included_angles": lambda: _fig_included_angles(run, facts, times),
        "fig10_tube_normal": lambda: _fig_tube(run, times, normal=True),
        "fig11_tube_tangential": lambda: _fig_tube(run, times, normal=False),
        "fig12_key_normal": lambda: _fig_keys(run, times, normal=True),
        "fig13_key_tangential": lambda: _fig_keys(run, times, normal=False),
        "table3_shape": lambda: _fig_shape(run, facts, times),
    }
    written = {}
    for name in FIGURES:
        fig = makers[name]()
        path = out / f"{name}.png"

        def save(tmp: Path, fig: Figure = fig) -> None:
            fig.savefig(tmp, format="png", dpi=120)

        _write_atomically(path, save)
        written[name] = path
    return written


def _figure(**kwargs: Any) -> Figure:
    # No pyplot: a bare Figure renders with Agg and leaves the global backend alone.
    from matplotlib.figure import Figure

    return Figure(layout="constrained", **kwargs)


def _no_data(ax: Axes, text: str) -> None:
    ax.text(0.5, 0.5, text, ha="center", va="center", transform=ax.transAxes)


def _fig_included_angles(run: Run, facts: _SceneFacts, times: np.ndarray) -> Figure:
    fig = _figure(figsize=(11, 4.5))
    by_link, over_time = fig.subplots(1, 2)
    links = run.tables.get("links")
    phases, skipped = _phases(run, facts)
    if links is not None and links.num_rows:
        grid = _grid(links, times, ["link"], ["included_angle_deg"])["included_angle_deg"][:, 1:]
        numbers = np.arange(1, grid.shape[1] + 1)
        for p in phases:
            by_link.plot(numbers, grid[p.frame], marker="o", label=f"{p.label} (t = {p.t:.3f} s)")
        by_link.set_xticks(numbers)
        cmap = _colormap("viridis")
        for k in range(grid.shape[1]):
            over_time.plot(times, grid[:, k], color=cmap(k / max(grid.shape[1] - 1, 1)), lw=1, label=f"link {k + 1}")
        over_time.legend(fontsize=7, ncol=2, loc="best")
    else:
        _no_data(over_time, "no links table")
    if phases:
        by_link.legend(fontsize=8, title="phase of the upper connector", title_fontsize=8)
    if skipped:
        by_link.text(
            0.01, 0.01, f"phases before t = 0 not shown: {', '.join(skipped)}", transform=by_link.transAxes, fontsize=7
        )
    by_link.set(
        xlabel="link number k [-]",
        ylabel="included angle, link k / body k+1 [deg]",
        title="At the four phases of the last revolution",
    )
    over_time.set(xlabel="time [s]", ylabel="included angle, link k / body k+1 [deg]", title="Over time")
    fig.suptitle("Fig. 9: angle between adjacent links (180 deg = straight)")
    return fig


def _colormap(name: str) -> Any:
    import matplotlib

    return matplotlib.colormaps[name]


def _fig_tube(run: Run, times: np.ndarray, *, normal: bool) -> Figure:
    fig = _figure(figsize=(9, 4.8))
    ax = fig.subplots()
    names = [f"link{k:02d}/tube" for k in TUBE_LINKS]
    forces = _pair_forces(run, names, times)
    for k, name in zip(TUBE_LINKS, names, strict=True):
        n, t = forces[name]
        ax.plot(times, n if normal else t, lw=1, label=f"link {k}")
    if "contacts" not in run.tables:
        _no_data(ax, "no contacts table")
    kind = "normal" if normal else "tangential"
    ax.set(xlabel="time [s]", ylabel=f"{kind} contact force link-tube [N]")
    ax.legend(title="pair linkNN/tube", fontsize=8)
    detail = "sum over the pair's contact points" if normal else "magnitude of the summed friction vector"
    number = 10 if normal else 11
    ax.set_title(f"Fig. {number}: {kind} force between links 2, 4, 6, 8, 10 and the guide tube\n(per frame: {detail})")
    return fig


def _key_races(joints: int) -> dict[str | int, list[tuple[int, str]]]:
    """For each plotted body, its races as (hinge, keys column prefix): head = inner race, seat = outer race."""
    races: dict[str | int, list[tuple[int, str]]] = {}
    for body in KEY_BODIES:
        if body == "upper":
            races[body] = [(0, "inner")]
        elif body == "lower":
            races[body] = [(joints, "outer")]
        else:
            assert isinstance(body, int)
            races[body] = [(body - 1, "outer"), (body, "inner")]
    return races


def _race_label(body: str | int, races: list[tuple[int, str]]) -> str:
    name = f"link {body}" if isinstance(body, int) else f"{body} connector"
    parts = [f"h{h:02d} {'seat (outer)' if side == 'outer' else 'head (inner)'} race" for h, side in races]
    return f"{name}: {parts[0]}" if len(parts) == 1 else f"{name}: max of {' and '.join(parts)}"


def _fig_keys(run: Run, times: np.ndarray, *, normal: bool) -> Figure:
    fig = _figure(figsize=(10, 5.2))
    ax = fig.subplots()
    keys = run.tables.get("keys")
    kind = "normal" if normal else "tangential"
    if keys is not None and keys.num_rows:
        cols = [f"{side}_{kind}" for side in ("inner", "outer")]
        grids = _grid(keys, times, ["hinge", "key"], cols)
        joints = grids[cols[0]].shape[1] - 1
        for body, races in _key_races(joints).items():
            series = [grids[f"{side}_{kind}"][:, h, :] for h, side in races if 0 <= h <= joints]
            if not series:
                continue
            largest = np.nanmax(np.concatenate(series, axis=1), axis=1)
            ax.plot(times, largest, lw=1, label=_race_label(body, races))
        ax.legend(fontsize=7, loc="best")
    else:
        _no_data(ax, "no keys table")
    ax.set(xlabel="time [s]", ylabel=f"largest ball-key {kind} force [N]")
    number = 12 if normal else 13
    column = "inner/outer_" + kind
    ax.set_title(
        f"Fig. {number}: ball-key {kind} force on the races of the connectors and links 1, 3, 6, 9, 12\n"
        f"per frame, the largest keys.{column} of the 6 keys over the body's races "
        "(link k: seat race of hinge k-1, head race of hinge k)",
        fontsize=9,
    )
    return fig


def _fig_shape(run: Run, facts: _SceneFacts, times: np.ndarray) -> Figure:
    fig = _figure(figsize=(12, 7.5))
    grid_spec = fig.add_gridspec(2, 4, height_ratios=[1.1, 1])
    sections = [fig.add_subplot(grid_spec[0, i]) for i in range(4)]
    profile = fig.add_subplot(grid_spec[1, :])
    links = run.tables.get("links")
    phases, _ = _phases(run, facts)
    by_label = {p.label: p for p in phases}
    clearance_mm = 1e3 * facts.clearance
    circle = np.linspace(0.0, 2.0 * math.pi, 181)
    if links is not None and links.num_rows:
        g = _grid(links, times, ["link"], ["com_x", "com_y", "com_z", "radial_offset"])
        com = np.stack([g["com_x"], g["com_y"], g["com_z"]], axis=-1)[:, 1:]
        offsets = g["radial_offset"][:, 1:]
        numbers = np.arange(1, offsets.shape[1] + 1)
        for ax, (label, t) in zip(sections, facts.phase_times(), strict=True):
            ax.plot(clearance_mm * np.cos(circle), clearance_mm * np.sin(circle), "k--", lw=0.8)
            ax.set_aspect("equal")
            ax.set(
                xlabel="in-plane offset [mm]\n(+ toward the outer wall)",
                ylabel="lateral offset [mm]",
                xlim=(-1.15 * clearance_mm, 1.15 * clearance_mm),
                ylim=(-1.15 * clearance_mm, 1.15 * clearance_mm),
            )
            p = by_label.get(label)
            if p is None:
                ax.set_title(f"{label}: t = {t:.3f} s not in run", fontsize=9)
                continue
            radial, lateral = _centreline_offsets(facts, com[p.frame])
            sc = ax.scatter(1e3 * radial, 1e3 * lateral, c=numbers, cmap="viridis", s=22, zorder=3)
            for k, x, y in zip(numbers, radial, lateral, strict=True):
                ax.annotate(str(k), (1e3 * x, 1e3 * y), fontsize=6, xytext=(2, 2), textcoords="offset points")
            ax.set_title(f"{label}: t = {p.t:.3f} s, max link {p.most_deformed}", fontsize=9)
            profile.plot(numbers, 1e3 * offsets[p.frame], marker="o", label=f"{label} (t = {p.t:.3f} s)")
        if phases:
            fig.colorbar(sc, ax=sections, label="link number [-]", shrink=0.8)
    else:
        _no_data(profile, "no links table")
    profile.axhline(clearance_mm, color="k", ls="--", lw=0.8, label=f"clearance {clearance_mm:.0f} mm")
    profile.set(
        xlabel="link number k [-]",
        ylabel="centre offset from tube centreline [mm]",
        title="Radial offset of each link's centre of mass (links.radial_offset)",
    )
    if links is not None and links.num_rows:
        profile.set_xticks(numbers)
    profile.legend(fontsize=8)
    fig.suptitle(
        "Table 3: chain shape at the phases 0/90/180/270 deg of the upper connector's last revolution "
        f"({facts.rpm:g} rpm; dashed circle: tube clearance {clearance_mm:.0f} mm)",
        fontsize=10,
    )
    return fig
