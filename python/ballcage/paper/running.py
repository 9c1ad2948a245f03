"""Running the paper: the paper scene, its section-4 sweep, and `run_paper` writing everything."""

from __future__ import annotations

import os
import shlex
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ballcage import _native
from ballcage._files import write_parquet, write_text
from ballcage.duty import write_loss_figure
from ballcage.paper.compare import comparison, with_numerical_error, with_spread
from ballcage.paper.fatigue import fatigue_markdown, write_fatigue_or_why
from ballcage.paper.figures import write_figures
from ballcage.paper.markdown import comparison_markdown
from ballcage.paper.wear_map import wear_map_markdown, write_wear_map
from ballcage.run import VERIFY_FILE, Run, VerificationError, simulate_then
from ballcage.scene import default_scene, override_list
from ballcage.view import write_view

if TYPE_CHECKING:
    import pyarrow as pa

    from ballcage.paper.section4 import Section4
    from ballcage.studies.sensitivity_report import Spread
    from ballcage.studies.sweep_spec import SweepSpec

__all__ = ["PAPER_TABLES", "SENSITIVITY_FILE", "find_sensitivity", "paper_scene", "run_paper"]

#: The 3D view `run_paper` writes beside the figures (`ballcage view`), and its most frames (evenly spaced).
VIEW_FILE, VIEW_FRAMES = "chain.html", 120
#: Tables the paper run records.
PAPER_TABLES: tuple[str, ...] = ("bodies", "contacts", "summary", "links", "hinges", "keys", "drive", "pairs", "wear")
#: The loss breakdown `run_paper` writes beside the figures (`ballcage.duty.write_loss_figure`).
LOSS_FILE = "losses.png"
#: A sensitivity study's table (``ballcage sensitivity --out DIR``) that `run_paper` looks for in its folder.
SENSITIVITY_FILE = "sensitivity.parquet"


