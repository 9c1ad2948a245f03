"""Contact pressure against the material's limit, wear, and where the power goes.

Read from a drill-pipe run's ``wear`` table (one row per contact pair: friction
work, Archard wear, the largest Hertz peak pressure and its margin) and its
``hinges`` and ``drive`` tables (torque and power per hinge, friction power per
feature). The models behind the columns are in docs/model.md, "Contact
pressure and wear"; ``ballcage schema wear`` lists every column with its unit.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ballcage._native import InputError

if TYPE_CHECKING:
    import pyarrow as pa

__all__ = [
    "LOSS_GROUPS",
    "loss_breakdown",
    "margin_line",
    "pressure_at",
    "smallest_margin",
    "wear_line",
    "write_loss_figure",
]

#: The loss groups of the breakdown, by the ``feature`` of a pair (the pairs and wear tables' labels).
LOSS_GROUPS: dict[str, str] = {
    "tube": "tube",
    "inner-race": "key–race",
    "outer-race": "key–race",
    "window": "key–window",
    "cage-head": "cage",
    "cage-seat": "cage",
    "neck-mouth": "neck",
}
_GROUP_ORDER = ("tube", "key–race", "key–window", "cage", "neck")


def _rows(wear: pa.Table) -> list[dict[str, Any]]:
    if "pressure_margin" not in wear.column_names:
        raise InputError(f"not a wear table: columns {wear.column_names} (ballcage schema wear)")
    return wear.to_pylist()


def _part(row: dict[str, Any]) -> str:
    """Where a pair is, in words: ``inner-race, hinge 2, key 3``."""
    ids = [f"{name} {row[name]}" for name in ("link", "hinge", "key") if row.get(name) is not None]
    return ", ".join([row["feature"], *ids])


def smallest_margin(wear: pa.Table) -> dict[str, Any] | None:
    """The wear row with the smallest ``pressure_margin`` (allowable / peak pressure); ``None`` without contact."""
    rows = [r for r in _rows(wear) if r["pressure_margin"] is not None]
    return min(rows, key=lambda r: r["pressure_margin"]) if rows else None


def margin_line(wear: pa.Table) -> str | None:
    """One line: the smallest contact-pressure margin, its contact and time; ``None`` without contact."""
    r = smallest_margin(wear)
    if r is None:
        return None
    verdict = "within" if r["pressure_margin"] >= 1.0 else "beyond"
    return (
        f"smallest contact-pressure margin {r['pressure_margin']:.3g} ({verdict} the static limit): "
        f"Hertz p0 {r['pressure_peak'] / 1e6:.0f} MPa against the allowable {r['allowable_pressure'] / 1e6:.0f} MPa "
        f"at {r['pair']} ({_part(r)}), t = {r['pressure_peak_t']:.3f} s, {r['pressure_peak_force'] / 1e3:.3g} kN"
    )


def loss_breakdown(wear: pa.Table) -> dict[str, float]:
    """Mean friction power [W] over the wear window, by group (`LOSS_GROUPS`), in a fixed order."""
    out = dict.fromkeys(_GROUP_ORDER, 0.0)
    for r in _rows(wear):
        out[LOSS_GROUPS[r["feature"]]] += r["friction_power"]
    return out


def wear_line(wear: pa.Table) -> str | None:
    """One line: the friction loss and its split, and the contact that wears 0.1 mm first; ``None`` without wear."""
    rows = _rows(wear)
    losses = loss_breakdown(wear)
    total = sum(losses.values())
    if not rows or total <= 0.0:
        return None
    split = ", ".join(f"{g} {100 * w / total:.0f} %" for g, w in losses.items() if w > 0.0)
    line = f"friction loss {total:.4g} W ({split}) over t = {rows[0]['window_start']:g}–{rows[0]['window_end']:g} s"
    wearing = [r for r in rows if r["hours_per_100um"] is not None]
    if wearing:
        r = min(wearing, key=lambda r: r["hours_per_100um"])
        line += (
            f"; a spot that stayed under the contact would wear 0.1 mm first at {r['pair']} ({_part(r)}) after "
            f"{r['hours_per_100um']:.3g} h of this duty (Archard, scales with k; a lower bound on the hours: the "
            "contact moves, the wear map's figure follows)"
        )
    return line


def pressure_at(wear: pa.Table, feature: str, force: float) -> float | None:
    """Hertz peak pressure [Pa] of a `feature` contact (``"inner-race"``, …) under `force` [N].

    Scaled from that feature's highest recorded peak as p0·(F/F_peak)^(1/3),
    exact for the elliptical (point) contacts of balls and cages, whose p0
    goes as the cube root of the force; ``None`` when the feature never touched.
    """
    rows = [r for r in _rows(wear) if r["feature"] == feature and r["pressure_peak"] is not None]
    if not rows:
        return None
    r = max(rows, key=lambda r: r["pressure_peak"])
    return float(r["pressure_peak"] * (force / r["pressure_peak_force"]) ** (1.0 / 3.0))


def write_loss_figure(wear: pa.Table, path: str | os.PathLike[str]) -> Path:
    """A stacked bar per position k of the pipe: link k's tube friction and hinge k's key–race,
    key–window, cage and neck friction [W], mean over the wear window; written as PNG to `path`."""
    from ballcage._files import write_png
    from ballcage._plot import figure, series_styles

    rows = _rows(wear)
    positions = sorted({r["link"] if r["link"] is not None else r["hinge"] for r in rows})
    index = {k: i for i, k in enumerate(positions)}
    stacks = {g: [0.0] * len(positions) for g in _GROUP_ORDER}
    for r in rows:
        k = r["link"] if r["link"] is not None else r["hinge"]
        stacks[LOSS_GROUPS[r["feature"]]][index[k]] += r["friction_power"]
    fig = figure(figsize=(9.5, 4.5))
    ax = fig.add_subplot()
    bottom = [0.0] * len(positions)
    for (group, heights), style in zip(stacks.items(), series_styles(len(stacks)), strict=True):
        ax.bar(positions, heights, bottom=bottom, color=style["color"], label=f"{group} {sum(heights):.0f} W")
        bottom = [b + h for b, h in zip(bottom, heights, strict=True)]
    start, end = rows[0]["window_start"], rows[0]["window_end"]
    ax.set_xlabel("position k [-]: link k (tube) and hinge k (0 above link 1)")
    ax.set_ylabel("mean friction power [W]")
    ax.set_title(f"Where the power goes: friction loss by contact, t = {start:g}–{end:g} s")
    ax.set_xticks(positions)
    ax.legend(title=f"total {sum(bottom):.0f} W", loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return write_png(fig, Path(path))
