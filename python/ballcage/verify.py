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

``verify=2`` (``ballcage run --verify 2``) adds a second verification run at
the rule applied twice (``rtol/100``, ``dt/16`` for SDIRK2), which checks the
first: the verification run's difference from the run is its error only if
the verification run's own error is much smaller. Its own error, as the second
run measures it, is the ``confirm_*`` columns; `CONFIRM_RULE` says when it
confirms the measured error. Where it does not, the error the first run
measures is an underestimate of unknown size (the ideal-CV chain at a loose
rtol, docs/accuracy.md, "A verification that checks itself").
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
from ballcage.run import Cancelled, ProgressBar, Run, Verification, VerificationError, run_watched, simulate
from ballcage.studies.refinement import TIGHTER, Tighter, tighter

if TYPE_CHECKING:
    import pyarrow as pa

__all__ = [
    "CONFIRM_RULE",
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
#: Relative differences at or below this are round-off, not error: every headline quantity is reported to fewer digits.
ROUND_OFF = 1e-9
#: When the second verification run (``verify=2``) confirms the first (``Verification.confirmed``).
CONFIRM_RULE = (
    "confirmed when the largest confirm_rel_difference (the first verification run's own error, measured by the "
    "second, 10 times tighter again) is at most a third of the largest rel_difference (the run's error, measured by "
    "the first), or at most 1e-9 (round-off): the measured error is then good to a third; otherwise the first "
    "verification run is not converged enough to measure the run's error"
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
    "confirm_value": ("float64", "", "the second verification run's value (in unit), ten times tighter again "
                      "(verify=2); null without it"),
    "confirm_difference": ("float64", "", "|verify_value - confirm_value| (in unit): the verification run's own "
                           "error, as the second measures it; null without it"),
    "confirm_rel_difference": ("float64", "1", "confirm_difference / max(|confirm_value|, floor), the rule of "
                               "rel_difference; null without the second run or as rel_difference"),
    "confirmed": ("bool_", "", "verify=2: whether the second run confirms this quantity's rel_difference, "
                  "confirm_rel_difference <= max(rel_difference / 3, 1e-9) (CONFIRM_RULE, per quantity); null without "
                  "the second run or either relative difference"),
    "floor": ("float64", "", "the quantity's natural scale near zero (in unit): the accuracy study's floor of its unit; "
              "null for a unit without one"),
    "note": ("string", "", "why rel_difference is null, or how the runs compare where it cannot say"),
}  # fmt: skip


class Started:
    """The verification runs of `scene` (one or two, `tighter`) going on in threads of their own beside the run they
    check (`verify`).

    Each thread runs `scene` at its setting without a bar; what it returns or
    raises is handed over by `outcomes`. `cancel` stops them at their next
    piece (`ballcage.run.run_watched`): the run they check failed. Daemon
    threads, so that they never hold up the interpreter's exit.
    """

    def __init__(self, scene: _native.Scene, progress: bool | None, runs: int = 1) -> None:
        self.settings = tuple(tighter(scene, times) for times in range(1, runs + 1))
        if progress is not False:
            _announce(self.settings)
        self._stop = threading.Event()
        self._t = [0.0] * runs
        self._duration = scene.duration
        self._outcomes: list[Run | BaseException | None] = [None] * runs
        self._threads = [
            threading.Thread(target=self._work, args=(scene, i), name=f"ballcage-verify-{i + 1}", daemon=True)
            for i in range(runs)
        ]
        for thread in self._threads:
            thread.start()

    def _work(self, scene: _native.Scene, i: int) -> None:
        try:
            self._outcomes[i] = run_watched(scene, self.settings[i].overrides, lambda t: self._watch(i, t))
        except BaseException as e:  # noqa: BLE001 - raised again in the caller's thread by `verify`
            self._outcomes[i] = e

    def _watch(self, i: int, t: float) -> bool:
        self._t[i] = t
        return self._stop.is_set()

    def cancel(self) -> None:
        """Stops the verification runs at their next piece, and waits for them."""
        self._stop.set()
        for thread in self._threads:
            thread.join()

    def outcomes(self, progress: bool | None) -> list[Run | BaseException]:
        """Each verification run, complete, or what it raised; waits for them with a bar of their own (`progress`,
        at the slower one's time). One that fails stops the other: its outcome is then `Cancelled`."""
        if any(thread.is_alive() for thread in self._threads):
            bar = ProgressBar(progress, self._duration)
            try:
                while alive := [thread for thread in self._threads if thread.is_alive()]:
                    if any(isinstance(outcome, BaseException) for outcome in self._outcomes):
                        self._stop.set()
                    alive[0].join(0.1)
                    bar.update(min(self._t))
            finally:
                bar.close()
        assert all(outcome is not None for outcome in self._outcomes)  # the threads have ended
        return [outcome for outcome in self._outcomes if outcome is not None]


def _announce(settings: tuple[Tighter, ...]) -> None:
    """The line on stderr that says which verification runs run."""
    what = " and at ".join(f"{s.label} ({', '.join(s.overrides)})" for s in settings)
    print(f"ballcage: verifying: the run again at {what}", file=sys.stderr)


class _Verifier:
    """`ballcage.run.VERIFIER`: the verification run started beside the run (`Started`) and finished by `verify`."""

    def start(self, scene: _native.Scene, progress: bool | None, runs: int) -> Started:
        return Started(scene, progress, runs)

    def finish(self, run: Run, progress: bool | None, started: Started) -> Verification:
        return verify(run, progress=progress, started=started)

    def cancel(self, started: Started) -> None:
        started.cancel()


#: The hook the package's facade sets as `ballcage.run.VERIFIER`.
VERIFIER = _Verifier()


def verify(
    run: Run, *, progress: bool | None = None, started: Started | None = None, runs: int = 1
) -> Verification:
    """Compares `run`'s `headline` quantities with those of its scene at the `tighter` setting.

    `run` must be complete. The verification runs are `started` (begun beside
    `run` by ``simulate(..., verify=...)``), or else run now: `runs` of them, 1
    or 2 (the second ten times tighter again, checking the first). `progress`
    is as for `simulate`; unless it is ``False``, a line on stderr announces
    the verification runs. Raises `VerificationError` when a verification run
    diverges or its scene is refused; an interrupt (`KeyboardInterrupt`)
    during them is re-raised carrying `run`, complete, as ``e.run``.
    """
    if not run.complete:
        if started is not None:
            started.cancel()
        raise _native.InputError(f"cannot verify an incomplete run ({run.error or 'ballcage.complete = false'})")
    if started is None and runs not in (1, 2):
        raise _native.InputError(f"verify: runs = {runs!r} is not 1 or 2")
    settings = tuple(tighter(run.scene, t) for t in range(1, runs + 1)) if started is None else started.settings
    if progress is not False and started is None:  # the verification run's bar starts again from 0 %
        _announce(settings)
    checks: list[Run] = []
    try:
        done = started.outcomes(progress) if started is not None else None
        failed = [(s, o) for s, o in zip(settings, done or ()) if isinstance(o, BaseException)]
        if failed:  # what failed, not the run it stopped (`Cancelled`)
            setting, outcome = next(((s, o) for s, o in failed if not isinstance(o, Cancelled)), failed[0])
            raise outcome
        for i, setting in enumerate(settings):
            outcome = done[i] if done is not None else simulate(run.scene, overrides=setting.overrides, progress=progress)
            if isinstance(outcome, BaseException):
                raise outcome
            checks.append(outcome)
        table = compare(headline(run), *(headline(check) for check in checks))
    except (_native.SimulationError, _native.SceneError) as e:
        error = VerificationError(f"the verification run at {setting.label} failed: {e}")
        error.run, error.check = run, getattr(e, "run", None)
        raise error from e
    except KeyboardInterrupt as e:
        if started is not None:
            started.cancel()
        e.run = run  # type: ignore[attr-defined]  # the complete run, not the verification's part
        raise
    largest, quantity = _largest(table, "rel_difference")
    confirm_largest, confirm_quantity = _largest(table, "confirm_rel_difference")
    confirmed = confirms(largest, confirm_largest) if len(checks) == 2 else None
    run_time = _float(run.metadata.get("ballcage.wall_time_s"))
    check_times = [_float(check.metadata.get("ballcage.wall_time_s")) for check in checks]
    ratio = sum(check_times) / run_time if run_time and None not in check_times else None  # type: ignore[arg-type]
    setting, check = settings[0], checks[0]
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
    if len(checks) == 2:
        meta |= _confirm_metadata(settings[1], checks[1], (confirm_largest, confirm_quantity), confirmed)
    return Verification(
        table.replace_schema_metadata(meta), setting.label, setting.overrides, largest, quantity, ratio,
        settings[1].label if len(checks) == 2 else None, confirm_largest, confirm_quantity, confirmed,
    )  # fmt: skip


def _confirm_metadata(
    setting: Tighter, check: Run, largest: tuple[float | None, str | None], confirmed: bool | None
) -> dict[str, str]:
    """The schema metadata of ``verify.parquet`` on the second verification run (`setting`, `check`): its largest
    ``confirm_rel_difference`` and quantity, and whether it confirms the first (`CONFIRM_RULE`)."""
    return {
        "ballcage.verify.confirm_setting": setting.label,
        "ballcage.verify.confirm_overrides": json.dumps(setting.overrides),
        "ballcage.verify.confirm_wall_time_s": check.metadata.get("ballcage.wall_time_s", ""),
        "ballcage.verify.confirm_largest_relative": "" if largest[0] is None else repr(largest[0]),
        "ballcage.verify.confirm_largest_quantity": largest[1] or "",
        "ballcage.verify.confirmed": "" if confirmed is None else str(confirmed).lower(),
        "ballcage.verify.confirm_rule": CONFIRM_RULE,
    }


def confirms(largest: float | None, confirm_largest: float | None) -> bool | None:
    """`CONFIRM_RULE`: whether the verification run's own error (`confirm_largest`, relative) is small enough beside
    the run's error it measured (`largest`) for that measure to hold; ``None`` when either is unknown."""
    if largest is None or confirm_largest is None:
        return None
    return confirm_largest <= max(largest / 3.0, ROUND_OFF)


def _largest(table: pa.Table, column: str) -> tuple[float | None, str | None]:
    """The largest value of `column` over the rows that have one, and its quantity; ``(None, None)`` if none has."""
    pairs = [(r, q) for r, q in zip(table[column].to_pylist(), table["quantity"].to_pylist()) if r is not None]
    return max(pairs, key=lambda rq: rq[0]) if pairs else (None, None)


def verification_of(table: pa.Table) -> Verification:
    """The `Verification` a ``verify.parquet`` table (read back, e.g. by ``pyarrow.parquet.read_table``) holds.

    Its settings, overrides, largest differences and time ratio come from the
    schema metadata `verify` writes.
    """
    meta = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}
    confirmed = meta.get("ballcage.verify.confirmed")
    return Verification(
        table,
        meta.get("ballcage.verify.setting", ""),
        tuple(json.loads(meta.get("ballcage.verify.overrides") or "[]")),
        _float(meta.get("ballcage.verify.largest_relative")),
        meta.get("ballcage.verify.largest_quantity") or None,
        _float(meta.get("ballcage.verify.time_ratio")),
        meta.get("ballcage.verify.confirm_setting") or None,
        _float(meta.get("ballcage.verify.confirm_largest_relative")),
        meta.get("ballcage.verify.confirm_largest_quantity") or None,
        None if not confirmed else confirmed == "true",
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
    values: Mapping[str, tuple[str, float | None]],
    reference: Mapping[str, tuple[str, float | None]],
    confirm: Mapping[str, tuple[str, float | None]] | None = None,
) -> pa.Table:
    """The ``verify.parquet`` table of the run's headline `values` against the verification run's `reference` (and,
    with ``verify=2``, the reference against the second verification run's `confirm`).

    One row per quantity of either (the reference's order first); a value that
    is ``None`` or not finite is null. Columns and the relative rule: `COLUMNS`
    and the module's docstring.
    """
    import pyarrow as pa

    rows = [
        _row(name, values.get(name), reference.get(name), None if confirm is None else confirm.get(name))
        for name in {**reference, **values}
    ]
    fields = [
        pa.field(name, getattr(pa, kind)(), metadata={"unit": unit, "description": description})
        for name, (kind, unit, description) in COLUMNS.items()
    ]
    return pa.Table.from_pylist(rows, schema=pa.schema(fields))


