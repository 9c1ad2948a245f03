"""Fatigue life at the links' critical sections: nominal stress, rainflow cycles, Basquin–Goodman, Miner.

From the section loads of `ballcage.measures.sections` (a free-body cut of
the rigid link) over the run's steady window (`steady_window`), per link and
section (docs/model.md §8.6):

- **stress**: at each of `FIBRES` points around the section's outer edge, the
  nominal normal stress σ = N/A + (M_y·z − M_z·y)/I (axial plus bending: a
  fibre of the turning link meets the bend's moment once per revolution), and
  the torsional shear τ = T·r_o/J;
- **cycles**: σ(t) at each fibre counted by ASTM E1049 rainflow (the
  ``rainflow`` package), each cycle a range and a mean, half cycles as 0.5;
- **damage**: each cycle's amplitude times the section's K_t, σ_a = K_t·Δσ/2,
  with the nominal equivalent mean σ′_m = √(σ_m² + 3·τ_m²) (von Mises of the
  means, τ_m the torque's mean shear over the window: the steady torque
  raises the mean, not the amplitude; K_t on the amplitude only, because the
  ductile steel yields at the notch root in the first cycles and the mean
  relaxes toward the nominal), made fully reversed by Goodman,
  σ_ar = σ_a/(1 − σ′_m/σ_u),
  and its life N_f = ½·(σ_ar/σ′_f)^(1/b) by Basquin; Miner's sum
  D = Σ n/N_f over the window, per revolution and per hour at the run's
  speed, and hours to failure 1/D_hour. The fibre with the largest D is the
  section's.

Why not a signed von Mises of σ and τ at each instant: with the torque's
steady shear it swings between ±√(σ² + 3τ²) whenever σ changes sign, so a
steady torque alone would count a full reversal every revolution.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
import pyarrow as pa
import rainflow
from numpy.typing import ArrayLike

from ballcage._links import summary_window
from ballcage._native import InputError
from ballcage.measures.sections import Section, SectionLoads, link_sections, section_loads
from ballcage.run import Run

__all__ = [
    "FATIGUE_COLUMNS",
    "FIBRES",
    "SnCurve",
    "count_cycles",
    "fatigue_line",
    "fatigue_table",
    "miner_sum",
    "section_stresses",
    "steady_window",
]

#: Points around a section's outer edge where the normal stress is followed (every 15°).
FIBRES = 24


@dataclass(frozen=True)
class SnCurve:
    """Basquin's S–N curve with Goodman's mean-stress correction [Pa, –]."""

    ultimate: float  # σ_u [Pa]
    coefficient: float  # σ′_f [Pa]
    exponent: float  # b [–], negative

    @classmethod
    def of(cls, run: Run) -> SnCurve:
        """The curve of the run's scene (``fatigue.ultimate_strength``, ``…strength_coefficient``, ``…exponent``)."""
        v = run.scene.value
        return cls(
            float(v("fatigue.ultimate_strength")), float(v("fatigue.strength_coefficient")),
            float(v("fatigue.strength_exponent")),
        )  # fmt: skip

    def reversed_amplitude(self, amplitude: ArrayLike, mean: ArrayLike) -> np.ndarray:
        """Goodman: the fully reversed amplitude σ_a/(1 − σ_m/σ_u) [Pa]; σ_a for a compressive mean, inf at σ_m ≥ σ_u."""
        amplitude, mean = np.asarray(amplitude, float), np.asarray(mean, float)
        ratio = np.clip(mean, 0.0, None) / self.ultimate
        with np.errstate(divide="ignore", over="ignore"):
            return np.where(ratio < 1.0, amplitude / np.maximum(1.0 - ratio, 1e-300), np.inf)

    def cycles_to_failure(self, reversed_amplitude: ArrayLike) -> np.ndarray:
        """Basquin: N_f = ½·(σ_ar/σ′_f)^(1/b) cycles; half a cycle (one reversal) at an infinite amplitude."""
        s = np.asarray(reversed_amplitude, float)
        with np.errstate(divide="ignore", over="ignore"):
            n = 0.5 * (s / self.coefficient) ** (1.0 / self.exponent)
        return np.where(np.isfinite(s), n, 0.5)


def count_cycles(series: Iterable[float]) -> np.ndarray:
    """ASTM E1049 rainflow cycles of `series` by the ``rainflow`` package: rows (range, mean, count 0.5 or 1)."""
    rows = [(rng, mean, count) for rng, mean, count, _, _ in rainflow.extract_cycles(list(series))]
    return np.array(rows, dtype=float).reshape(-1, 3)


