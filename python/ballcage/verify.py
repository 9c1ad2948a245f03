"""A run's measured error: the same scene ten times tighter, and the difference of each headline quantity.

``ballcage run --verify`` and ``simulate(..., verify=True)`` start the
verification run beside the run (`Started`, in a thread of its own: the
engine releases the GIL, so on two cores both take about the time of the
longer) and finish it with `verify` (`VERIFIER`, the hook
`ballcage.run.VERIFIER`); `verify` alone checks a finished run after it. It runs the scene at the
setting `tighter` gives (``dt/4`` for SDIRK2, ``rtol/10`` for adaptive steps;
the rule lives in `ballcage.studies.refinement`, which ``ballcage sensitivity`` shares),
takes the headline quantities of both runs (`headline`: the drill pipe's
comparison quantities, `ballcage.measures.DRILL_PIPE`, as
`ballcage.studies.sweep_quantities.for_scene` picks them; a generic scene's
summary statistics) and tabulates their differences (`compare`) as a
`ballcage.run.Verification`, written as ``verify.parquet``. `verdict` is the
one line ``ballcage run --verify`` ends with.

The relative difference is ``|a − b| / max(|b|, floor)``, a the run's value
and b the verification run's: `floor` is the quantity's natural scale near
zero, the accuracy study's floor of its unit (`ballcage.studies.FLOORS`: 1 N,
0.1°, 1 mm, …). A unit without a floor (an efficiency) has none: the relative
difference is then null when b is zero and a is not. A quantity without a
unit (a part number, as ``most_deformed_joint``) has no relative difference;
its note says whether the runs agree.
"""

from __future__ import annotations

import inspect
import json
import math
import sys
import threading
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from ballcage import _native
from ballcage.run import ProgressBar, Run, Verification, VerificationError, run_watched, simulate
from ballcage.studies.refinement import TIGHTER, Tighter, tighter

if TYPE_CHECKING:
    import pyarrow as pa

__all__ = [
    "TIGHTER",
    "Tighter",
    "VerificationError",
    "compare",
    "floor",
    "headline",
    "tighter",
    "verdict",
    "verification_of",
    "verify",
]

#: The rule of ``verify.parquet``'s relative difference (also in its schema metadata, ``ballcage.verify.relative``).
RELATIVE = (
    "rel_difference = |run_value - verify_value| / max(|verify_value|, floor), floor the quantity's natural scale "
    "near zero: the accuracy study's floor of its unit (ballcage.studies.FLOORS: 1 N, 0.1 deg, 1 mm, 1 mm/s, "
    "1e-3 rad/s, 1 mJ); a unit without a floor has none, and rel_difference is null when verify_value is zero and "
    "run_value is not; a quantity without a unit (a part number) has none; 0 where the values are equal"
)
#: The columns of ``verify.parquet``: name -> (Arrow type name, unit, description).
COLUMNS: dict[str, tuple[str, str, str]] = {
    "quantity": ("string", "", "headline quantity: a drill pipe's comparison quantity (as in a sweep's summary.parquet) "
                 "or a generic scene's summary statistic, <column of the summary table>[<contact pair>]"),
    "unit": ("string", "", "unit of run_value, verify_value, abs_difference and floor"),
    "run_value": ("float64", "", "the run's value (in unit); null where not computed or not finite"),
    "verify_value": ("float64", "", "the verification run's value (in unit): the same scene ten times tighter"),
    "abs_difference": ("float64", "", "|run_value - verify_value| (in unit): the run's measured error"),
    "rel_difference": ("float64", "1", "abs_difference / max(|verify_value|, floor); null: see note"),
    "floor": ("float64", "", "the quantity's natural scale near zero (in unit): the accuracy study's floor of its unit; "
              "null for a unit without one"),
    "note": ("string", "", "why rel_difference is null, or how the runs compare where it cannot say"),
}  # fmt: skip


class Started:
    """The verification run of `scene` going on in a thread of its own beside the run it checks (`verify`).

    The thread runs `scene` at the `tighter` setting without a bar; what it
    returns or raises is handed over by `result`. `cancel` stops it at its
    next piece (`ballcage.run.run_watched`): the run it checks failed. A
    daemon thread, so that it never holds up the interpreter's exit.
    """

    def __init__(self, scene: _native.Scene, progress: bool | None) -> None:
        self.setting = tighter(scene)
        if progress is not False:
            print(f"ballcage: verifying: the run again at {self.setting.label} ({', '.join(self.setting.overrides)})",
                  file=sys.stderr)  # fmt: skip
        self._stop = threading.Event()
        self._t = 0.0
        self._duration = scene.duration
        self._outcome: Run | BaseException | None = None
        self._thread = threading.Thread(target=self._work, args=(scene,), name="ballcage-verify", daemon=True)
        self._thread.start()

    def _work(self, scene: _native.Scene) -> None:
        try:
            self._outcome = run_watched(scene, self.setting.overrides, self._watch)
        except BaseException as e:  # noqa: BLE001 - raised again in the caller's thread by `result`
            self._outcome = e

    def _watch(self, t: float) -> bool:
        self._t = t
        return self._stop.is_set()

    def cancel(self) -> None:
        """Stops the verification run at its next piece, and waits for it."""
        self._stop.set()
        self._thread.join()

    def result(self, progress: bool | None) -> Run:
        """The verification run, complete, or what it raised; waits for it with a bar of its own (`progress`)."""
        if self._thread.is_alive():
            bar = ProgressBar(progress, self._duration)
            try:
                while self._thread.is_alive():
                    self._thread.join(0.1)
                    bar.update(self._t)
            finally:
                bar.close()
        if isinstance(self._outcome, BaseException):
            raise self._outcome
        assert self._outcome is not None  # the thread has ended
        return self._outcome


