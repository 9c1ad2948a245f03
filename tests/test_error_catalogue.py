"""The catalogue of bad inputs: every entry exits with code 2 and one line naming the field, with no output left.

Each entry is a real ``python -m ballcage`` subprocess (run in parallel, two
at a time) given one bad input: a scene field out of range or of the wrong
type, a misspelt key or name (answered with "did you mean …?"), a chain that
cannot fit or bend, a bad option, a bad sweep file. The expected text is
what must appear in the one line: the field's path, and for a slip the word
it should have been. ``python tests/test_error_catalogue.py`` prints the
catalogue with each message as Markdown (docs/reliability.md).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
BALL_DROP = str(REPO / "examples" / "scenes" / "ball_drop.toml")


@dataclass(frozen=True)
class Entry:
    """One bad input: the CLI arguments (``{out}`` and ``{tmp}`` filled in) and text the error line must hold."""

    what: str
    args: tuple[str, ...]
    expect: tuple[str, ...]


def _set(what: str, override: str, *expect: str) -> Entry:
    """`ballcage run` of the paper scene with one ``--set``."""
    return Entry(what, ("run", "--out", "{out}", "--set", override), expect or (override.split("=")[0],))


def _fixed(what: str, override: str, *expect: str) -> Entry:
    """`ballcage run` of the paper scene at fixed steps of SDIRK2 (``simulation.rtol = 0``) with one ``--set``."""
    args = ("run", "--out", "{out}", "--set", 'simulation.integrator="sdirk2"', "--set", "simulation.rtol=0")
    return Entry(what, (*args, "--set", override), expect or (override.split("=")[0],))


CATALOGUE: tuple[Entry, ...] = (
    # misspelt keys and names: the nearest valid one is suggested
    _set("misspelt pipe key", "pipe.jionts=3", "pipe.jionts", "did you mean `joints`?"),
    _set("misspelt simulation key", "simulation.duraton=1", "did you mean `duration`?"),
    _set("misspelt integrator", 'simulation.integrator="sdirk"', "did you mean `sdirk2`?"),
    _set("misspelt hinge model", 'pipe.hinge="ball-key"', "did you mean `ball-keys`?"),
    _set("misspelt table name", 'record.tables=["link"]', "record.tables[0]", "did you mean `links`?"),
    _set("misspelt contact law", 'materials.tube.normal.law="impcat"', "did you mean `impact`?"),
    _set("misspelt friction key", "materials.tube.friction.mu_statc=0.2", "did you mean `mu_static`?"),
    _set("unknown section", "motor.speed=3", "motor"),
    # wrong types
    _set("text for a number", 'drive.speed_rpm="fast"', "drive.speed_rpm", "expected a number"),
    _set("fraction for a count", "pipe.joints=2.5", "pipe.joints"),
    _set("negative count", "pipe.joints=-3", "pipe.joints"),
    _set("two inertias for three", "pipe.link_inertia=[1.0, 2.0]", "pipe.link_inertia", "length 3"),
    _set("text for a list", 'record.summary_window="late"', "record.summary_window"),
    # ranges: simulation
    _set("zero step", "simulation.dt=0", "simulation.dt", "must be positive"),
    _set("negative step", "simulation.dt=-1e-4", "simulation.dt"),
    _set("zero duration", "simulation.duration=0", "simulation.duration"),
    _set("NaN duration", "simulation.duration=nan", "simulation.duration"),
    _fixed("output interval not a whole number of steps", "simulation.output_interval=0.00015", "whole multiple"),
    _fixed("a 1 ns step: too many steps", "simulation.dt=1e-9", "simulation.dt", "simulation.max_steps"),
    _set("a negative largest adaptive step", "simulation.max_step=-0.001", "simulation.max_step", "positive"),
    _set("a negative tolerance", "simulation.rtol=-1e-4", "simulation.rtol", "≥ 0"),
    _set("a tolerance for an integrator without an error estimate", 'simulation.integrator="rk4"', "simulation.rtol = 0"),
    _set("zero step limit", "simulation.max_steps=0", "simulation.max_steps"),
    _set("zero Newton tolerance", "simulation.newton.tolerance=0", "simulation.newton.tolerance"),
    _set("no Newton iterations", "simulation.newton.max_iterations=0", "simulation.newton.max_iterations"),
    _set("zero divergence fraction", "simulation.divergence.penetration_fraction=0", "penetration_fraction"),
    _set("infinite gravity", "world.gravity=inf", "world.gravity"),
    # ranges and geometry: the borehole and the chain
    _set("zero curvature radius", "borehole.curvature_radius=0", "borehole.curvature_radius"),
    _set("bend past the articulation limit", "borehole.curvature_radius=0.5", "borehole.curvature_radius",
         "articulation limit"),
    _set("link wider than the tube", "borehole.inner_diameter=0.08", "pipe.link_diameter"),
    _set("build angle over 180", "borehole.build_angle_deg=200", "borehole.build_angle_deg"),
    _set("zero pitch", "pipe.pitch=0", "pipe.pitch"),
    _set("link too long for the bend", "pipe.pitch=3.5", "borehole.curvature_radius"),
    _set("no joints", "pipe.joints=0", "pipe.joints"),
    _set("1e8 joints", "pipe.joints=100000000", "pipe.joints"),
    _set("massless link", "pipe.link_mass=0", "mass", "must be positive"),
    _set("negative link inertia", "pipe.link_inertia=[-1.0, 1.0, 1.0]", "inertia"),
    _set("negative connector mass", "pipe.connector_mass=-1", "mass"),
    _set("neck wider than the seat's mouth", "pipe.neck_radius=0.05", "pipe.neck_radius"),
    _set("no tube contact points", "pipe.tube_contact_points=0", "points"),
    _set("negative drive ramp", "drive.ramp=-1", "drive.ramp"),
    _set("infinite resisting moment", "load.resisting_moment=inf", "load.resisting_moment"),
    _set("negative load ramp", "load.ramp=-0.3", "load.ramp"),
    # ranges and geometry: the hinge
    _set("negative ball radius", "pipe.ball_keys.ball_radius=-0.001", "pipe.ball_keys.ball_radius"),
    _set("ball wider than its window", "pipe.ball_keys.ball_radius=0.02", "must exceed the ball radius"),
    _set("groove narrower than the ball", "pipe.ball_keys.groove_radius=0.005", "pipe.ball_keys.groove_radius"),
    _set("contact angle past 90 degrees", "pipe.ball_keys.contact_angle_deg=95", "pipe.ball_keys.contact_angle_deg"),
    _set("cage inside the head", "pipe.ball_keys.cage_inner_radius=0.029", "head_radius < cage_inner_radius"),
    _set("head larger than the cage", "pipe.ball_keys.head_radius=0.04", "pipe.ball_keys.head_radius"),
    _set("negative flank clearance", "pipe.ball_keys.flank_clearance=-1e-5", "pipe.ball_keys.flank_clearance"),
    _set("window narrower than the ball", "pipe.ball_keys.window_axial_width=0.01", "half_width"),
    _set("massless ball", "pipe.ball_keys.ball_mass=0", "pipe.ball_keys.ball_mass"),
    _set("negative CV stiffness", "pipe.ideal_cv.stiffness=-1", "pipe.ideal_cv.stiffness"),
    # contact laws
    _set("zero contact stiffness", "materials.tube.normal.stiffness=0", "stiffness"),
    _set("negative exponent", "materials.tube.normal.exponent=-1", "exponent"),
    _set("negative damping", "materials.tube.normal.damping=-1", "damping"),
    _set("zero damping depth", "materials.tube.normal.depth_max=0", "depth_max"),
    _set("negative friction", "materials.tube.friction.mu_static=-0.1", "mu_static"),
    _set("dynamic above static friction", "materials.tube.friction.mu_dynamic=0.5", "mu_dynamic", "mu_static = 0.3"),
    _set("transition speeds in the wrong order", "materials.tube.friction.v_dynamic=50", "v_dynamic"),
    _set("zero stiction speed", "materials.internal.friction.v_static=0", "v_static"),
    # recording
    _set("summary window backwards", "record.summary_window=[1.0, 0.5]", "record.summary_window[1]"),
    _set("summary window past the run", "record.summary_window=[0.0, 5.0]", "simulation.duration"),
    _set("record an unknown body", 'record.bodies=["nope"]', "record.bodies[0]"),
    _set("a table listed twice", 'record.tables=["links", "links"]', "listed twice"),
    _set("tables over the memory budget", "record.max_bytes=1000000", "record.max_bytes", "frames", "contacts"),
    _set("zero memory budget", "record.max_bytes=0", "record.max_bytes", "at least 1"),
    # several errors at once: all in the one line
    Entry("three errors in one scene", ("run", "--out", "{out}", "--set", "pipe.jionts=3", "--set",
                                        'simulation.dt="x"', "--set", "drive.speed_rpmm=5"),
          ("pipe.jionts", "simulation.dt", "drive.speed_rpmm")),
    # generic scenes, files and options
    Entry("negative mass in a scene file", ("run", BALL_DROP, "--out", "{out}", "--set", "bodies[1].mass=-2"),
          ("bodies[1].mass", "must be positive")),
    Entry("misspelt body key", ("run", BALL_DROP, "--out", "{out}", "--set", "bodies[0].mas=3"),
          ("did you mean `mass`?",)),
    Entry("TOML syntax error", ("run", "{tmp}/broken.toml", "--out", "{out}"), ("TOML syntax error at line 2",)),
    Entry("scene file missing", ("run", "{tmp}/nothing.toml", "--out", "{out}"), ("nothing.toml",)),
    Entry("--set without a value", ("run", "--out", "{out}", "--set", "pipe.joints"), ("pipe.joints",)),
    Entry("unknown table option", ("run", "--out", "{out}", "--tables", "links,nope"), ("nope",)),
    Entry("sweep file with an unknown section", ("sweep", "{tmp}/bad_sweep.toml", "--out", "{out}"),
          ("unknown section [grids]",)),
    Entry("size with a negative radius", ("size", "--radius", "-1500", "--tube-id", "116", "--joint-od", "86"),
          ("--radius",)),
    Entry("chart with a joint wider than the tube", ("chart", "--out", "{out}", "--joint-od", "120"), ("--joint-od",)),
    Entry("paper --workers without --sweeps", ("paper", "--out", "{out}", "--workers", "2"), ("--workers",)),
)

#: Files the catalogue's entries read: a scene with a syntax error and a sweep file with an unknown section.
FIXTURES = {
    "broken.toml": "[simulation]\nduration = = 1\n",
    "bad_sweep.toml": '[grids]\n"drive.speed_rpm" = [60, 100]\n',
}


def _run(entry: Entry, tmp: Path) -> subprocess.CompletedProcess[str]:
    out = tmp / "out"
    args = [a.replace("{out}", str(out)).replace("{tmp}", str(tmp)) for a in entry.args]
    return subprocess.run([sys.executable, "-m", "ballcage", *args], capture_output=True, text=True, timeout=120, cwd=tmp)


def _fixtures(tmp: Path) -> Path:
    for name, text in FIXTURES.items():
        (tmp / name).write_text(text, encoding="utf-8")
    return tmp


@pytest.fixture(scope="module")
def results(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[subprocess.CompletedProcess[str], Path]]:
    tmps = {e.what: _fixtures(tmp_path_factory.mktemp("entry")) for e in CATALOGUE}
    with ThreadPoolExecutor(max_workers=2) as pool:
        done = dict(zip(tmps, pool.map(lambda e: _run(e, tmps[e.what]), CATALOGUE), strict=True))
    return {what: (done[what], tmps[what]) for what in tmps}


def test_the_catalogue_has_at_least_fifty_distinct_entries() -> None:
    assert len(CATALOGUE) >= 50
    assert len({e.what for e in CATALOGUE}) == len(CATALOGUE)
    assert len({e.args for e in CATALOGUE}) == len(CATALOGUE)


@pytest.mark.parametrize("entry", CATALOGUE, ids=[e.what for e in CATALOGUE])
def test_each_bad_input_is_one_line_with_exit_code_2_and_leaves_no_output(entry: Entry, results) -> None:
    result, tmp = results[entry.what]
    assert result.returncode == 2, (result.returncode, result.stderr)
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("ballcage: error: "), result.stderr
    for text in entry.expect:
        assert text in lines[0], (text, lines[0])
    assert result.stdout == ""
    out = tmp / "out"
    assert not out.exists() or not any(out.rglob("*")), sorted(out.rglob("*"))


def main() -> int:
    """Prints the catalogue as a Markdown table: what, command and the error line."""
    with tempfile.TemporaryDirectory() as name:
        print("| # | bad input | command | exit | message |")
        print("|---:|---|---|---:|---|")
        for i, entry in enumerate(CATALOGUE, start=1):
            tmp = Path(name) / f"e{i}"
            tmp.mkdir()
            result = _run(entry, _fixtures(tmp))
            command = " ".join(["ballcage", *entry.args]).replace("{out}", "OUT").replace("{tmp}/", "")
            command = command.replace(str(REPO) + "/", "")
            message = result.stderr.strip().replace("|", "\\|").replace(str(tmp) + "/", "")
            print(f"| {i} | {entry.what} | `{command}` | {result.returncode} | {message} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