def miner_sum(cycles: np.ndarray, curve: SnCurve, shear_mean: float = 0.0, scf: float = 1.0) -> float:
    """Miner's sum Σ n/N_f of nominal rainflow `cycles` (range, mean, count) [Pa] with a steady shear `shear_mean`
    [Pa]: amplitude `scf`·range/2, equivalent mean √(mean² + 3·shear_mean²)."""
    if len(cycles) == 0:
        return 0.0
    amplitude = scf * cycles[:, 0] / 2.0
    mean = np.sqrt(cycles[:, 1] ** 2 + 3.0 * shear_mean**2)
    return float(np.sum(cycles[:, 2] / curve.cycles_to_failure(curve.reversed_amplitude(amplitude, mean))))


def section_stresses(loads: SectionLoads, section: Section) -> tuple[np.ndarray, np.ndarray]:
    """Nominal normal stress at each fibre [frame, link, fibre] and torsional shear [frame, link] [Pa].

    Fibre j lies at angle 2πj/`FIBRES` from the link's body y axis toward its z axis on the outer edge.
    """
    f, m = loads.force[section.name], loads.moment[section.name]
    r = section.outer_diameter / 2.0
    phi = 2.0 * np.pi * np.arange(FIBRES) / FIBRES
    y, z = r * np.cos(phi), r * np.sin(phi)
    sigma = f[..., 0:1] / section.area + (m[..., 1:2] * z - m[..., 2:3] * y) / section.second_moment
    tau = m[..., 0] * r / (2.0 * section.second_moment)
    return sigma, tau


def steady_window(run: Run) -> tuple[float, float]:
    """The window the damage is counted over [s]: ``record.summary_window`` if set, else from the end of the
    drive's and the load's ramps to the run's end (the start-up is not the duty)."""
    start, end = summary_window(run.scene)
    if math.isfinite(end):
        return start, end
    v = run.scene.value
    return max(float(v("drive.ramp")), float(v("load.ramp"))), float(run.scene.duration)


#: The columns of ``fatigue.parquet``: name, Arrow type, unit, meaning.
FATIGUE_COLUMNS: tuple[tuple[str, pa.DataType, str, str], ...] = (
    ("section", pa.string(), "", "neck, body or seat (docs/model.md §8.6; fatigue.* of the scene)"),
    ("link", pa.uint32(), "", "link number, 1 at the top"),
    ("hinge", pa.uint32(), "", "the hinge whose joint loads cross the section (neck: the link's own; seat: the one above; body: null)"),
    ("fibre_deg", pa.float64(), "deg", "the most damaged point of the section's outer edge, from the link's body y axis toward z"),
    ("stress_amplitude", pa.float64(), "Pa", "amplitude σ_a of that fibre's largest rainflow cycle, nominal × K_t"),
    ("stress_mean", pa.float64(), "Pa", "that cycle's nominal equivalent mean σ′_m = √(σ_m² + 3·τ_m²)"),
    ("reversed_amplitude", pa.float64(), "Pa", "that cycle made fully reversed by Goodman, σ_a/(1 − σ′_m/σ_u)"),
    ("shear_mean", pa.float64(), "Pa", "nominal torsional shear τ_m at the edge, mean over the window"),
    ("shear_amplitude", pa.float64(), "Pa", "half the largest rainflow range of that shear × K_t: left out of the damage, given to judge that"),
    ("cycles", pa.float64(), "", "rainflow cycles of that fibre in the window (half cycles count 0.5)"),
    ("damage_per_revolution", pa.float64(), "", "Miner's sum per revolution of the drive; null when it does not turn"),
    ("damage_per_hour", pa.float64(), "1/h", "Miner's sum per hour of this duty"),
    ("hours_to_failure", pa.float64(), "h", "1/damage_per_hour: hours of this duty to a Miner's sum of 1; null without damage"),
    ("window_start", pa.float64(), "s", "start of the window the cycles are counted over (steady_window)"),
    ("window_end", pa.float64(), "s", "end of that window"),
)  # fmt: skip


def _schema() -> pa.Schema:
    return pa.schema([
        pa.field(name, kind, metadata={"unit": unit, "description": meaning})
        for name, kind, unit, meaning in FATIGUE_COLUMNS
    ])  # fmt: skip