class _Verifier:
    """`ballcage.run.VERIFIER`: the verification run started beside the run (`Started`) and finished by `verify`."""

    def start(self, scene: _native.Scene, progress: bool | None) -> Started:
        return Started(scene, progress)

    def finish(self, run: Run, progress: bool | None, started: Started) -> Verification:
        return verify(run, progress=progress, started=started)

    def cancel(self, started: Started) -> None:
        started.cancel()


#: The hook the package's facade sets as `ballcage.run.VERIFIER`.
VERIFIER = _Verifier()


def verify(run: Run, *, progress: bool | None = None, started: Started | None = None) -> Verification:
    """Compares `run`'s `headline` quantities with those of its scene at the `tighter` setting.

    `run` must be complete. The verification run is `started` (begun beside
    `run` by ``simulate(..., verify=True)``), or else run now. `progress` is
    as for `simulate`; unless it is ``False``, a line on stderr announces the
    verification run. Raises `VerificationError` when the verification run
    diverges or its scene is refused; an interrupt (`KeyboardInterrupt`)
    during it is re-raised carrying `run`, complete, as ``e.run``.
    """
    if not run.complete:
        if started is not None:
            started.cancel()
        raise _native.InputError(f"cannot verify an incomplete run ({run.error or 'ballcage.complete = false'})")
    setting = tighter(run.scene) if started is None else started.setting
    if progress is not False and started is None:  # the verification run's bar starts again from 0 %
        print(f"ballcage: verifying: the run again at {setting.label} ({', '.join(setting.overrides)})", file=sys.stderr)
    try:
        if started is None:
            check = simulate(run.scene, overrides=setting.overrides, progress=progress)
        else:
            check = started.result(progress)
        table = compare(headline(run), headline(check))
    except (_native.SimulationError, _native.SceneError) as e:
        error = VerificationError(f"the verification run at {setting.label} failed: {e}")
        error.run, error.check = run, getattr(e, "run", None)
        raise error from e
    except KeyboardInterrupt as e:
        if started is not None:
            started.cancel()
        e.run = run  # type: ignore[attr-defined]  # the complete run, not the verification's part
        raise
    rel = [(r, q) for r, q in zip(table["rel_difference"].to_pylist(), table["quantity"].to_pylist()) if r is not None]
    largest, quantity = max(rel, key=lambda rq: rq[0]) if rel else (None, None)
    run_time, check_time = (_float(r.metadata.get("ballcage.wall_time_s")) for r in (run, check))
    ratio = check_time / run_time if check_time is not None and run_time else None
    meta = {
        "ballcage.table": "verify",
        "ballcage.row": "one row per headline quantity",
        "ballcage.version": _native.__version__,
        "ballcage.verify.setting": setting.label,
        "ballcage.verify.overrides": json.dumps(setting.overrides),
        "ballcage.verify.rule": inspect.cleandoc(tighter.__doc__ or ""),
        "ballcage.verify.relative": RELATIVE,
        "ballcage.verify.run_wall_time_s": run.metadata.get("ballcage.wall_time_s", ""),
        "ballcage.verify.check_wall_time_s": check.metadata.get("ballcage.wall_time_s", ""),
        "ballcage.verify.time_ratio": "" if ratio is None else repr(ratio),
        "ballcage.verify.run_dt_s": run.metadata.get("ballcage.dt_s", ""),
        "ballcage.verify.check_dt_s": check.metadata.get("ballcage.dt_s", ""),
        "ballcage.verify.largest_relative": "" if largest is None else repr(largest),
        "ballcage.verify.largest_quantity": quantity or "",
    }
    return Verification(table.replace_schema_metadata(meta), setting.label, setting.overrides, largest, quantity, ratio)


def verification_of(table: pa.Table) -> Verification:
    """The `Verification` a ``verify.parquet`` table (read back, e.g. by ``pyarrow.parquet.read_table``) holds.

    Its setting, overrides, largest difference and time ratio come from the
    schema metadata `verify` writes.
    """
    meta = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}
    return Verification(
        table,
        meta.get("ballcage.verify.setting", ""),
        tuple(json.loads(meta.get("ballcage.verify.overrides") or "[]")),
        _float(meta.get("ballcage.verify.largest_relative")),
        meta.get("ballcage.verify.largest_quantity") or None,
        _float(meta.get("ballcage.verify.time_ratio")),
    )


