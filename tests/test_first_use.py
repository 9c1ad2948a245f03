"""First use without surprises: engineering tables by default, ``--tables``, ``scene show`` with units,
TOML syntax errors with line and column, the phase list once in comparison.md, a legible Fig. 9."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pyarrow.parquet as pq
import pytest

import ballcage
from ballcage import _native
from ballcage.scene import default_scene

BALL_DROP = Path(__file__).resolve().parent.parent / "examples" / "scenes" / "ball_drop.toml"
#: A drill-pipe run of a few seconds: the reduced hinge model, 10 ms.
QUICK = ["--set", "simulation.duration=0.01", "--set", 'pipe.hinge="ideal-cv"', "--quiet"]
#: What `ballcage run` records for a drill-pipe scene that does not choose (besides bodies and contacts).
ENGINEERING = {"links", "hinges", "keys", "drive", "summary", "pairs", "wear"}


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "ballcage", *args], capture_output=True, text=True, timeout=300)


#: Files a run derives from its tables (the wear map, the fatigue table), not recorded tables.
DERIVED = {"wear_map", "fatigue"}


def _tables(out: Path) -> set[str]:
    return {p.stem for p in out.glob("*.parquet")} - DERIVED


# --------------------------------------------------------------------------- tables


def test_run_records_the_engineering_tables_of_a_drill_pipe_by_default(tmp_path):
    out = tmp_path / "out"
    proc = _cli("run", "--out", str(out), *QUICK)
    assert proc.returncode == 0, proc.stderr
    assert _tables(out) == {"bodies", "contacts"} | ENGINEERING
    assert (out / "wear_map.parquet").is_file() and (out / "wear_map.png").is_file()  # derived from those tables
    links = pq.read_table(out / "links.parquet")
    assert set(links.column("link").to_pylist()) == set(range(1, 13)) and links.num_rows > 0
    assert pq.read_table(out / "drive.parquet").num_rows == round(0.01 / 1e-3) + 1
    # The written scene says what was recorded, so it reruns the same.
    scene = tomllib.loads((out / "scene.toml").read_text(encoding="utf-8"))
    assert set(scene["record"]["tables"]) == _tables(out)
    # The default is the scene's, so Python records the same.
    assert set(ballcage.load_scene({"kind": "drill-pipe"}).table_names) == _tables(out)


def test_tables_option_chooses_the_tables(tmp_path):
    out = tmp_path / "out"
    proc = _cli("run", "--out", str(out), "--tables", "links,drive", *QUICK)
    assert proc.returncode == 0, proc.stderr
    assert _tables(out) == {"links", "drive"}
    generic = tmp_path / "generic"
    proc = _cli("run", str(BALL_DROP), "--out", str(generic), "--tables", "energy", "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert _tables(generic) == {"energy"}


def test_a_scene_file_that_chooses_its_tables_keeps_them_unless_tables_is_given(tmp_path):
    chosen = tmp_path / "chosen.toml"
    chosen.write_text('kind = "drill-pipe"\n[record]\ntables = ["links"]\n', encoding="utf-8")
    silent = tmp_path / "silent.toml"
    silent.write_text('kind = "drill-pipe"\n[drive]\nspeed_rpm = 60.0\n', encoding="utf-8")
    for path, expected in ((chosen, {"links"}), (silent, {"bodies", "contacts"} | ENGINEERING)):
        out = tmp_path / path.stem
        proc = _cli("run", str(path), "--out", str(out), *QUICK)
        assert proc.returncode == 0, proc.stderr
        assert _tables(out) == expected, path.name
    out = tmp_path / "override"
    proc = _cli("run", str(chosen), "--out", str(out), "--tables", "drive", *QUICK)
    assert proc.returncode == 0, proc.stderr
    assert _tables(out) == {"drive"}
    # --set record.tables is the scene's choice too.
    out = tmp_path / "set"
    proc = _cli("run", "--out", str(out), "--set", 'record.tables=["hinges"]', *QUICK)
    assert proc.returncode == 0, proc.stderr
    assert _tables(out) == {"hinges"}
    # A generic scene records what it says.
    out = tmp_path / "generic"
    assert _cli("run", str(BALL_DROP), "--out", str(out), "--quiet").returncode == 0
    assert _tables(out) == {"bodies", "contacts"}


def test_an_unknown_table_name_exits_2_naming_it_and_the_known_ones(tmp_path):
    proc = _cli("run", "--out", str(tmp_path / "out"), "--tables", "links,link", *QUICK)
    assert proc.returncode == 2
    line = proc.stderr.strip()
    assert proc.stderr.count("\n") == 1 and line.startswith("ballcage: error: --tables link: unknown table")
    assert ", ".join(_native.TABLE_NAMES) in line
    assert not (tmp_path / "out").exists()
    # A table the scene kind does not have: exit 2, naming --tables.
    proc = _cli("run", str(BALL_DROP), "--out", str(tmp_path / "g"), "--tables", "links")
    assert proc.returncode == 2 and "--tables links" in proc.stderr and "links" in proc.stderr


def test_run_help_says_how_to_choose_tables():
    proc = _cli("run", "--help")
    assert proc.returncode == 0
    text = " ".join(proc.stdout.split())
    assert "--tables NAME,..." in text
    assert "links, hinges, keys, drive, summary, pairs and wear" in text
    assert ", ".join(_native.TABLE_NAMES) in text


# --------------------------------------------------------------------------- scene show


def _numeric_lines(text: str) -> list[str]:
    """Lines that set a number or an array of numbers (``key = 1.5``, ``key = [`` followed by a number)."""
    lines = text.splitlines()
    found = []
    for i, line in enumerate(lines):
        if line.startswith((" ", "[", "]", "#")) or " = " not in line:
            continue
        value = line.split(" = ", 1)[1].split("  #")[0]
        following = lines[i + 1].strip() if i + 1 < len(lines) else ""
        if re.match(r"[-0-9]", value) or (value == "[" and re.match(r"[-0-9]", following)):
            found.append(line)
    return found


@pytest.mark.parametrize("hinge", ["ball-keys", "ideal-cv"])
def test_scene_show_gives_every_number_its_unit_and_parses_back(hinge):
    text = default_scene([f'pipe.hinge="{hinge}"']).to_toml(units=True)
    numeric = _numeric_lines(text)
    assert len(numeric) > 50
    missing = [line for line in numeric if not re.search(r"  # \S+$", line)]
    assert missing == []
    assert tomllib.loads(text) == tomllib.loads(default_scene([f'pipe.hinge="{hinge}"']).to_toml())
    assert "curvature_radius = 1.5  # m\n" in text
    assert "speed_rpm = 100.0  # rpm\n" in text
    assert "resisting_moment = 1800.0  # N·m\n" in text
    assert "link_inertia = [  # kg·m²\n" in text
    # The paper's N-mm-s contact laws: stiffness in N/mm^e for the law's exponent e.
    assert "stiffness = 100000.0  # N/mm^2.2\n" in text
    assert "damping = 10.0  # N·s/mm\n" in text
    assert "depth_max = 0.1  # mm\n" in text
    assert "v_dynamic = 1000.0  # mm/s\n" in text


def test_scene_show_cli_prints_the_default_scene_with_units():
    proc = _cli("scene", "show")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == default_scene().to_toml(units=True)
    assert tomllib.loads(proc.stdout) == tomllib.loads(_native.default_scene_toml())


def test_scene_show_prints_a_scene_file_with_overrides_and_units():
    proc = _cli("scene", "show", str(BALL_DROP), "--set", "bodies[1].mass=2")
    assert proc.returncode == 0, proc.stderr
    expected = ballcage.load_scene(BALL_DROP, ["bodies[1].mass=2"])
    assert tomllib.loads(proc.stdout) == tomllib.loads(expected.to_toml())
    assert "mass = 2.0  # kg\n" in proc.stdout and "dt = 0.00005  # s\n" in proc.stdout
    assert [line for line in _numeric_lines(proc.stdout) if "  # " not in line] == []
    bad = _cli("scene", "show", str(BALL_DROP), "--set", "bodies[1].mass=-2")
    assert bad.returncode == 2 and "bodies[1].mass" in bad.stderr


# --------------------------------------------------------------------------- TOML syntax errors

BAD_TOML = 'kind = "drill-pipe"\n[pipe]\njoints = @\n'


def test_a_toml_syntax_error_names_line_and_column_in_python(tmp_path):
    with pytest.raises(ballcage.SceneError) as info:
        _native.Scene.from_toml(BAD_TOML)
    assert str(info.value).startswith("TOML syntax error at line 3, column 10: ")
    assert info.value.path == ""
    path = tmp_path / "bad.toml"
    path.write_text(BAD_TOML, encoding="utf-8")
    with pytest.raises(ballcage.SceneError) as info:
        ballcage.load_scene(path)
    assert str(info.value).startswith(f"{path}: TOML syntax error at line 3, column 10: ")
    assert info.value.reason.startswith("TOML syntax error at line 3, column 10")


def test_a_toml_syntax_error_exits_2_with_file_line_and_column(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(BAD_TOML, encoding="utf-8")
    proc = _cli("run", str(path), "--out", str(tmp_path / "out"))
    assert proc.returncode == 2
    assert proc.stderr.startswith(f"ballcage: error: {path}: TOML syntax error at line 3, column 10: ")
    assert proc.stderr.count("\n") == 1 and "<toml" not in proc.stderr
    assert not (tmp_path / "out").exists()


# --------------------------------------------------------------------------- paper outputs


@pytest.fixture(scope="module")
def short_paper_run():
    """The paper scene for 10 ms with the paper's tables: one phase (270°) lies in it."""
    from ballcage.paper.running import paper_scene

    return ballcage.simulate(paper_scene(["simulation.duration=0.01"]), progress=False)


def test_comparison_md_lists_the_phases_once(short_paper_run):
    from ballcage.paper.compare import PHASES_KEY, comparison
    from ballcage.paper.markdown import comparison_markdown

    table = comparison(short_paper_run)
    phases = json.loads(table.schema.metadata[PHASES_KEY.encode()])
    assert phases["phases"] and phases["phases"][0].startswith("270° t=0.010 s: link ")
    text = comparison_markdown(table, command="ballcage paper --out x", run=short_paper_run)
    # the comparison table's rows: those before the next section ("## Contact pressure, wear and losses")
    rows = [line for line in text.split("\n## ")[0].splitlines() if line.startswith("| ")]
    assert not any(phases["note"] in row for row in rows)
    assert sum("phases: listed under the table" in row for row in rows) >= 4
    for item in phases["phases"]:
        assert text.count(item) == 1, item
    assert text.index(phases["phases"][0]) > text.index(rows[-1])  # under the table
    assert "Only 1 of 4 phases in the run (0°, 90°, 180° fall before t = 0)." in text
    # The data file keeps each note whole.
    note = {r["key"]: r["note"] for r in table.to_pylist()}["included_angle_min_deg"]
    assert phases["note"] in note


def test_fig09_tells_the_hinges_apart_and_marks_the_articulation_limit(short_paper_run):
    from ballcage._plot import series_styles
    from ballcage.measures.frames import frame_times
    from ballcage.measures.phases import scene_facts
    from ballcage.paper import figures

    styles = series_styles(12)
    assert len({(s["color"], s["ls"], s["marker"]) for s in styles}) == 12
    assert all(a["color"] != b["color"] for a, b in zip(styles, styles[1:], strict=False))
    limit = figures.articulation_limit_deg(short_paper_run)
    assert limit == short_paper_run.scene.articulation_limit_deg()
    assert limit is not None and 5.0 < limit < 30.0
    fig = figures._fig_included_angles(short_paper_run, scene_facts(short_paper_run), frame_times(short_paper_run))
    over_time = fig.axes[1]
    hinge_lines = [line for line in over_time.get_lines() if line.get_label().startswith("hinge")]
    assert len(hinge_lines) == 12
    assert len({(line.get_color(), line.get_linestyle(), line.get_marker()) for line in hinge_lines}) == 12
    flat = [line for line in over_time.get_lines() if "articulation limit" in str(line.get_label())]
    assert len(flat) == 1 and flat[0].get_ydata()[0] == pytest.approx(180.0 - limit)
    assert f"{180.0 - limit:.2f} deg" in flat[0].get_label()