def run_paper(
    out_dir: str | os.PathLike[str],
    overrides: Iterable[str] = (),
    sweeps: bool = False,
    progress: bool | None = None,
    *,
    workers: int | None = None,
    client: Any = None,
    sensitivity: str | os.PathLike[str] | None = None,
    verify: bool | int = True,
) -> dict[str, Path]:
    """Runs the paper scene and writes tables, figures and the comparison into `out_dir`.

    `overrides` (``dotted.key=value``, on the drill-pipe TOML of
    `ballcage.scene.default_scene_toml`) apply to the main run and to every case of
    the section-4 sweep, whose own keys (curvature radius, drive speed) are
    applied last. `progress` is as for `ballcage.simulate` and `ballcage.sweep`.
    Every scene is validated before anything runs.

    With `sweeps`, the paper's §4.2–4.3 run as one sweep (`ballcage.paper.section4`)
    in `workers` local threads (default one per CPU) or on the Dask cluster of
    `client`, into ``out_dir/sweeps`` (resumed when run again); its finished
    cases fill the comparison's ``sweep_*`` rows, ``fig16_curvature.png`` and
    ``fig17_speed.png``, and ``trends.parquet`` checks each ``[[trend]]`` of
    the reference file, also listed in ``comparison.md``.

    Returns the written paths: one per table (``"bodies"``, …), ``"scene"``, one per figure
    (``"fig09_included_angles"``, …), ``"losses"`` (``losses.png``, `ballcage.duty`), ``"fatigue"`` and
    ``"fatigue_figure"`` (`ballcage.measures.fatigue`), ``"wear_map"`` and ``"wear_map_figure"``
    (`ballcage.measures.wear_map`), ``"view"`` (``chain.html``, `ballcage.view`), ``"verify"``, ``"comparison"``,
    ``"comparison_md"`` and, with `sweeps`, ``"sweeps"`` (the sweep folder), ``"fig16_curvature"``,
    ``"fig17_speed"``, ``"losses_curvature"`` and ``"trends"``.

    With a sensitivity study (`sensitivity`, the path of its ``sensitivity.parquet``; default
    ``out_dir/sensitivity.parquet`` when it exists, `find_sensitivity`), every comparison row gains the range of
    its quantity over the study's runs and the parameter with the largest effect
    (`ballcage.paper.compare.with_spread`; null, "—" in ``comparison.md``, where the study has no such quantity).

    With `verify` the run is repeated ten times tighter (``ballcage run --verify``), and every row gains its
    measured numerical error (`ballcage.paper.compare.with_numerical_error`); ``verify=2`` also a hundred times
    tighter, which confirms each row's error or not. If a verification run fails, the rest is written and its
    `ballcage.run.VerificationError` raised last, the written paths as ``e.written``. Raises
    `ballcage.SceneError` for an invalid override, `ballcage.InputError` for a
    sensitivity table that cannot be read, and `ballcage.SimulationError`
    when the main run diverges (a sweep case that diverges is recorded in the
    sweep's summary and its rows stay empty).
    """
    from ballcage.paper.section4 import section4_spec  # deferred: the sweep machinery imports this package
    from ballcage.studies.sweep_spec import with_verification

    user = override_list(overrides)
    out = Path(out_dir)
    study = find_sensitivity(out, sensitivity)
    spread = _read_spread(study) if study is not None else None  # before the run: a bad file fails at once
    main_scene = paper_scene(user)
    spec = section4_spec(user) if sweeps else None
    if spec is not None:
        spec.check()
        if verify:  # each case again ten times tighter: the trends weigh their changes against that error
            spec = with_verification(spec)
    run, written, derived, failure = _run_and_write(main_scene, out, progress, verify)
    section4 = _run_section4(out, spec, written, client, workers, progress) if spec is not None else None
    sweep_runs = section4[0].variant_runs() if section4 is not None else None
    table = with_numerical_error(comparison(run, sweep_runs), run.verification)
    if spread is not None:
        table = with_spread(table, *spread)
    written["comparison"] = write_parquet(table, out / "comparison.parquet")
    md = comparison_markdown(
        table,
        command=_command_line(out, user, sweeps, sensitivity, verify),
        run=run,
        sweep_runs=sweep_runs,
        section4=(section4[0].summary, section4[1]) if section4 is not None else None,
        unverified=str(failure) if failure is not None else None if verify else "not measured (--no-verify)",
    )
    written["comparison_md"] = write_text(md + derived, out / "comparison.md")
    if failure is not None:
        failure.written = written  # type: ignore[attr-defined]
        raise failure
    return written


def _run_and_write(
    scene: _native.Scene, out: Path, progress: bool | None, verify: bool | int
) -> tuple[Run, dict[str, Path], str, VerificationError | None]:
    """The paper run, its tables and `_write_derived`'s files, written while its verification run goes on
    (`simulate_then`), and ``verify.parquet``; returns the run, the written paths, the derived Markdown and a
    failed verification (not raised)."""

    def write(run: Run) -> tuple[dict[str, Path], str]:
        written = run.write(out)  # without verify.parquet: the verification is not done yet
        return written, _write_derived(run, out, written)

    try:
        run, (written, derived) = simulate_then(scene, write, progress=progress, verify=verify)
    except VerificationError as e:
        return e.run, *e.done, e  # type: ignore[attr-defined]
    if run.verification is not None:
        written["verify"] = write_parquet(run.verification.table, out / VERIFY_FILE)
    return run, written, derived, None


def _write_derived(run: Run, out: Path, written: dict[str, Path]) -> str:
    """The figures, loss figure, fatigue table, wear map and 3D view of `run` into `out` (and `written`); returns
    the Markdown of the wear map and fatigue table for ``comparison.md``."""
    written.update(write_figures(run, out))
    written["losses"] = write_loss_figure(run.tables["wear"], out / LOSS_FILE)
    fatigue = write_fatigue_or_why(run, out, written)
    wear_map, wear_paths = write_wear_map(run, out)
    written.update(wear_paths)
    written["view"] = write_view(run, out / VIEW_FILE, frames=VIEW_FRAMES)
    spot = [r["hours_per_100um"] for r in run.tables["wear"].to_pylist() if r["hours_per_100um"] is not None]
    return wear_map_markdown(wear_map, min(spot) if spot else None) + fatigue_markdown(fatigue)