def _row(
    name: str,
    value: tuple[str, float | None] | None,
    reference: tuple[str, float | None] | None,
    confirm: tuple[str, float | None] | None,
) -> dict[str, Any]:
    """One row of `compare` (`confirm`: the second verification run's value, ``None`` without one)."""
    unit = (reference or value or ("", None))[0]
    a, b, c = _finite(value), _finite(reference), _finite(confirm)
    low = floor(unit) if unit else None
    row: dict[str, Any] = dict.fromkeys(COLUMNS) | {"quantity": name, "unit": unit, "run_value": a, "verify_value": b}
    row["floor"] = low
    row["confirm_value"] = c
    if b is not None and c is not None and unit:
        row["confirm_difference"] = abs(b - c)
        row["confirm_rel_difference"] = _relative(b, c, low)
    if a is None or b is None:
        missing = [label for label, v in (("the run", a), ("the verification run", b)) if v is None]
        row["note"] = f"not computed (or not finite) in {' and '.join(missing)}"
        return row
    row["abs_difference"] = abs(a - b)
    if not unit:
        row["note"] = "a part number, not a magnitude: " + ("the runs agree" if a == b else "the runs differ")
    elif (rel := _relative(a, b, low)) is not None:
        row["rel_difference"] = rel
        row["confirmed"] = confirms(rel, row["confirm_rel_difference"])
    else:
        row["note"] = f"zero in the verification run and no floor for unit {unit!r}: no relative difference"
    return row


