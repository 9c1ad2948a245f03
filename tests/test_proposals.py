"""The registry of unstated parameters: `ballcage.proposals()`, the `scene show` marks and the docs that list it.

The registry is defined once in Rust (`scene/provenance.rs`, `drillpipe/provenance.rs`; its completeness is
tested in `crates/ballcage-core/tests/provenance.rs`). Here: the table's schema, that every entry's default,
unit and meaning are the default scene's, that every key takes its low and high value through the ordinary
overrides, that `ballcage scene show` marks each entry, and that docs/proposals.md (generated) and
docs/model.md (its PROPOSAL marks) agree with it. ``python tests/test_proposals.py`` rewrites the table of
docs/proposals.md from the registry.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pyarrow as pa
import pytest

import ballcage
from ballcage.scene import default_scene

ROOT = Path(__file__).resolve().parents[1]
BALL_DROP = ROOT / "examples" / "scenes" / "ball_drop.toml"
PROPOSALS_MD = ROOT / "docs" / "proposals.md"
MODEL_MD = ROOT / "docs" / "model.md"
BEGIN, END = "<!-- registry:begin -->", "<!-- registry:end -->"

#: The schema another command (`ballcage sensitivity`) reads: names and types, in this order.
SCHEMA = [
    ("key", pa.string()),
    ("scene_kind", pa.string()),
    ("default", pa.float64()),
    ("low", pa.float64()),
    ("high", pa.float64()),
    ("unit", pa.string()),
    ("source", pa.string()),
    ("reference", pa.string()),
    ("meaning", pa.string()),
    ("range_reason", pa.string()),
]


@pytest.fixture(scope="module")
def rows() -> list[dict]:
    return ballcage.proposals().to_pylist()


def _scene(kind: str, overrides: tuple[str, ...] = ()) -> ballcage.Scene:
    """The default scene of `kind` (a generic one: the ball drop example) with `overrides`."""
    return default_scene(overrides) if kind == "drill-pipe" else ballcage.load_scene(BALL_DROP, overrides)


# --------------------------------------------------------------------------- the table


def test_the_table_has_exactly_the_agreed_columns_and_types():
    table = ballcage.proposals()
    assert [(f.name, f.type) for f in table.schema] == SCHEMA
    assert table.num_rows >= 30
    assert all(table.column(name).null_count == 0 for name, _ in SCHEMA)


def test_every_row_has_a_range_around_its_default_and_says_why(rows):
    assert {r["scene_kind"] for r in rows} == {"drill-pipe", "generic"}
    assert len({r["key"] for r in rows}) == len(rows)
    for r in rows:
        assert math.isfinite(r["low"]) and math.isfinite(r["high"]), r["key"]
        assert r["low"] < r["high"], r["key"]
        assert r["low"] <= r["default"] <= r["high"], r["key"]
        assert r["source"] in ("invented", "paper-reading", "handbook"), r["key"]
        for text in ("unit", "reference", "meaning", "range_reason"):
            assert r[text].strip(), (r["key"], text)
    neck = next(r for r in rows if r["key"] == "pipe.neck_radius")
    assert (neck["scene_kind"], neck["default"], neck["unit"], neck["source"]) == ("drill-pipe", 0.019, "m", "invented")
    assert (neck["low"], neck["high"]) == (0.0175, 0.021)


def test_default_unit_and_meaning_are_the_default_scenes(rows):
    scenes = {kind: _scene(kind) for kind in ("drill-pipe", "generic")}
    for r in rows:
        scene = scenes[r["scene_kind"]]
        assert scene.value(r["key"]) == r["default"], r["key"]
        assert scene.unit(r["key"]) == r["unit"], r["key"]
        assert scene.meaning(r["key"]) == r["meaning"], r["key"]


def test_a_kind_keeps_its_own_rows(rows):
    pipe, generic = ballcage.proposals(kind="drill-pipe"), ballcage.proposals("generic")
    assert set(pipe.column("scene_kind").to_pylist()) == {"drill-pipe"}
    assert set(generic.column("scene_kind").to_pylist()) == {"generic"}
    assert pipe.num_rows + generic.num_rows == len(rows)
    assert pipe.schema == generic.schema == ballcage.proposals().schema
    with pytest.raises(ballcage.InputError, match='kind = "crane": unknown scene kind'):
        ballcage.proposals("crane")
    with pytest.raises(ballcage.InputError, match="kind = 3"):
        ballcage.proposals(3)  # type: ignore[arg-type]


def test_every_key_takes_its_low_and_high_value_through_the_overrides(rows):
    for r in rows:
        extra = ['pipe.hinge="ideal-cv"'] if r["key"].startswith("pipe.ideal_cv.") else []
        for value in (r["low"], r["high"]):
            scene = _scene(r["scene_kind"], (f"{r['key']}={value!r}", *extra))
            assert scene.value(r["key"]) == value, r["key"]


# --------------------------------------------------------------------------- scene show


def _marked(text: str) -> dict[str, str]:
    """Each field `scene show` marks, by dotted key: the mark (the comment line above its line)."""
    marks, section, lines = {}, "", text.splitlines()
    for i, line in enumerate(lines):
        if line.startswith("["):
            section = line.strip("[]")
        elif line.startswith("# PROPOSAL, "):
            key = lines[i + 1].split(" = ", 1)[0]
            marks[f"{section}.{key}" if section else key] = line[2:]
    return marks


def test_scene_show_marks_every_proposal_of_the_default_scene_above_its_line(rows):
    proc = subprocess.run(
        [sys.executable, "-m", "ballcage", "scene", "show"], capture_output=True, text=True, timeout=120, check=False
    )
    assert proc.returncode == 0, proc.stderr
    marks = _marked(proc.stdout)
    expected = {r["key"] for r in rows if r["scene_kind"] == "drill-pipe" or r["key"].startswith("simulation.")}
    assert set(marks) == expected
    assert marks["pipe.neck_radius"] == "PROPOSAL, 17.5–21 mm: not in the paper"
    assert marks["pipe.ball_keys.mouth_offset"] == "PROPOSAL, 18–22 mm: a reading of the paper"
    assert marks["materials.internal.normal.stiffness"] == "PROPOSAL, 1e4–1e6 N/mm^2.2: a reading of the paper"
    assert marks["materials.key_steel.hardness"] == "PROPOSAL, 6.84–7.85 GPa: a handbook value, not in the paper"
    assert marks["pipe.ball_keys.contact_angle_deg"].startswith("PROPOSAL, 35–50°: ")
    assert "# PROPOSAL, 17.5–21 mm: not in the paper\nneck_radius = 0.019  # m\n" in proc.stdout
    # the marks are comments: the text reads back as the scene
    assert tomllib.loads(proc.stdout) == tomllib.loads(default_scene().to_toml())


def test_scene_show_marks_a_generic_scenes_divergence_thresholds():
    marks = _marked(ballcage.load_scene(BALL_DROP).to_toml(units=True))
    assert marks == {
        "simulation.divergence.penetration_fraction": "PROPOSAL, 0.1–0.5: not in the paper",
        "simulation.divergence.energy_growth": "PROPOSAL, 0.5–2: not in the paper",
    }


# --------------------------------------------------------------------------- the docs


def _number(x: float) -> str:
    """`x` in at most six significant digits, exponents short: 0.0175, 1e4, 1.336e9, 3e-5."""
    text = f"{x:.6g}"
    return re.sub(r"e([+-])0*(\d)", lambda m: "e" + ("-" if m.group(1) == "-" else "") + m.group(2), text)


def render_registry() -> str:
    """The table of docs/proposals.md, from `ballcage.proposals()`: one section per scene kind."""
    out = []
    for kind, title in (("drill-pipe", "Drill pipe"), ("generic", "Every scene (the engine's own)")):
        out += [
            f"### {title}",
            "",
            "| key | meaning | default | plausible range | unit | source | why this range | reference |",
            "|---|---|---:|---|---|---|---|---|",
        ]
        for r in ballcage.proposals(kind).to_pylist():
            cells = [
                f"`{r['key']}`",
                r["meaning"],
                _number(r["default"]),
                f"{_number(r['low'])} – {_number(r['high'])}",
                r["unit"],
                r["source"],
                r["range_reason"],
                r["reference"],
            ]
            out.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
        out.append("")
    return "\n".join(out).rstrip("\n")


def _registry_in(text: str) -> str:
    return text.split(BEGIN, 1)[1].split(END, 1)[0].strip("\n")


def test_docs_proposals_lists_the_registry_as_it_is():
    text = PROPOSALS_MD.read_text(encoding="utf-8")
    assert _registry_in(text) == render_registry(), "regenerate it: python tests/test_proposals.py"


def _blocks(text: str) -> list[tuple[str, str]]:
    """docs text as (context, block) pairs: each paragraph without context, each table row with the paragraph
    before its table as its context."""
    blocks, before = [], ""
    for paragraph in re.split(r"\n\s*\n", text):
        lines = paragraph.splitlines()
        rows = [line for line in lines if line.startswith("|")]
        prose = "\n".join(line for line in lines if not line.startswith("|"))
        if prose:
            blocks.append(("", prose))
        blocks += [(prose or before, row) for row in rows]
        before = prose or before
    return blocks


def _sections(context: str) -> list[str]:
    """The sections a text names as ``prefix.*`` (`pipe.ball_keys.*`)."""
    return re.findall(r"`([a-z_][a-z0-9_.]*)\.\*`", context)


def test_docs_model_marks_every_registry_key_as_a_proposal(rows):
    blocks = _blocks(MODEL_MD.read_text(encoding="utf-8"))

    def marked(key: str) -> bool:
        section, last = key.rsplit(".", 1)
        for context, block in blocks:
            text = f"{context}\n{block}"
            if "PROPOSAL" not in block:
                continue
            if f"`{key}`" in block or (f"`{last}`" in block and section in _sections(text)):
                return True
        return False

    assert [r["key"] for r in rows if not marked(r["key"])] == []


def test_every_proposal_of_the_docs_model_parameter_tables_is_in_the_registry(rows):
    keys = {r["key"] for r in rows}
    blocks = _blocks(MODEL_MD.read_text(encoding="utf-8"))
    rows_marked = [(c, b) for c, b in blocks if b.startswith("|") and "PROPOSAL" in b]
    assert len(rows_marked) >= 10
    unknown = []
    for context, row in rows_marked:
        for name in re.findall(r"`([a-z_][a-z0-9_.]*)`", row):
            candidates = {name} | {f"{section}.{name}" for section in _sections(context)}
            if not candidates & keys:
                unknown.append(name)
    assert unknown == []


if __name__ == "__main__":
    text = PROPOSALS_MD.read_text(encoding="utf-8")
    head, rest = text.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    PROPOSALS_MD.write_text(f"{head}{BEGIN}\n{render_registry()}\n{END}{tail}", encoding="utf-8")
    print(f"wrote the registry's table into {PROPOSALS_MD}")
