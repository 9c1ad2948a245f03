"""``ballcage stability``: the largest stable step of each integrator (`ballcage.studies.stability`, `write_stability`).

The ``--parameters`` names are `ballcage.studies.PARAMETER_NAMES`. That
package pulls in numpy, pyarrow and matplotlib, which the other commands do
not need to start, so it is imported only by the handler (which checks the
names) and by ``--help`` (which lists them).
"""

from __future__ import annotations

import argparse
import shlex

from ballcage import _native
from ballcage.cli._common import (
    DEFAULT_SCENE_NAME,
    PROG,
    Commands,
    UsageError,
    add_integrators_option,
    add_out_option,
    add_quiet_option,
    add_set_option,
    checked_out,
    checked_override,
    count,
    human_size,
    names,
    positive,
)

#: Options whose value may be a (wrong) negative number (`ballcage.cli` lets the option's check report it).
NUMBER_OPTIONS = ("--duration", "--values-per-parameter", "--bisections")
#: Stands for the parameter names in the ``--parameters`` help until it is shown (`_HelpFormatter`).
_NAMES = "{parameter_names}"


class _HelpFormatter(argparse.HelpFormatter):
    """Writes `ballcage.studies.PARAMETER_NAMES` into the help text when ``--help`` shows it."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = super()._get_help_string(action)
        if text is None or _NAMES not in text:
            return text
        from ballcage.studies import PARAMETER_NAMES  # deferred: numpy, pyarrow, matplotlib

        return text.replace(_NAMES, ",".join(PARAMETER_NAMES))


def add(commands: Commands) -> None:
    stability = commands.add_parser(
        "stability",
        help="largest stable step of each integrator against stiffness, speed, curvature, key mass, damping",
        description=(
            "For each integrator, find the largest step at which a short probe run finishes without a divergence "
            "error (bracketing by factors of 4, then bisection in log dt), varying one parameter at a time around "
            "the defaults: contact stiffness of the key and cage contacts (1e3-1e7 N/mm^2.2), drive speed "
            "(30-600 rpm), curvature radius (from the tightest the hinge allows, pitch / (2 sin(limit / 2)) = "
            "0.770 m for the paper's pipe, to 5 m), key mass (1/4-4x) and contact damping (0 and 0.1-100 N s/mm). "
            "The probe scene is the paper's drill pipe with pipe.joints = 2, 0.03 s simulated and the drive and "
            "load ramped in over 0.01 s (--set and --duration change it). Writes stability.parquet, "
            "stability_<parameter>.png heat maps (integrator x value, colour log10 max stable dt) and stability.md."
        ),
        formatter_class=_HelpFormatter,
    )
    add_out_option(stability)
    add_integrators_option(stability)
    stability.add_argument("--parameters", metavar="NAME,...", help=f"parameters to vary (default all: {_NAMES})")
    stability.add_argument(
        "--values-per-parameter",
        metavar="N",
        default="5",
        help="values of each parameter (default 5, at least 2)",
    )
    stability.add_argument("--duration", metavar="S", help="simulated duration of each probe [s] (default 0.03)")
    stability.add_argument(
        "--bisections",
        metavar="N",
        default="5",
        help="bisections after bracketing (default 5: the step is found to 4.4%%)",
    )
    stability.add_argument("--grid", action="store_true", help="also map every stiffness x speed pair (stability_grid.png)")
    add_set_option(stability, example="--set pipe.joints=3 --set 'pipe.hinge=\"ideal-cv\"'")
    add_quiet_option(stability, "no progress lines and no summary")
    stability.set_defaults(command=command)


def command(args: argparse.Namespace) -> int:
    from ballcage.studies import PARAMETER_NAMES, probe_scene, stability, write_stability  # deferred: numpy, matplotlib

    known = list(_native.INTEGRATORS)
    integrators = names("--integrators", args.integrators, known, "integrator") or known
    parameters = names("--parameters", args.parameters, PARAMETER_NAMES, "parameter")
    values = count("--values-per-parameter", args.values_per_parameter, 2)
    bisections = count("--bisections", args.bisections, 0)
    duration = positive("--duration", args.duration)
    overrides = [checked_override(o) for o in args.overrides]
    out = checked_out(args.out)
    try:
        scene = probe_scene(overrides, duration)
    except _native.SceneError as e:
        raise UsageError(f"{DEFAULT_SCENE_NAME}: {e}") from e
    table = stability(
        scene,
        parameters=parameters if parameters is not None else list(PARAMETER_NAMES),
        integrators=integrators,
        values_per_parameter=values,
        grid=args.grid,
        bisections=bisections,
        progress=not args.quiet,
    )
    paths = write_stability(table, out, command=shlex.join([PROG, *args.argv]))
    if not args.quiet:
        for path in paths.values():
            print(f"wrote {path}  ({human_size(path.stat().st_size)})")
    return 0
