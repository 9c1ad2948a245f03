"""ballcage: rigid-body penalty-contact dynamics with Arrow/Parquet output.

The pipeline is scene → simulation → tables::

    import ballcage

    run = ballcage.simulate("examples/scenes/ball_drop.toml")
    run.bodies            # pyarrow.Table, one row per recorded body per frame
    run.write("out/")     # out/bodies.parquet, out/contacts.parquet, out/scene.toml

A scene is a TOML file, a dict of the same structure, or a `SceneBuilder`;
`load_scene` validates it (in Rust) and raises `SceneError` naming the field.
Every error ballcage raises is a `ballcage.Error`: `SceneError` (a scene field),
`SimulationError` (a run that diverged), `InputError` (a function argument),
`InternalError` (a bug: a Rust panic, caught), the studies' `StudyError`
and `SweepError`, `ballcage.verify.VerificationError` (a `SimulationError`)
and `ballcage.run.TimeLimitError` (a run past ``simulate(..., time_limit=)``).
``ballcage.simulate(scene, verify=True)`` repeats the run ten times tighter
and keeps the difference of each headline quantity as the run's measured
error, ``run.verification`` (``ballcage run --verify``; `ballcage.verify`);
``verify=2`` adds a run a hundred times tighter that checks the first.
All quantities are SI; units are in each output column's field metadata.

The paper's drill pipe is built in: `ballcage.scene.default_scene()` is its scene, and
`ballcage.paper.run_paper(dir)` runs it and writes the tables, the paper's
figures and a comparison with the paper's numbers (``ballcage paper``).
`ballcage.proposals()` is the registry of the values the paper does not give (PROPOSALs): each with its
default, plausible range and why, as a `pyarrow.Table` (docs/proposals.md).
`ballcage.sizing` is the paper's link-sizing eq. (9) both ways (``ballcage size``):
`longest_link`, `tightest_radius_for_link`, `largest_link_diameter`.
`ballcage.studies.accuracy` and `ballcage.studies.stability` measure what
each integrator's step costs in error and where it stops being stable
(``ballcage accuracy``, ``ballcage stability``); ``ballcage.sensitivity(scene, out)``
measures how much each unstated parameter moves each headline quantity
(``ballcage sensitivity``, `ballcage.studies.sensitivity_run`).
"""

import importlib as _importlib
import warnings as _warnings
from typing import Any as _Any

from ballcage import _native
from ballcage._native import (
    Error,
    InputError,
    InternalError,
    Scene,
    SceneError,
    Simulation,
    SimulationError,
    table_schema,
)
from ballcage import run as _run
from ballcage import verify as _verify
from ballcage.buckling import buckling
from ballcage.run import Run, simulate
from ballcage.scene import DrillPipeBuilder, SceneBuilder, load_scene, proposals
from ballcage.sizing import largest_link_diameter, longest_link, tightest_radius_for_link

# `simulate(..., verify=True)` measures the run's error with `ballcage.verify`, which lies above
# `ballcage.run` (it takes a drill pipe's quantities from `ballcage.measures`): wired here, on top.
_run.VERIFIER = _verify.VERIFIER

__version__: str = _native.__version__

__all__ = [
    "DrillPipeBuilder",
    "Error",
    "InputError",
    "InternalError",
    "Run",
    "Scene",
    "SceneBuilder",
    "SceneError",
    "Simulation",
    "SimulationError",
    "__version__",
    "buckling",
    "largest_link_diameter",
    "load_scene",
    "longest_link",
    "proposals",
    "simulate",
    "table_schema",
    "tightest_radius_for_link",
]

_DEBUG_BUILD_MESSAGE = "ballcage was built without optimizations; runs are ~10x slower: pip install . builds release"


def _warn_if_debug_build(build_profile: str) -> None:
    """Warns once, at import, when the extension was compiled without optimizations."""
    if build_profile == "debug":
        _warnings.warn(_DEBUG_BUILD_MESSAGE, RuntimeWarning, stacklevel=3)


_warn_if_debug_build(_native.BUILD_PROFILE)


def __getattr__(name: str) -> _Any:
    """Imports `ballcage.paper` and `ballcage.studies` (and with them matplotlib) only when first used."""
    if name in ("paper", "studies"):
        return _importlib.import_module(f"ballcage.{name}")
    if name in ("longest_joint", "smallest_curvature_radius", "largest_joint_diameter"):
        # eq. (9)'s names of the previous release: deprecated (a DeprecationWarning when called)
        return getattr(_importlib.import_module("ballcage.sizing"), name)
    if name == "sweep":  # `ballcage.sweep(spec, out, client=...)`: ballcage.studies.sweep_run.sweep
        return _importlib.import_module("ballcage.studies.sweep_run").sweep
    if name == "sensitivity":  # `ballcage.sensitivity(scene, out, ...)`: ballcage.studies.sensitivity_run.sensitivity
        return _importlib.import_module("ballcage.studies.sensitivity_run").sensitivity
    raise AttributeError(f"module 'ballcage' has no attribute {name!r}")