def _fibre_row(sigma: np.ndarray, tau: np.ndarray, curve: SnCurve, scf: float) -> dict[str, float]:
    """The most damaged fibre of one link's section: nominal `sigma` [frame, fibre], `tau` [frame] [Pa]."""
    shear_mean = float(np.mean(tau)) if len(tau) else 0.0
    best: dict[str, float] = {}
    for j in range(sigma.shape[1]):
        cycles = count_cycles(sigma[:, j])
        damage = miner_sum(cycles, curve, shear_mean, scf)
        if best and damage <= best["damage"]:
            continue
        big = cycles[int(np.argmax(cycles[:, 0]))] if len(cycles) else np.zeros(3)
        amplitude, mean = scf * big[0] / 2.0, math.sqrt(big[1] ** 2 + 3.0 * shear_mean**2)
        best = {
            "damage": damage, "fibre_deg": 360.0 * j / FIBRES, "stress_amplitude": amplitude, "stress_mean": mean,
            "reversed_amplitude": float(curve.reversed_amplitude(amplitude, mean)),
            "cycles": float(np.sum(cycles[:, 2])),
        }  # fmt: skip
    shear = count_cycles(tau)
    best["shear_mean"] = shear_mean
    best["shear_amplitude"] = float(scf * np.max(shear[:, 0]) / 2.0) if len(shear) else 0.0
    return best


def fatigue_table(run: Run, sections: list[Section] | None = None, loads: SectionLoads | None = None) -> pa.Table:
    """``fatigue.parquet``: one row per link and section (`link_sections`), its damage over the steady window.

    `loads` are the run's `section_loads` at `sections` when already computed. Raises `ballcage.InputError` when
    the run cannot give section loads (`section_loads`) or its steady window holds fewer than two frames.
    """
    secs = link_sections(run) if sections is None else sections
    loads = section_loads(run, secs) if loads is None else loads
    start, end = steady_window(run)
    inside = (loads.times >= start - 1e-9) & (loads.times <= end + 1e-9)
    if inside.sum() < 2:
        raise InputError(
            f"the steady window t = {start:g}–{end:g} s holds {int(inside.sum())} frame(s) of a run that ends at "
            f"{loads.times[-1] if len(loads.times) else 0:g} s: fatigue needs the run past its ramps (drive.ramp, "
            "load.ramp) or a record.summary_window"
        )
    t = loads.times[inside]
    span = float(t[-1] - t[0])
    revolutions = float(run.scene.value("drive.speed_rpm")) / 60.0 * span
    curve = SnCurve.of(run)
    rows: list[dict[str, object]] = []
    for sec in secs:
        sigma, tau = section_stresses(loads, sec)
        for i, k in enumerate(loads.links):
            row = _fibre_row(sigma[inside, i, :], tau[inside, i], curve, sec.scf)
            damage = row.pop("damage")
            per_hour = damage / span * 3600.0 if span > 0 else 0.0
            hinge = {"neck": int(k), "seat": int(k) - 1}.get(sec.name)
            rows.append(row | {
                "section": sec.name, "link": int(k), "hinge": hinge,
                "damage_per_revolution": damage / revolutions if revolutions > 0 else None,
                "damage_per_hour": per_hour, "hours_to_failure": 1.0 / per_hour if per_hour > 0 else None,
                "window_start": float(t[0]), "window_end": float(t[-1]),
            })  # fmt: skip
    return pa.Table.from_pylist(rows, schema=_schema())


def fatigue_line(table: pa.Table) -> str | None:
    """One line: the shortest fatigue life, where, and its stresses; ``None`` without damage."""
    rows = [r for r in table.to_pylist() if r["hours_to_failure"] is not None]
    if not rows:
        return None
    r = min(rows, key=lambda r: r["hours_to_failure"])
    where = f"{r['section']} of link {r['link']}" + (f" (hinge {r['hinge']})" if r["hinge"] is not None else "")
    return (
        f"shortest fatigue life {r['hours_to_failure']:.3g} h of this duty at the {where}: "
        f"σ_a {r['stress_amplitude'] / 1e6:.0f} MPa at σ′_m {r['stress_mean'] / 1e6:.0f} MPa "
        f"(K_t × nominal, rigid-link loads; Basquin–Goodman, Miner, over t = {r['window_start']:g}–"
        f"{r['window_end']:g} s; fatigue.*)"
    )