def headline(run: Run) -> dict[str, tuple[str, float | None]]:
    """The run's headline quantities, name -> (unit, value; ``None`` where not computed).

    The quantities of the scene kind's sweep plug-in (`for_scene`: the drill
    pipe's `DRILL_PIPE`); when it has none (`GENERIC`), the summary statistics
    of each contact pair, ``<statistic>[<pair>]`` for every column of the
    ``summary`` table in N (empty without that table).
    """
    from ballcage.studies.sweep_quantities import for_scene, summary_statistics  # deferred: numpy, the measures

    plugin = for_scene(run.scene)
    values = plugin(run)
    if not values:
        return summary_statistics(run)
    columns = plugin.columns(values)
    return {name: (columns[name][0], value) for name, value in values.items()}


def floor(unit: str) -> float | None:
    """The natural scale near zero of a quantity in `unit`: the accuracy study's floor of that unit, else ``None``."""
    from ballcage.studies.scalars import FLOORS  # deferred: numpy

    floors = {u: value for value, u in FLOORS.values()}
    if unit == "mm" and "m" in floors:
        return 1e3 * floors["m"]
    return floors.get(unit)


def compare(
    values: Mapping[str, tuple[str, float | None]], reference: Mapping[str, tuple[str, float | None]]
) -> pa.Table:
    """The ``verify.parquet`` table of the run's headline `values` against the verification run's `reference`.

    One row per quantity of either (the reference's order first); a value that
    is ``None`` or not finite is null. Columns and the relative rule: `COLUMNS`
    and the module's docstring.
    """
    import pyarrow as pa

    rows = [_row(name, values.get(name), reference.get(name)) for name in {**reference, **values}]
    fields = [
        pa.field(name, getattr(pa, kind)(), metadata={"unit": unit, "description": description})
        for name, (kind, unit, description) in COLUMNS.items()
    ]
    return pa.Table.from_pylist(rows, schema=pa.schema(fields))


def _row(
    name: str, value: tuple[str, float | None] | None, reference: tuple[str, float | None] | None
) -> dict[str, Any]:
    """One row of `compare`."""
    unit = (reference or value or ("", None))[0]
    a, b = _finite(value), _finite(reference)
    low = floor(unit) if unit else None
    row: dict[str, Any] = dict.fromkeys(COLUMNS) | {"quantity": name, "unit": unit, "run_value": a, "verify_value": b}
    row["floor"] = low
    if a is None or b is None:
        missing = [label for label, v in (("the run", a), ("the verification run", b)) if v is None]
        row["note"] = f"not computed (or not finite) in {' and '.join(missing)}"
        return row
    row["abs_difference"] = abs(a - b)
    if not unit:
        row["note"] = "a part number, not a magnitude: " + ("the runs agree" if a == b else "the runs differ")
    elif a == b:
        row["rel_difference"] = 0.0
    elif max(abs(b), low or 0.0) > 0.0:
        row["rel_difference"] = abs(a - b) / max(abs(b), low or 0.0)
    else:
        row["note"] = f"zero in the verification run and no floor for unit {unit!r}: no relative difference"
    return row


def verdict(verification: Verification) -> str:
    """The last line of ``ballcage run --verify``.

    ``error ≤ 0.31 % on <quantity> (verified at dt/4: 3.9× the run's time)``: the largest relative
    difference, its quantity, the setting and the verification run's wall time over the run's.
    """
    ratio = verification.time_ratio
    cost = f"verified at {verification.setting}: " + (
        f"{_two_digits(ratio)}× the run's time" if ratio is not None else "its time not measured"
    )
    if verification.largest is None:
        return f"error not measured: no headline quantity has a relative difference, see verify.parquet ({cost})"
    return f"error ≤ {_two_digits(100.0 * verification.largest)} % on {verification.quantity} ({cost})"


def disagreements(verification: Verification) -> list[str]:
    """One line per quantity the runs disagree on without a relative difference (a part number, a missing value)."""
    out = []
    for row in verification.table.to_pylist():
        a, b = row["run_value"], row["verify_value"]
        if row["rel_difference"] is None and a != b:
            out.append(f"{row['quantity']}: {_value(a)} in the run, {_value(b)} verified ({row['note']})")
    return out


def _two_digits(x: float) -> str:
    """`x` to two significant digits without an exponent from 0.001 to 10⁴: 0.31, 3.9, 12, 150."""
    if x == 0.0 or not math.isfinite(x):
        return f"{x:g}"
    if not 1e-3 <= abs(x) < 1e4:
        return f"{x:.2g}"
    return f"{x:.{max(0, 1 - math.floor(math.log10(abs(x))))}f}"


def _value(x: float | None) -> str:
    return "none" if x is None else f"{x:.6g}"


def _finite(value: tuple[str, float | None] | None) -> float | None:
    if value is None or value[1] is None:
        return None
    x = float(value[1])
    return x if math.isfinite(x) else None


def _float(text: str | None) -> float | None:
    try:
        return float(text) if text else None
    except ValueError:
        return None
