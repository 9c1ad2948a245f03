"""The named scalars of a run the accuracy study compares (`quantities`), and their relative error."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pyarrow as pa

from ballcage._links import link_tube_forces
from ballcage.run import Run

__all__ = ["FLOORS", "MAX_QUANTITY", "Quantity", "quantities"]

#: Floor of the relative error's denominator per kind of quantity: (value, unit).
FLOORS: dict[str, tuple[float, str]] = {
    "force": (1.0, "N"),
    "angle": (0.1, "deg"),
    "position": (1e-3, "m"),
    "velocity": (1e-3, "m/s"),
    "angular_velocity": (1e-3, "rad/s"),
    "energy": (1e-3, "J"),
}
#: The pseudo-quantity holding the largest error of a run.
MAX_QUANTITY = "max_over_quantities"

@dataclass(frozen=True)
class Quantity:
    """One named scalar of a run: `value` in `unit`; `components` are compared for the error."""

    kind: str  # a key of FLOORS
    unit: str
    value: float
    components: tuple[float, ...]
    description: str


def _scalar(kind: str, value: float, description: str) -> Quantity:
    return Quantity(kind, FLOORS[kind][1], float(value), (float(value),), description)


def _vector(kind: str, vec: Sequence[float], description: str) -> Quantity:
    comps = tuple(float(v) for v in vec)
    return Quantity(kind, FLOORS[kind][1], math.sqrt(sum(c * c for c in comps)), comps, description)


def quantities(run: Run) -> dict[str, Quantity]:
    """The named scalars of a run the accuracy study compares (see `ballcage.studies`).

    Drill-pipe quantities come from the ``keys`` and ``links`` tables;
    generic ones from ``summary`` and ``bodies``; both from ``energy``.
    A quantity whose table was not recorded (or is empty) is left out.
    """
    out: dict[str, Quantity] = {}
    out.update(_key_quantities(run))
    out.update(_pair_quantities(run))
    out.update(_tube_quantities(run))
    out.update(_link_quantities(run))
    out.update(_body_quantities(run))
    out.update(_energy_quantities(run))
    return out


def _recorded(run: Run, name: str) -> pa.Table | None:
    """The table `name` of `run` when it was recorded and has rows, else ``None``."""
    table = run.tables.get(name)
    return table if table is not None and table.num_rows else None


def _key_quantities(run: Run) -> dict[str, Quantity]:
    keys = _recorded(run, "keys")
    if keys is None:
        return {}
    peak = float(np.nanmax(keys.column("outer_normal").to_numpy()))
    return {
        "key_seat_normal_peak": _scalar(
            "force", peak, "largest keys.outer_normal (seat race, both flanks of one key) over all keys and frames"
        )
    }


def _pair_quantities(run: Run) -> dict[str, Quantity]:
    """Generic scenes: the peak normal force of each recorded pair."""
    summary = _recorded(run, "summary")
    if summary is None or run.scene.kind != "generic":
        return {}
    pairs = summary.column("pair").cast(pa.string()).to_pylist()
    peaks = summary.column("normal_peak").to_numpy()
    return {
        f"peak_normal_force_{pair}": _scalar("force", peak, f"summary.normal_peak of pair {pair}")
        for pair, peak in zip(pairs, peaks, strict=True)
    }


def _tube_quantities(run: Run) -> dict[str, Quantity]:
    """Drill pipes: each link's mean link–tube normal force over the summary window."""
    tube = link_tube_forces(run)
    if tube is None:
        return {}
    return {
        f"tube_mean_force_joint_{link:02d}": _scalar(
            "force", mean, f"time mean of links.tube_normal of link {link:02d} over the summary window"
        )
        for link, mean in tube.normal_mean.items()
    }


def _link_quantities(run: Run) -> dict[str, Quantity]:
    links = _recorded(run, "links")
    if links is None:
        return {}
    last = last_frame(links)
    out: dict[str, Quantity] = {}
    for link, angle in zip(last.column("link").to_pylist(), last.column("included_angle_deg").to_numpy(), strict=True):
        out[f"final_bend_deg_link_{int(link):02d}"] = _scalar(
            "angle", 180.0 - float(angle), f"180 deg - links.included_angle_deg of link {int(link):02d} at the last frame"
        )
    return out


def _body_quantities(run: Run) -> dict[str, Quantity]:
    bodies = _recorded(run, "bodies")
    if bodies is None:
        return {}
    # a generic scene's quantities are its moving bodies' (`Scene.integrated_bodies`); a drill pipe's, every recorded body's
    integrated = set(run.scene.integrated_bodies) if run.scene.kind == "generic" else None
    last = last_frame(bodies)
    names = last.column("body").cast(pa.string()).to_pylist()
    cols = {c: last.column(c).to_numpy() for c in last.column_names if c.startswith(("pos_", "vel_", "angvel_"))}
    out: dict[str, Quantity] = {}
    for i, name in enumerate(names):
        if integrated is not None and name not in integrated:
            continue
        for prefix, kind, label in (
            ("pos", "position", "final_position"),
            ("vel", "velocity", "final_velocity"),
            ("angvel", "angular_velocity", "final_angular_velocity"),
        ):
            vec = [cols[f"{prefix}_{a}"][i] for a in "xyz"]
            out[f"{label}_{name}"] = _vector(kind, vec, f"bodies.{prefix}_x/y/z of {name} at the last frame")
    return out


def _energy_quantities(run: Run) -> dict[str, Quantity]:
    energy = _recorded(run, "energy")
    if energy is None:
        return {}
    last = last_frame(energy)
    return {
        "final_total_energy": _scalar("energy", last.column("total")[0].as_py(), "energy.total at the last frame"),
        "final_kinetic_energy": _scalar("energy", last.column("kinetic")[0].as_py(), "energy.kinetic at the last frame"),
    }


def last_frame(table: pa.Table) -> pa.Table:
    """The rows of `table` at its last recorded step."""
    import pyarrow.compute as pc

    return table.filter(pc.equal(table.column("step"), pc.max(table.column("step"))))


def relative_error(q: Quantity, ref: Quantity, floor: float) -> float:
    """Largest component difference of `q` and `ref` over ``max(|ref|, floor)``; NaN when their shapes differ."""
    if len(q.components) != len(ref.components):
        return math.nan
    diff = max(abs(a - b) for a, b in zip(q.components, ref.components, strict=True))
    return diff / max(abs(ref.value), floor)
