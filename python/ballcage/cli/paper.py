"""``ballcage paper``: the paper's scene with every table, its figures and a comparison (`ballcage.paper.run_paper`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ballcage import _native
from ballcage.cli._common import (
    DEFAULT_SCENE_NAME,
    Commands,
    UsageError,
    add_out_option,
    add_quiet_option,
    add_set_option,
    checked_out,
    checked_override,
    fail,
    human_size,
    workers,
)


def add(commands: Commands) -> None:
    paper = commands.add_parser(
        "paper",
        help="run the paper's scene; write tables, the paper's figures and a comparison",
        description=(
            "Run the embedded paper scene (Zhu et al., Machines 2023) recording every table; write "
            "<table>.parquet, scene.toml, the figures fig09-fig13 and table3_shape as PNG, and "
            "comparison.parquet / comparison.md against the paper's numbers, each row with its measured numerical "
            "error (the run repeated ten times tighter, as ballcage run --verify: verify.parquet). The full run "
            "takes minutes."
        ),
    )
    add_out_option(paper)
    add_set_option(paper, example="--set simulation.duration=0.2 --set drive.speed_rpm=60")
    paper.add_argument(
        "--sweeps",
        action="store_true",
        help="also run the paper's section 4 as a sweep into DIR/sweeps (R = 1.0-2.5 m at 100 rpm, 60-120 rpm at "
        "1.5 m, and the baseline with R +-1 um for the run-to-run spread: 9 runs, and unless --no-verify each again "
        "ten times tighter for its numerical error; resumed when run again); fill the sweep rows, draw Figures 16-17 "
        "and check the paper's trends against the spread and the numerical error (trends.parquet)",
    )
    paper.add_argument("--workers", metavar="N", type=workers, help="with --sweeps: local threads (default: one per CPU)")
    paper.add_argument(
        "--scheduler", metavar="ADDRESS", help="with --sweeps: run the sweep on the Dask cluster at ADDRESS; needs ballcage[dask]"
    )
    paper.add_argument(
        "--sensitivity", metavar="PATH", type=Path,
        help="a sensitivity.parquet of ballcage sensitivity (default: DIR/sensitivity.parquet when it exists): every "
        "comparison row gains the range of its quantity over the unstated parameters and the dominant parameter",
    )  # fmt: skip
    paper.add_argument(
        "--no-verify", action="store_true",
        help="do not repeat the run ten times tighter: the comparison's numerical error column stays empty",
    )  # fmt: skip
    paper.add_argument(
        "--verify", type=int, choices=(1, 2), default=None, metavar="RUNS",
        help="verification runs (default 1: the run ten times tighter, each row's numerical error); 2 adds a run a "
        "hundred times tighter that confirms each row's error or not, as ballcage run --verify 2",
    )  # fmt: skip
    add_quiet_option(paper, "no progress bar and no summary")
    paper.set_defaults(command=command)


def command(args: argparse.Namespace) -> int:
    from ballcage.paper import run_paper  # deferred: imports matplotlib
    from ballcage.paper.running import find_sensitivity

    from ballcage.studies.sweep_run import scheduler_client
    from ballcage.studies.sweep_spec import SweepError
    from ballcage.verify import VerificationError

    overrides = [checked_override(o) for o in args.overrides]
    out = checked_out(args.out)
    if (args.workers or args.scheduler) and not args.sweeps:
        raise UsageError(f"--{'workers' if args.workers else 'scheduler'}: only with --sweeps (it sets where the sweep runs)")
    if args.sensitivity is not None and not args.sensitivity.is_file():
        raise UsageError(f"--sensitivity {args.sensitivity}: no such file (give the sensitivity.parquet of ballcage "
                         "sensitivity)")
    study = find_sensitivity(out, args.sensitivity)
    failure = None
    try:
        with scheduler_client(args.scheduler) as client:
            paths = run_paper(
                out, overrides, sweeps=args.sweeps, progress=False if args.quiet else None, workers=args.workers,
                client=client, sensitivity=args.sensitivity, verify=_verification_runs(args),
            )
    except VerificationError as e:
        failure, paths = e, e.written  # type: ignore[attr-defined]  # run_paper wrote everything else
    except _native.SceneError as e:
        raise UsageError(f"{DEFAULT_SCENE_NAME}: {e}") from e
    except SweepError as e:
        raise UsageError(str(e)) from e
    if not args.quiet:
        for name, path in paths.items():
            print(_summary(name, path))
        if study is not None:
            print(f"ballcage: the comparison shows the spread over the unstated parameters of {study}")
        if "verify" in paths:
            print(f"ballcage: {_verdict(paths['verify'])}")
        note = _fallback_note(paths)
        if note is not None:  # last: a run with fallback steps says so in its last line
            print(f"ballcage: warning: {note}")
    if failure is not None:
        return fail(f"{failure}; the report in {out} is complete without the numerical error column", 1)
    return 0


def _verification_runs(args: argparse.Namespace) -> int:
    """`run_paper`'s `verify` from ``--verify RUNS`` and ``--no-verify``."""
    if args.no_verify and args.verify is not None:
        raise UsageError(f"--verify {args.verify} and --no-verify: choose one")
    return 0 if args.no_verify else args.verify or 1


def _verdict(path: Path) -> str:
    """The line ``ballcage run --verify`` ends with, from the ``verify.parquet`` at `path`."""
    import pyarrow.parquet as pq

    from ballcage.verify import verdict, verification_of

    return verdict(verification_of(pq.read_table(path)))


def _fallback_note(paths: dict[str, Path]) -> str | None:
    """The main run's fallback sentence (`Run.fallback_note`), from the metadata of one of its tables."""
    import pyarrow.parquet as pq

    from ballcage.run import Run

    table = next((p for n, p in paths.items() if n in ("links", "drive", "bodies") and p.suffix == ".parquet"), None)
    if table is None:
        return None
    schema = pq.read_schema(table)
    return Run({table.stem: schema.empty_table()}, "").fallback_note


def _summary(name: str, path: Path) -> str:
    if path.is_dir():
        return f"wrote {path}/  (the section-4 sweep: summary.parquet, the cases' tables, plots/)"
    if path.suffix == ".parquet":
        import pyarrow.parquet as pq

        meta = pq.ParquetFile(path).metadata
        return f"wrote {path}  ({meta.num_rows} rows x {meta.num_columns} columns, {human_size(path.stat().st_size)})"
    what = {"scene": "resolved scene", "comparison_md": "comparison and trends", "view": "3D view, `ballcage view`"}.get(
        name, "figure" if path.suffix == ".png" else name
    )
    return f"wrote {path}  ({what}, {human_size(path.stat().st_size)})"