def _run_section4(
    out: Path, spec: SweepSpec, written: dict[str, Path], client: Any, workers: int | None, progress: bool | None
) -> tuple[Section4, pa.Table]:
    """Runs the section-4 sweep into ``out/sweeps``, writes Figures 16–17 and ``trends.parquet`` (into `written`)."""
    from ballcage.paper.section4 import run_section4
    from ballcage.paper.section4_figures import write_section4_figures
    from ballcage.paper.trends import trend_table

    if progress is not False:
        print("ballcage: the paper's section 4 (curvature and speed) as a sweep", file=sys.stderr, flush=True)
    section4 = run_section4(out / "sweeps", spec, client=client, workers=workers, progress=progress)
    written["sweeps"] = out / "sweeps"
    written.update(write_section4_figures(section4.curvature_runs(), section4.speed_runs(), out))
    trends = trend_table(section4.summary, section4.other_windows())
    written["trends"] = write_parquet(trends, out / "trends.parquet")
    return section4, trends


def find_sensitivity(out: Path, given: str | os.PathLike[str] | None) -> Path | None:
    """The sensitivity table for the comparison: `given` (which must exist), else ``out/sensitivity.parquet`` if any."""
    if given is not None:
        path = Path(given)
        if not path.is_file():
            raise _native.InputError(f"sensitivity = {str(path)!r}: no such file (a sensitivity.parquet of "
                                     "ballcage sensitivity)")
        return path
    path = out / SENSITIVITY_FILE
    return path if path.is_file() else None


def _read_spread(path: Path) -> tuple[dict[str, Spread], dict[str, str]]:
    """The spreads of the sensitivity table at `path` and the metadata the comparison keeps of it."""
    from ballcage.studies.common import study_meta
    from ballcage.studies.sensitivity_report import read_sensitivity, spreads

    table = read_sensitivity(path)
    meta = {k: v for k, v in study_meta(table).items() if k.startswith("ballcage.sensitivity.")}
    meta["ballcage.sensitivity.source"] = str(path)
    return spreads(table), meta


def paper_scene(overrides: Iterable[str] = ()) -> _native.Scene:
    """The paper's scene as `run_paper` runs it: the default scene recording `PAPER_TABLES`, then `overrides`.

    Raises `ballcage.SceneError` for an invalid override or a ``record.tables``
    override that drops a table the analysis needs.
    """
    record = "record.tables=[" + ", ".join(f'"{t}"' for t in PAPER_TABLES) + "]"
    scene = default_scene([record, *override_list(overrides)])
    missing = [t for t in PAPER_TABLES if t not in scene.table_names]
    if missing:
        reason = f"must include {', '.join(missing)} for the paper's figures and comparison"
        error = _native.SceneError(f"scene field `record.tables` = {scene.table_names}: {reason}")
        error.path, error.value, error.reason = "record.tables", str(scene.table_names), reason
        error.errors = [(error.path, error.value, reason)]
        raise error
    return scene


def _command_line(
    out: Path, overrides: Sequence[str], sweeps: bool, sensitivity: str | os.PathLike[str] | None, verify: bool | int
) -> str:
    args = ["ballcage", "paper", "--out", str(out)]
    for o in overrides:
        args += ["--set", o]
    if sweeps:
        args.append("--sweeps")
    if sensitivity is not None:
        args += ["--sensitivity", os.fspath(sensitivity)]
    if not verify:
        args.append("--no-verify")
    elif verify == 2:
        args += ["--verify", "2"]
    return shlex.join(args)
