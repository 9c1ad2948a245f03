"""Units once: the engine's one table of field units answers `Scene.unit` / `Scene.meaning` for every
field `scene show` prints, and the stub's table names are the module's."""

from __future__ import annotations

import ast
import re
import tomllib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

import ballcage
from ballcage import _native, studies

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples" / "scenes").glob("*.toml"))


def _shown() -> Iterator[tuple[str, ballcage.Scene]]:
    """The scenes `scene show` prints: the default drill pipe (both hinges) and every example scene."""
    for hinge in ("ball-keys", "ideal-cv"):
        yield f"drill pipe, {hinge}", ballcage.Scene.from_toml('kind = "drill-pipe"', [f'pipe.hinge="{hinge}"'])
    for path in EXAMPLES:
        yield path.name, ballcage.Scene.from_toml(path.read_text(encoding="utf-8"))


def _numeric_leaves(value: Any, path: str = "") -> Iterator[tuple[str, Any]]:
    """Every number of a parsed TOML document, by dotted key (array elements by index, `bodies.1.mass`)."""
    if isinstance(value, dict):
        for key, item in value.items():
            yield from _numeric_leaves(item, f"{path}.{key}" if path else key)
    elif isinstance(value, list):
        for i, item in enumerate(value):
            yield from _numeric_leaves(item, f"{path}.{i}")
    elif isinstance(value, int | float) and not isinstance(value, bool):
        yield path, value


def test_there_are_example_scenes_to_check():
    assert len(EXAMPLES) >= 2, EXAMPLES


@pytest.mark.parametrize(("name", "scene"), list(_shown()), ids=lambda x: x if isinstance(x, str) else "")
def test_scene_unit_answers_for_every_number_scene_show_prints(name, scene):
    printed = tomllib.loads(scene.to_toml(units=True))
    leaves = list(_numeric_leaves(printed))
    assert len(leaves) > 20, name
    lines = scene.to_toml(units=True).splitlines()
    for key, _ in leaves:
        unit = scene.unit(key)
        assert unit, f"{name}: {key} has no unit"
        assert scene.meaning(key), f"{name}: {key} has no meaning"
        # a scalar's printed line ends in the same unit (arrays print theirs on the opening line)
        last = key.rsplit(".", 1)[-1]
        if not last.isdigit():
            assert any(line.startswith(f"{last} = ") and line.endswith(f"  # {unit}") for line in lines), (name, key)


@pytest.mark.parametrize(
    ("key", "unit"),
    [
        ("borehole.curvature_radius", "m"),
        ("drive.speed_rpm", "rpm"),
        ("materials.tube.normal.stiffness", "N/mm^2.2"),
        ("materials.tube.normal.damping", "N·s/mm"),
        ("materials.tube.friction.v_static", "mm/s"),
        ("pipe.link_inertia", "kg·m²"),
        ("pipe.link_inertia[2]", "kg·m²"),
        ("pipe.ideal_cv.stiffness", "N/m"),
        ("pipe.ball_keys.contact_angle_deg", "deg"),
        ("pipe.joints", "-"),
        ("pipe.hinge", ""),
        ("record.max_bytes", "B"),
        ("borehole", ""),
    ],
)
def test_exact_units_of_the_drill_pipe(key, unit):
    assert ballcage.scene.default_scene().unit(key) == unit


def test_a_generic_scenes_units_by_either_index_syntax_and_from_its_law():
    scene = ballcage.load_scene(ROOT / "examples" / "scenes" / "two_balls.toml")
    assert scene.unit("bodies[1].mass") == scene.unit("bodies.1.mass") == "kg"
    assert scene.unit("bodies.0.shape.radius") == "m"
    assert scene.unit("contacts[0].normal.stiffness") == "N/m^1.5"  # the law's exponent
    si = ballcage.scene.default_scene(['materials.tube.normal.units="SI"'])
    assert si.unit("materials.tube.normal.stiffness") == "N/m^2.2"
    assert si.unit("materials.tube.normal.depth_max") == "m"


def test_meaning_is_one_line_from_the_table():
    scene = ballcage.scene.default_scene()
    assert scene.meaning("borehole.curvature_radius") == "centreline curvature radius R of the guide tube"
    assert "stiffness" in scene.meaning("materials.internal.normal.stiffness")
    assert all("\n" not in scene.meaning(k) for k, _ in _numeric_leaves(tomllib.loads(scene.to_toml())))


