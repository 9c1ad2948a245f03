"""Running the paper: the paper scene and its sweep variants, and `run_paper` writing everything."""

from __future__ import annotations

import os
import shlex
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path

from ballcage import _native
from ballcage._files import write_parquet, write_text
from ballcage.paper.compare import comparison
from ballcage.paper.definitions import SWEEPS
from ballcage.paper.figures import write_figures
from ballcage.paper.markdown import comparison_markdown
from ballcage.run import Run, simulate
from ballcage.scene import default_scene

__all__ = ["PAPER_TABLES", "SWEEP_TABLES", "paper_scene", "run_paper"]

#: Tables the paper run records.
PAPER_TABLES: tuple[str, ...] = ("bodies", "contacts", "summary", "links", "hinges", "keys", "drive")
#: Tables the sweep variants record (enough for their comparison rows).
SWEEP_TABLES: tuple[str, ...] = ("links", "keys")


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
    main_scene = paper_scene(user)
    variants = {vid: paper_scene(user, sweep=vid) for vid in SWEEPS} if sweeps else {}

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
    written["comparison"] = write_parquet(table, out / "comparison.parquet")
    md = comparison_markdown(table, command=_command_line(out, user, sweeps), run=run, sweep_runs=sweep_runs)
    written["comparison_md"] = write_text(md, out / "comparison.md")
    return written


def paper_scene(overrides: Iterable[str] = (), sweep: str | None = None) -> _native.Scene:
    """The paper's scene as `run_paper` runs it: the default scene recording `PAPER_TABLES`, then
    `overrides`; for a `sweep` id of `SWEEPS`, recording `SWEEP_TABLES` with that variant's key last.

    Raises `ballcage.SceneError` for an invalid override or a ``record.tables``
    override that drops a table the analysis needs, and `ValueError` for an
    unknown `sweep`.
    """
    if isinstance(overrides, str):
        raise TypeError("overrides is a list of 'key=value' strings, not one string")
    if sweep is not None and sweep not in SWEEPS:
        raise ValueError(f"sweep = {sweep!r}: not a sweep variant ({', '.join(SWEEPS)})")
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