def _relative(x: float, reference: float, low: float | None) -> float | None:
    """|x − reference| / max(|reference|, `low`) (`RELATIVE`): 0 where they are equal, ``None`` where the
    denominator is zero."""
    if x == reference:
        return 0.0
    scale = max(abs(reference), low or 0.0)
    return abs(x - reference) / scale if scale > 0.0 else None


def verdict(verification: Verification) -> str:
    """The last line of ``ballcage run --verify``.

    ``error ≤ 0.31 % on <quantity> (verified at dt/4: 3.9× the run's time)``: the largest relative
    difference, its quantity, the setting and the verification run's wall time over the run's. With a
    second verification run (``--verify 2``), what it says of the first (`CONFIRM_RULE`)::

        error ≤ 2.1 % on <quantity> (verified at dt/4, confirmed at dt/16: the dt/4 run is within 0.058 %
        of it; 21× the run's time)
        error NOT MEASURED: the rtol/10 run is 0.52 % from the rtol/100 run on <quantity>, more than a third
        of the 0.055 % it gives as the run's error on <quantity> (verified at rtol/10 and rtol/100: 5.5× …)
    """
    ratio = verification.time_ratio
    time = f"{_two_digits(ratio)}× the run's time" if ratio is not None else "its time not measured"
    first, second = verification.setting, verification.confirm_setting
    if verification.largest is None:
        settings = first if second is None else f"{first} and {second}"
        return f"error not measured: no headline quantity has a relative difference, see verify.parquet " \
               f"(verified at {settings}: {time})"  # fmt: skip
    error = f"{_two_digits(100.0 * verification.largest)} %"
    if second is None or verification.confirmed is None:
        return f"error ≤ {error} on {verification.quantity} (verified at {first}: {time})"
    own = f"{_two_digits(100.0 * (verification.confirm_largest or 0.0))} %"
    if verification.confirmed:
        return f"error ≤ {error} on {verification.quantity} (verified at {first}, confirmed at {second}: " \
               f"the {first} run is within {own} of it; {time})"  # fmt: skip
    return (
        f"error NOT MEASURED: the {first} run is {own} from the {second} run on {verification.confirm_quantity}, "
        f"more than a third of the {error} it gives as the run's error on {verification.quantity} "
        f"(verified at {first} and {second}: {time})"
    )


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