@pytest.mark.parametrize("key", ["pipe.nope", "bodies[0].mass", "pipe.link_inertia[7]", ""])
def test_an_unknown_key_raises_input_error_naming_it(key):
    scene = ballcage.scene.default_scene()
    for method in (scene.unit, scene.meaning):
        with pytest.raises(ballcage.InputError, match=re.escape(f'("{key}"): ')):
            method(key)


def test_a_law_value_scales_from_the_papers_units_into_the_laws_own():
    paper = ballcage.scene.default_scene()
    si = ballcage.scene.default_scene(['materials.internal.normal.units="SI"'])
    key = "materials.internal.normal"
    assert paper.scale_from(f"{key}.stiffness", "N-mm-s") == 1.0
    assert si.scale_from(f"{key}.stiffness", "N-mm-s") == 1000.0**2.2
    assert si.scale_from(f"{key}.damping", "N-mm-s") == 1000.0
    assert si.scale_from(f"{key}.depth_max", "N-mm-s") == 1e-3
    assert paper.scale_from(f"{key}.depth_max", "SI") == 1000.0
    with pytest.raises(ballcage.InputError, match="pipe.pitch"):
        paper.scale_from("pipe.pitch", "N-mm-s")
    with pytest.raises(ballcage.InputError, match='units = "mm": must be "SI" or "N-mm-s"'):
        paper.scale_from(f"{key}.stiffness", "mm")


def test_the_stability_parameters_take_their_units_and_scales_from_the_engine():
    paper = studies.drill_pipe_parameters(values_per_parameter=3)
    si = studies.drill_pipe_parameters(
        ballcage.scene.default_scene(['materials.internal.normal.units="SI"']), values_per_parameter=3
    )
    assert (paper["stiffness"].unit, si["stiffness"].unit) == ("N/mm^2.2", "N/m^2.2")
    assert (paper["damping"].unit, si["damping"].unit) == ("N·s/mm", "N·s/m")
    assert si["stiffness"].values == tuple(v * 1000.0**2.2 for v in paper["stiffness"].values)
    assert si["damping"].values == tuple(v * 1000.0 for v in paper["damping"].values)
    assert (paper["speed"].unit, paper["curvature_radius"].unit, paper["key_mass"].unit) == ("rpm", "m", "kg")


def test_the_stubs_table_names_are_the_modules():
    tree = ast.parse((ROOT / "python" / "ballcage" / "_native.pyi").read_text(encoding="utf-8"))
    literal = next(
        node.value
        for node in tree.body
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "_TableName" for t in node.targets)
    )
    assert isinstance(literal, ast.Subscript) and getattr(literal.value, "id", "") == "Literal"
    assert isinstance(literal.slice, ast.Tuple)
    names = [ast.literal_eval(e) for e in literal.slice.elts]
    assert names == list(_native.TABLE_NAMES)


def test_scene_show_lists_the_optional_tolerances_while_they_are_unset():
    # The paper scene sets rtol (adaptive steps) and leaves max_step and atol to their defaults: `scene show`
    # says so in the [simulation] table, with unit and meaning. Fixed steps (rtol = 0) print rtol and still
    # list the other two; a generic scene without rtol lists all three.
    shown = ballcage.Scene.from_toml('kind = "drill-pipe"').to_toml(units=True)
    simulation = shown.split("[simulation]")[1].split("[simulation.newton]")[0]
    assert "rtol = 0.0001  # -" in simulation and "# rtol: unset" not in simulation
    assert "# max_step: unset, largest adaptive step (default: the output interval) [s]" in simulation
    assert "# atol: unset" in simulation and "[m, rad, m/s, rad/s]" in simulation
    assert tomllib.loads(shown)["simulation"]["rtol"] == 1e-4
    fixed = ballcage.Scene.from_toml('kind = "drill-pipe"', ["simulation.rtol=0"]).to_toml(units=True)
    assert "rtol = 0.0  # -" in fixed and "# max_step: unset" in fixed
    generic = ballcage.Scene.from_toml(EXAMPLES[0].read_text(encoding="utf-8")).to_toml(units=True)
    assert (
        "# rtol: unset, relative tolerance of esdirk32's and trbdf2's adaptive steps (absent or 0: fixed steps of dt) [-]"
    ) in generic
